"""The parallel arrangement's own Pinocchio closed-loop model against the closed form (docs/parallel.md).

- assembly: Newton on Pinocchio's closure residual lands on eq. (P3) and on both forward-kinematics modes;
- the closure Jacobian has rank 5 (as the perpendicular model's), and Pinocchio's kinetic energy is eq. (P9)'s;
- constrained inverse dynamics (rank-revealing, λ eliminated) equals eq. (P14) to 1e-9 relative.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz import InvalidParametersError, Params, SingularConfigurationError, UnreachablePoseError
from tpm_viz.multibody import parallel as mbp
from tpm_viz.multibody.rank import ranked_svd
from tpm_viz.paper import parallel as par

P = Params.paper()
MB = mbp.parallel_model_for(P)


@st.composite
def parallel_params(draw) -> Params:
    l_a = draw(st.floats(0.12, 0.5))
    b = draw(st.floats(0.02, 0.2))
    a = b + draw(st.floats(0.05, 0.8))
    masses = {k: draw(st.floats(0.05, 10.0)) for k in ("m_a", "m_b", "m_p")}
    try:
        return par.validate(Params(a=a, b=b, l_a=l_a, stroke=0.5, pivot_spacing=0.2 * l_a, **masses))
    except InvalidParametersError:
        assume(False)
        raise


def state(params: Params, rng: np.random.Generator):
    la = params.l_a
    p = np.array([rng.uniform(-0.8, 0.8) * la, rng.uniform(0.25, 0.9) * la * rng.choice([-1.0, 1.0])])
    return p, rng.uniform(-2, 2, 2), rng.uniform(-30, 30, 2), rng.uniform(-50, 50, 2)


def rel(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / np.max(np.abs(b)))


@settings(max_examples=examples(60), deadline=None, derandomize=True)
@given(params=parallel_params(), seed=st.integers(0, 2**32 - 1))
def test_pinocchio_inverse_dynamics_equals_the_closed_form(params, seed):
    rng = np.random.default_rng(seed)
    model = mbp.ParallelMultibodyModel(params)
    for _ in range(3):
        p, dp, ddp, f = state(params, rng)
        closed = par.inverse_dynamics(params, p, dp, ddp, f_ext=f)
        assert rel(model.inverse_dynamics(p, dp, ddp, f_ext=f), closed) < 1e-9


def test_batches_and_the_module_function_agree():
    rng = np.random.default_rng(7)
    states = [state(P, rng) for _ in range(20)]
    p, dp, ddp, f = (np.array(x) for x in zip(*states, strict=True))
    closed = par.inverse_dynamics(P, p, dp, ddp, f_ext=f)
    assert rel(mbp.inverse_dynamics(P, p, dp, ddp, f_ext=f), closed) < 1e-9


@pytest.mark.parametrize("p", [(0.0, 0.1), (0.12, 0.2), (-0.2, -0.15)])
def test_assembly_lands_on_the_working_mode(p):
    p = np.asarray(p)
    q = MB.configuration(p)
    assert MB.constraint_violation(q) < 1e-12
    assert rel(MB.platform_position(q), p) < 1e-12
    d = par.inverse_kinematics(P, p)
    assert np.allclose(q[[MB.index["slider1"], MB.index["slider2"]]], d, atol=1e-12)
    theta = par.leg_angles(P, p)
    assert q[MB.index["link1_0"]] == pytest.approx(theta[0], abs=1e-12)
    assert q[MB.index["link2_0"]] == pytest.approx(-theta[1], abs=1e-12)
    parts = MB.placements(q)
    pose = par.mechanism_pose(P, p)
    assert np.allclose(parts["slider1"][0][:2], pose.A[0], atol=1e-12)
    assert np.allclose(parts["slider2"][0][:2], pose.A[1], atol=1e-12)
    assert np.allclose(parts["link2_1"][0][:2], pose.links[1, 1, 0], atol=1e-12)
    assert np.allclose(parts["platform"][0][:2], p, atol=1e-12)


def test_assembly_from_actuators_gives_both_modes():
    d = par.inverse_kinematics(P, [0.05, 0.12])
    sol = par.forward_kinematics_both(P, d)
    for mode, expected in ((1, sol.plus), (-1, sol.minus)):
        q = MB.configuration_from_actuators(d, mode)
        assert MB.constraint_violation(q) < 1e-12
        assert rel(MB.platform_position(q), expected) < 1e-10
    with pytest.raises(UnreachablePoseError):
        MB.configuration_from_actuators([-0.5, -0.5])


def test_closure_rank_and_kinetic_energy():
    rng = np.random.default_rng(3)
    for _ in range(5):
        p, dp, ddp, _ = state(P, rng)
        q, v, _ = MB.constrained_motion(p, dp, ddp)
        _, jc = MB.closure_terms(q)
        assert ranked_svd(jc).rank == 5
        assert abs(jc @ v).max() < 1e-12 * (1 + abs(v).max())
        assert MB.kinetic_energy(q, v) == pytest.approx(float(par.kinetic_energy(P, p, dp)), rel=1e-10)


def test_singular_and_unreachable_poses_are_refused():
    with pytest.raises(SingularConfigurationError):
        MB.inverse_dynamics([0.0, 0.0], [0.1, 0.0], [0.0, 0.0])
    with pytest.raises(UnreachablePoseError):
        MB.configuration([0.0, P.l_a])
    far = np.array([1.5 * P.l_a, 0.1])  # |p1| > l_a is reachable in this arrangement (p1 is free)
    assert MB.platform_position(MB.configuration(far)) == pytest.approx(far, abs=1e-12)
    assert math.isfinite(float(MB.inverse_dynamics(far, [0.1, 0.1], [1.0, 1.0])[0]))
