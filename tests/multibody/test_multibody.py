"""The Pinocchio closed-loop model against independent routes.

- kinematics: Newton on Pinocchio's closure residual vs the closed form (eq. 4, FK circles, part poses);
- the constraint Jacobian of ``getConstraintJacobian`` vs finite differences of the closure gaps;
- inverse dynamics vs the paper's closed form (eqs. 29-31) at random states and parameter sets, and
  independence from which redundant closure row is kept (square solves with each row subset);
- energy: Pinocchio's kinetic energy vs eqs. (20)-(22) and the rigid-rod reference;
- forward dynamics: our null-space KKT solve vs ``pinocchio.constraintDynamics`` (ProximalSettings).
"""

from __future__ import annotations

import itertools
import threading

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

import tpm_viz as tv
from tests.support.hypo import examples
from tests.support.reference import rod_kinetic_energy
from tests.support.strategies import params_sets, regular_states
from tpm_viz import multibody
from tpm_viz.multibody.model import PART_NAMES, MultibodyModel

P = tv.Params.paper()
MB = multibody.model_for(P)
IN_PLANE_ROWS = [0, 1, 3, 4, 6, 7]  # x, y of each of the 3 CONTACT_3D closures; 2, 5, 8 are z


def rel_err(a, b) -> float:
    return float(np.max(np.abs(np.asarray(a) - np.asarray(b)) / (1.0 + np.abs(b))))


def quat_rotation(wxyz) -> np.ndarray:
    w, x, y, z = wxyz
    return pin.Quaternion(w, x, y, z).toRotationMatrix()


# ----------------------------------------------------------------------------- the model itself
def test_topology_masses_and_gravity_follow_conventions():
    m = MB.model
    assert (m.nq, m.nv) == (7, 7)
    assert list(m.names)[1:] == sorted(PART_NAMES, key=lambda n: MB.index[n])
    assert np.all(m.gravity.vector == 0)
    masses = {name: m.inertias[m.getJointId(name)].mass for name in PART_NAMES}
    assert masses == pytest.approx(
        {"slider1": P.m_a, "slider2": P.m_a, "platform": P.m_p} | {n: P.m_b / 2 for n in PART_NAMES[2:6]}
    )
    rod = m.inertias[m.getJointId("link2_1")]
    assert rod.lever == pytest.approx([P.l_a / 2, 0, 0])
    assert np.diag(rod.inertia) == pytest.approx([0, P.m_b / 2 * P.l_a**2 / 12] * 1 + [P.m_b / 2 * P.l_a**2 / 12])
    assert [c.type for c in MB.constraint_models] == [pin.ContactType.CONTACT_3D] * 3


def test_constraint_jacobian_matches_finite_differences_and_has_rank_five():
    rng = np.random.default_rng(7)
    q = MB.configuration([0.04, -0.07]) + 0.05 * rng.standard_normal(7)  # off the closures on purpose
    phi, jc = MB.closure_terms(q)
    h = 1e-6
    fd = np.stack([(MB.closure_terms(q + h * e)[0] - MB.closure_terms(q - h * e)[0]) / (2 * h) for e in np.eye(7)], 1)
    assert np.max(np.abs(jc - fd)) < 1e-8
    assert np.max(np.abs(phi)) > 1e-3
    q0 = MB.configuration([0.04, -0.07])
    _, jc0 = MB.closure_terms(q0)
    assert np.all(jc0[[2, 5, 8]] == 0)  # out-of-plane rows of a planar motion
    s = np.linalg.svd(jc0, compute_uv=False)
    assert s[4] > 1e-3 * s[0] and s[5] < 1e-12 * s[0]  # rank 5: one in-plane row is redundant


# ----------------------------------------------------------------------------- kinematics
@settings(max_examples=examples(100), deadline=None, derandomize=True)
@given(params=params_sets(), u=st.floats(-0.97, 0.97), w=st.floats(-0.97, 0.97))
def test_configuration_matches_closed_form_inverse_kinematics(params, u, w):
    model = multibody.model_for(params)
    p = np.array([u, w]) * params.l_a
    q = model.configuration(p)
    assert (
        np.max(np.abs(q[[model.index["slider1"], model.index["slider2"]]] - tv.inverse_kinematics(params, p))) < 1e-10
    )
    assert np.max(np.abs(model.platform_position(q) - p)) < 1e-10
    theta = tv.leg_angles(params, p)
    assert q[model.index["link1_0"]] == pytest.approx(theta[0], abs=1e-10)
    assert q[model.index["link2_1"]] == pytest.approx(-theta[1], abs=1e-10)
    assert model.constraint_violation(q) < 1e-12


@pytest.mark.parametrize("seed", range(5))
def test_newton_converges_from_a_perturbed_start(seed, monkeypatch):
    """The cold guess is exact (sin θ_1 = p_2 / l_a); Newton on Pinocchio's closure residual must also find the
    configuration from a start off by up to 0.2 rad and 20 mm, so the solver (not the guess) carries the check."""
    rng = np.random.default_rng(seed)
    model = MultibodyModel(P)
    p = rng.uniform(-0.15, 0.15, 2)
    exact = model._guess_from_platform
    monkeypatch.setattr(model, "_guess_from_platform", lambda p_, d_: exact(p_, d_) + _perturbation(model, rng))
    q = model.configuration(p)
    assert q[[model.index["slider1"], model.index["slider2"]]] == pytest.approx(tv.inverse_kinematics(P, p), abs=1e-12)
    assert model.constraint_violation(q) < 1e-12


def _perturbation(model, rng) -> np.ndarray:
    dq = rng.uniform(-0.2, 0.2, model.model.nv)
    dq[[model.index["slider1"], model.index["slider2"]]] = rng.uniform(-0.02, 0.02, 2)
    return dq


def test_configuration_on_the_other_branch_follows_the_given_actuators():
    p = np.array([0.03, -0.05])
    k, la = P.a - P.b, P.l_a
    d_other = p + k + np.sqrt(la**2 - p[::-1] ** 2)  # positive root of eq. (3): sliders beyond the platform
    q = MB.configuration(p, d=d_other)
    assert q[[MB.index["slider1"], MB.index["slider2"]]] == pytest.approx(d_other, abs=1e-10)
    assert MB.platform_position(q) == pytest.approx(p, abs=1e-12)
    assert np.cos(q[MB.index["link1_0"]]) < 0


@settings(max_examples=examples(80), deadline=None, derandomize=True)
@given(params=params_sets(), u=st.floats(-0.9, 0.9), w=st.floats(-0.9, 0.9), mode=st.sampled_from([1, -1]))
def test_configuration_from_actuators_matches_both_closed_form_assembly_modes(params, u, w, mode):
    d = tv.inverse_kinematics(params, np.array([u, w]) * params.l_a)
    ref = tv.forward_kinematics(params, d, mode)
    both = tv.forward_kinematics_both(params, d)
    assume(np.linalg.norm(both.plus - both.minus) > 0.02 * params.l_a)  # away from eq. (12)
    model = multibody.model_for(params)
    q = model.configuration_from_actuators(d, mode)
    assert np.max(np.abs(model.platform_position(q) - ref)) < 1e-10
    assert q[[model.index["slider1"], model.index["slider2"]]] == pytest.approx(d, abs=1e-12)


def test_placements_match_the_closed_form_mechanism_pose():
    p = np.array([-0.06, 0.045])
    pose = tv.mechanism_pose(P, p)
    place = MB.placements(MB.configuration(p))
    assert set(place) == set(PART_NAMES)
    for i in range(2):
        assert place[f"slider{i + 1}"][0] == pytest.approx([*pose.A[i], 0], abs=1e-12)
        for k in range(2):
            pos, quat = place[f"link{i + 1}_{k}"]
            tip = pos + P.l_a * quat_rotation(quat)[:, 0]  # local x runs along the link
            assert pos[:2] == pytest.approx(pose.links[i, k, 0], abs=1e-12)
            assert tip[:2] == pytest.approx(pose.links[i, k, 1], abs=1e-12)
            assert np.linalg.norm(quat) == pytest.approx(1)
    pos, quat = place["platform"]
    assert pos == pytest.approx([*p, 0], abs=1e-12)
    assert abs(quat[0]) == pytest.approx(1, abs=1e-12)  # the platform translates


# ----------------------------------------------------------------------------- inverse dynamics
@settings(max_examples=examples(200), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data(), f=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_inverse_dynamics_matches_the_paper_closed_form(params, data, f):
    p, dp, ddp = data.draw(regular_states(params))
    tau_paper = tv.inverse_dynamics(params, p, dp, ddp, f_ext=f)
    tau_pin = multibody.inverse_dynamics(params, p, dp, ddp, f_ext=f)
    assert rel_err(tau_pin, tau_paper) <= 1e-9


@pytest.mark.parametrize("kind", ["line", "circle"])
def test_inverse_dynamics_along_the_paper_trajectories(kind):
    traj = tv.paper_trajectory(kind, samples=101)
    tau_pin = multibody.inverse_dynamics(P, traj.p, traj.dp, traj.ddp)
    tau_paper = tv.inverse_dynamics(P, traj.p, traj.dp, traj.ddp)
    assert tau_pin.shape == (101, 2)
    assert np.max(np.abs(tau_paper)) > 100  # the paper's ~150-180 N peaks, not a trivial zero
    assert rel_err(tau_pin, tau_paper) <= 1e-9


def test_tau_does_not_depend_on_which_redundant_closure_row_is_kept():
    rng = np.random.default_rng(11)
    for _ in range(5):
        p = rng.uniform(-0.15, 0.15, 2)
        dp, ddp, f = rng.normal(0, 1, 2), rng.normal(0, 20, 2), rng.normal(0, 20, 2)
        g = MB.generalized_forces(p, dp, ddp, f_ext=f)
        jc, rhs, s_t, tau = g["J_c"], g["rhs"], g["S_T"], g["tau"]
        # The full over-determined system is consistent: rnea - J_Pᵀ f = Sᵀ τ + J_cᵀ λ exactly.
        assert np.max(np.abs(rhs - s_t @ tau - jc.T @ g["lam"])) < 1e-9 * (1 + np.max(np.abs(rhs)))
        kept = []
        for rows in itertools.combinations(IN_PLANE_ROWS, 5):
            sub = jc[list(rows)]
            if np.linalg.matrix_rank(sub, tol=1e-9) < 5:
                continue
            x = np.linalg.solve(np.hstack([s_t, sub.T]), rhs)  # square 7 x 7: τ and 5 multipliers
            kept.append(x[:2])
        assert len(kept) >= 4  # several different maximal independent subsets exist
        for tau_sub in kept:
            assert rel_err(tau_sub, tau) <= 1e-9
        assert rel_err(tau, tv.inverse_dynamics(P, p, dp, ddp, f_ext=f)) <= 1e-9


def test_kinetic_energy_agrees_with_eqs_20_22_and_the_rod_reference():
    rng = np.random.default_rng(5)
    for _ in range(5):
        p, dp = rng.uniform(-0.15, 0.15, 2), rng.normal(0, 1, 2)
        q, v, _ = MB.constrained_motion(p, dp, np.zeros(2))
        k = MB.kinetic_energy(q, v)
        assert k == pytest.approx(float(tv.kinetic_energy(P, p, dp)), rel=1e-12)
        assert k == pytest.approx(rod_kinetic_energy(P, p, dp), rel=1e-6)
        assert MB.platform_velocity(q, v) == pytest.approx(dp, abs=1e-12)


def test_batches_keep_their_shape_and_match_one_state_at_a_time():
    rng = np.random.default_rng(3)
    p = rng.uniform(-0.1, 0.1, (2, 3, 2))
    dp, ddp = rng.normal(0, 1, (2, 3, 2)), rng.normal(0, 10, (2, 3, 2))
    tau = MB.inverse_dynamics(p, dp, ddp, f_ext=[3.0, -2.0])
    assert tau.shape == (2, 3, 2)
    assert tau[1, 2] == pytest.approx(MB.inverse_dynamics(p[1, 2], dp[1, 2], ddp[1, 2], [3.0, -2.0]), abs=1e-12)


def test_module_level_function_caches_one_model_per_parameter_set():
    assert multibody.model_for(tv.Params.paper()) is multibody.model_for(tv.Params.paper())
    assert multibody.model_for(P.replace(m_p=3.0)) is not MB


def test_concurrent_callers_get_correct_forces():
    rng = np.random.default_rng(2)
    states = [(rng.uniform(-0.12, 0.12, 2), rng.normal(0, 1, 2), rng.normal(0, 10, 2)) for _ in range(40)]
    expected = [tv.inverse_dynamics(P, *s) for s in states]
    errors: list[float] = []

    def work():
        errors.extend(rel_err(MB.inverse_dynamics(*s), e) for s, e in zip(states, expected, strict=True))

    threads = [threading.Thread(target=work) for _ in range(3)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert len(errors) == 120 and max(errors) <= 1e-9


# ----------------------------------------------------------------------------- forward dynamics
def test_forward_dynamics_inverts_inverse_dynamics_and_matches_pinocchio_constraint_dynamics():
    model, data = MB.model, MB.model.createData()
    cmodels = pin.StdVec_RigidConstraintModel()
    cdatas = pin.StdVec_RigidConstraintData()
    for c in MB.constraint_models:
        cmodels.append(c)
        cdatas.append(c.createData())
    pin.initConstraintDynamics(model, data, cmodels, cdatas)
    rng = np.random.default_rng(9)
    for _ in range(5):
        p, dp, ddp = rng.uniform(-0.15, 0.15, 2), rng.normal(0, 1, 2), rng.normal(0, 20, 2)
        q, v, a = MB.constrained_motion(p, dp, ddp)
        tau = MB.inverse_dynamics(p, dp, ddp)
        a_fd = MB.forward_dynamics(q, v, tau)
        assert np.max(np.abs(a_fd - a)) < 1e-9 * (1 + np.max(np.abs(a)))
        tau_joint = np.zeros(7)
        tau_joint[[MB.index["slider1"], MB.index["slider2"]]] = tau
        settings_ = pin.ProximalSettings(1e-12, 1e-12, 1e-8, 200)
        a_pin = pin.constraintDynamics(model, data, q, v, tau_joint, cmodels, cdatas, settings_)
        assert np.max(np.abs(a_pin - a)) < 1e-9 * (1 + np.max(np.abs(a)))


def test_projection_restores_the_closures_and_admissible_velocity():
    q, v, _ = MB.constrained_motion([0.02, 0.05], [0.4, -0.3], [0, 0])
    rng = np.random.default_rng(4)
    q_bad, v_bad = q + 1e-4 * rng.standard_normal(7), v + 0.1 * rng.standard_normal(7)
    assert MB.constraint_violation(q_bad) > 1e-5
    q_new, v_new = MB.project(q_bad, v_bad)
    assert MB.constraint_violation(q_new) < 1e-13
    assert np.max(np.abs(MB.closure_terms(q_new)[1] @ v_new)) < 1e-12
    # (nearly) the closest point of the closures: no farther than the configuration we perturbed
    assert np.linalg.norm(q_new - q_bad) <= 1.01 * np.linalg.norm(q - q_bad)


# ----------------------------------------------------------------------------- errors
ANY = st.floats(allow_nan=True, allow_infinity=True) | st.floats(-0.3, 0.3) | st.sampled_from([1e300, -0.26, 0.2599])


@settings(max_examples=examples(300), deadline=None, derandomize=True)
@given(p=st.tuples(ANY, ANY), dp=st.tuples(ANY, ANY), ddp=st.tuples(ANY, ANY), mode=st.sampled_from([1, -1]))
def test_arbitrary_numbers_give_finite_results_or_one_line_errors(p, dp, ddp, mode):
    for call in (
        lambda: MB.inverse_dynamics(p, dp, ddp, f_ext=ddp),
        lambda: MB.configuration(p),
        lambda: MB.configuration_from_actuators(dp, mode),
    ):
        try:
            out = call()
        except tv.TpmVizError as exc:
            assert str(exc) and "\n" not in str(exc)
        else:
            assert np.all(np.isfinite(out))


@pytest.mark.parametrize(
    ("call", "error"),
    [
        (lambda: MB.configuration([0.3, 0.0]), tv.UnreachablePoseError),
        (lambda: MB.configuration([np.nan, 0.0]), tv.InputError),
        (lambda: MB.configuration([0.1, 0.0, 0.0]), tv.InputError),
        (lambda: MB.configuration_from_actuators([0.1, 0.1], mode=0), tv.InputError),
        (lambda: MB.configuration_from_actuators([0.3, -2.0]), tv.UnreachablePoseError),
        (lambda: MB.platform_position(np.zeros(5)), tv.InputError),
        (lambda: MB.inverse_dynamics([0.1, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0]), tv.InputError),
        (lambda: MB.inverse_dynamics([[0.1, 0.0]] * 3, [[0.0, 0.0]] * 2, [0.0, 0.0]), tv.InputError),
        (lambda: MB.inverse_dynamics([0.3, 0.0], [0, 0], [0, 0]), tv.UnreachablePoseError),
        (lambda: MB.inverse_dynamics([-0.26 / 2**0.5] * 2, [0.1, 0], [0, 0]), tv.SingularConfigurationError),
        (lambda: MultibodyModel({"a": 1}), tv.InputError),
        (lambda: multibody.inverse_dynamics(None, [0, 0], [0, 0], [0, 0]), tv.InputError),
    ],
)
def test_bad_input_raises_one_line_tpm_viz_errors(call, error):
    with pytest.raises(error) as info:
        call()
    assert "\n" not in str(info.value) and str(info.value)
