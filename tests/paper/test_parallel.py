"""The parallel arrangement (tpm_viz.paper.parallel, docs/parallel.md) against independent routes.

Geometry and kinematics from the loop equations solved as quadratics (tests/support/parallel_reference.py); the
Jacobian and d̈ against finite differences; cond(J) against its closed form; statics against virtual work; the
inverse dynamics against a minimal-coordinate Lagrangian of rigid bodies (finite differences) and the energy balance
∫ (τ·ḋ + f·ṗ) dt = ΔK along a trajectory; the geometric validity rule against a brute-force search.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import assume, given, settings
from hypothesis import strategies as st

from tests.support import parallel_reference as ref
from tests.support.hypo import examples
from tpm_viz import InvalidParametersError, Params, SingularConfigurationError, UnreachablePoseError
from tpm_viz.paper import parallel as par
from tpm_viz.paper.status import MOVE_LIMITS, FkStatus, PoseStatus

P = Params.paper()


@st.composite
def parallel_params(draw) -> Params:
    """Random parameter sets valid for the parallel arrangement (lengths 0.5x-2x the prototype's)."""
    l_a = draw(st.floats(0.12, 0.5))
    b = draw(st.floats(0.02, 0.2))
    a = b + draw(st.floats(0.05, 0.8))
    stroke = draw(st.floats(0.1, 0.8))
    masses = {k: draw(st.floats(0.05, 10.0)) for k in ("m_a", "m_b", "m_p")}
    try:
        params = Params(a=a, b=b, l_a=l_a, stroke=stroke, pivot_spacing=0.2 * l_a, **masses)
        return par.validate(params)
    except InvalidParametersError:
        assume(False)
        raise


@st.composite
def states(draw, params: Params, margin: float = 0.2):
    """A regular state: ``sin θ`` in ``[margin, 1 - margin]`` (upper mode), ``|p_1| <= l_a``, either sign of p2."""
    la = params.l_a
    s = draw(st.floats(margin, 1.0 - margin)) * draw(st.sampled_from([1.0, -1.0]))
    p = np.array([draw(st.floats(-la, la)), s * la])
    dp = np.array([draw(st.floats(-2, 2)), draw(st.floats(-2, 2))])
    ddp = np.array([draw(st.floats(-30, 30)), draw(st.floats(-30, 30))])
    return p, dp, ddp


def rel(a, b) -> float:
    a, b = np.asarray(a, float), np.asarray(b, float)
    return float(np.max(np.abs(a - b)) / (1.0 + np.max(np.abs(b))))


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data())
def test_inverse_kinematics_closes_both_loops_with_the_legs_inwards(params, data):
    p, _, _ = data.draw(states(params))
    d = par.inverse_kinematics(params, p)
    assert rel(d, ref.ik_quadratic(params, p)) < 1e-12
    pose = par.mechanism_pose(params, p)
    a1, a2, b1, b2 = ref.joints(params, p)
    assert rel(pose.A, [a1, a2]) < 1e-12 and rel(pose.B, [b1, b2]) < 1e-12
    for leg in pose.links:
        for link in leg:
            assert abs(np.linalg.norm(link[1] - link[0]) - params.l_a) < 1e-12
    assert pose.A[0, 0] < pose.B[0, 0] and pose.B[1, 0] < pose.A[1, 0]  # leaning inwards
    u = math.sqrt(params.l_a**2 - p[1] ** 2)
    assert np.allclose(pose.theta, math.atan2(p[1], u), atol=1e-12)  # both legs at the same angle


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data())
def test_forward_kinematics_returns_both_mirror_modes(params, data):
    p, _, _ = data.draw(states(params))
    sol = par.forward_kinematics_both(params, par.inverse_kinematics(params, p))
    upper, lower = np.array([p[0], abs(p[1])]), np.array([p[0], -abs(p[1])])
    assert bool(sol.exists) and int(sol.status) == FkStatus.TWO_MODES
    assert rel(sol.plus, upper) < 1e-9 and rel(sol.minus, lower) < 1e-9
    p_near, mode = par.forward_kinematics_nearest(params, par.inverse_kinematics(params, p), p)
    assert rel(p_near, p) < 1e-9 and mode == (1 if p[1] > 0 else -1)


def test_forward_kinematics_statuses_and_errors():
    k = P.offset
    sol = par.forward_kinematics_both(P, [[k + 0.01, k - 0.01], [0.15, 0.15], [-0.5, -0.5]])
    assert sol.status.tolist() == [FkStatus.COINCIDE, FkStatus.TWO_MODES, FkStatus.APART]
    with pytest.raises(SingularConfigurationError, match="coincide"):
        par.forward_kinematics(P, [k + 0.01, k - 0.01])
    with pytest.raises(UnreachablePoseError, match="2 l_a apart"):
        par.forward_kinematics(P, [-0.5, -0.5])
    tangent = par.forward_kinematics_both(P, [k - P.l_a, k - P.l_a])  # c_1 = c_2 = l_a: legs flat, modes merge
    assert int(tangent.status) == FkStatus.MODES_MERGE and abs(tangent.plus[1]) < 1e-6
    with pytest.raises(UnreachablePoseError, match="unreachable"):
        par.inverse_kinematics(P, [0.0, P.l_a])


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data())
def test_jacobians_match_finite_differences_of_the_kinematics(params, data):
    p, dp, _ = data.draw(states(params))
    jac = par.jacobians(params, p)
    assert rel(jac.j, ref.jacobian_fd(params, p)) < 1e-6
    u = math.sqrt(params.l_a**2 - p[1] ** 2)
    assert rel(jac.j, [[1.0, p[1] / u], [-1.0, p[1] / u]]) < 1e-12  # the J
    assert rel(jac.jx @ dp, jac.jq @ (jac.j @ dp)) < 1e-12
    assert abs(jac.det_jx - 2 * p[1] * u / params.l_a**2) < 1e-12  # direct singularity at p2 = 0
    assert abs(jac.det_jq - (u / params.l_a) ** 2) < 1e-12  # inverse singularity at |p2| = l_a
    dd = par.actuator_velocity(params, p, dp)
    assert rel(par.platform_velocity(params, p, dd), dp) < 1e-9


@settings(max_examples=examples(300), deadline=None, derandomize=True)
@given(params=parallel_params(), s=st.floats(1e-3, 1 - 1e-3), p1=st.floats(-0.3, 0.3), sign=st.sampled_from([1, -1]))
def test_condition_number_is_max_of_p2_over_u_and_its_inverse(params, s, p1, sign):
    """cond J = max(|p2|/u, u/|p2|) in the working mode: JᵀJ = diag(2, 2 t²), t = p2/u (docs/parallel.md, P6).
    With the sign of p2 kept the issue's formula max(p2/u, u/p2) is negative below the axis: |p2| is the true one."""
    p = np.array([p1, sign * s * params.l_a])
    u = math.sqrt(params.l_a**2 - p[1] ** 2)
    expected = max(abs(p[1]) / u, u / abs(p[1]))
    assert abs(par.condition_number(params, p) - expected) < 1e-9 * expected


def test_condition_number_formula_holds_on_every_regular_branch():
    """Each leg has c_i = ±u. Both inwards or both outwards: |t_1| = |t_2| = |p2|/u and the formula holds; one of
    each: c_1 + c_2 = 0, the legs are parallel and J is singular (det J_x = p2 (c_1 + c_2) / l_a² = 0)."""
    p = np.array([0.03, 0.1])
    d = par.inverse_kinematics(P, p)
    u = math.sqrt(P.l_a**2 - p[1] ** 2)
    expected = max(0.1 / u, u / 0.1)
    assert par.condition_number(P, p) == pytest.approx(expected, rel=1e-12)
    outwards = d + np.array([2 * u, 2 * u])  # the other root of both legs' quadratics
    assert par.leg_components(P, p, outwards)[0] == pytest.approx([-u, -u])
    assert par.condition_number(P, p, outwards) == pytest.approx(expected, rel=1e-12)
    for mixed in (d + np.array([2 * u, 0.0]), d + np.array([0.0, 2 * u])):
        assert abs(par.jacobians(P, p, mixed).det_jx) < 1e-15
        assert par.condition_number(P, p, mixed) > 1e12


def test_classify_uses_the_shared_thresholds():
    la = P.l_a
    home = par.home(P)
    assert par.classify(P, home) == PoseStatus.REGULAR
    assert par.classify(P, [0.0, 0.01]) == PoseStatus.NEAR_DIRECT  # det J_x = 2 p2 u / l_a² small
    assert par.classify(P, [0.0, 0.0]) == PoseStatus.NEAR_DIRECT
    assert par.classify(P, [0.0, la]) == PoseStatus.UNREACHABLE
    assert par.classify(P, [0.5, home[1]]) == PoseStatus.OUT_OF_STROKE
    wide = P.replace(stroke=0.8)
    s = 0.99
    assert par.classify(wide, [0.0, s * la]) == PoseStatus.NEAR_INVERSE  # cos θ = 0.14 < 0.2
    assert par.classify(wide, [0.0, s * la], MOVE_LIMITS) == PoseStatus.REGULAR  # 0.14 > 0.03
    statuses = par.classify(P, np.array([[0.0, 0.1], [0.0, np.nan]]))
    assert statuses.tolist() == [PoseStatus.REGULAR, PoseStatus.UNREACHABLE]


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data())
def test_actuator_acceleration_matches_finite_differences(params, data):
    p, dp, ddp = data.draw(states(params))
    h = 1e-4

    def d_at(t):
        return ref.ik_quadratic(params, p + dp * t + 0.5 * ddp * t**2)

    fd = (d_at(h) - 2 * d_at(0.0) + d_at(-h)) / h**2
    assert rel(par.actuator_acceleration(params, p, dp, ddp), fd) < 1e-4


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data(), f=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_statics_satisfy_virtual_work_and_hold_a_load(params, data, f):
    p, v, _ = data.draw(states(params))
    f = np.asarray(f)
    tau = par.actuator_forces_from_platform_force(params, p, f)
    assert abs(tau @ (ref.jacobian_fd(params, p) @ v) - f @ v) < 1e-6 * (1 + np.abs(f).sum() * np.abs(v).sum())
    assert rel(par.platform_force_from_actuator_forces(params, p, tau), f) < 1e-9
    held = par.inverse_dynamics(params, p, np.zeros(2), np.zeros(2), f_ext=f)  # at rest: τ = -J⁻ᵀ f_ext
    assert rel(held, par.actuator_forces_from_platform_force(params, p, -f)) < 1e-9


@settings(max_examples=examples(100), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data(), f=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_inverse_dynamics_matches_a_minimal_coordinate_lagrangian(params, data, f):
    p, dp, ddp = data.draw(states(params, margin=0.25))
    tau = par.inverse_dynamics(params, p, dp, ddp, f_ext=f)
    expected = ref.minimal_coordinate_forces(params, p, dp, ddp, f_ext=f)
    assert rel(tau, expected) < 1e-6


@settings(max_examples=examples(100), deadline=None, derandomize=True)
@given(params=parallel_params(), data=st.data())
def test_kinetic_energy_and_mass_matrix_match_rigid_bodies(params, data):
    p, dp, _ = data.draw(states(params))
    m_ref = ref.mass_matrix_ref(params, p)
    assert rel(par.mass_matrix(params, p), m_ref) < 1e-7
    assert abs(par.kinetic_energy(params, p, dp) - ref.kinetic_energy_ref(params, p, dp)) < 1e-7 * (1 + dp @ m_ref @ dp)


@pytest.mark.parametrize("f_ext", [None, (12.0, -7.0)])
def test_energy_balance_along_a_trajectory(f_ext):
    """∫ (τ·ḋ + f_ext·ṗ) dt = ΔK over a 1 s path from rest to motion (Simpson, K of rigid bodies)."""
    t = np.linspace(0.0, 1.0, 2001)
    w = 2 * math.pi * 0.8
    home = par.home(P)
    p = home + np.stack([0.08 * np.sin(w * t), 0.05 * (1 - np.cos(w * t))], -1)
    dp = np.stack([0.08 * w * np.cos(w * t), 0.05 * w * np.sin(w * t)], -1)
    ddp = np.stack([-0.08 * w**2 * np.sin(w * t), 0.05 * w**2 * np.cos(w * t)], -1)
    f = np.zeros(2) if f_ext is None else np.asarray(f_ext)
    tau = par.inverse_dynamics(P, p, dp, ddp, f_ext=f)
    dd = np.array([ref.jacobian_fd(P, pk) @ vk for pk, vk in zip(p, dp, strict=True)])
    power = np.sum(tau * dd, axis=-1) + dp @ f
    n = len(t) - 1
    work = (t[1] - t[0]) / 3 * (power[0] + power[-1] + 4 * power[1:n:2].sum() + 2 * power[2:n:2].sum())
    dk = ref.kinetic_energy_ref(P, p[-1], dp[-1]) - ref.kinetic_energy_ref(P, p[0], dp[0])
    scale = np.trapezoid(np.abs(power), t)
    assert scale > 0.5  # joules moved through: the check is not vacuous
    assert abs(work - dk) < 1e-6 * scale


def test_inverse_dynamics_raises_at_singularities_and_broadcasts():
    with pytest.raises(SingularConfigurationError, match="sin"):
        par.inverse_dynamics(P, [0.0, 0.0], [0.1, 0.1], [1.0, 1.0])
    many = par.inverse_dynamics(P, [[0.0, 0.1], [0.02, 0.15]], [0.1, 0.2], [1.0, 2.0])
    one = par.inverse_dynamics(P, [0.02, 0.15], [0.1, 0.2], [1.0, 2.0])
    assert many.shape == (2, 2) and np.array_equal(many[1], one)
    detail = par.inverse_dynamics_detail(P, [0.02, 0.15], [0.1, 0.2], [1.0, 2.0], f_ext=[3.0, -4.0])
    c, _ = par.leg_components(P, detail.p, detail.d)
    g = np.array([[2 * c[0], -2 * c[1]], [2 * detail.p[1], 2 * detail.p[1]]])  # ∂Γ_k/∂p_i (P12)
    assert rel(g @ detail.lam, detail.v - [3.0, -4.0]) < 1e-12
    assert rel(detail.tau, detail.w + 2 * detail.lam * c) < 1e-12


@settings(max_examples=examples(300), deadline=None, derandomize=True)
@given(a=st.floats(0.05, 1.0), b=st.floats(0.02, 0.3), l_a=st.floats(0.1, 0.5), stroke=st.floats(0.05, 0.8))
def test_geometry_rule_matches_a_brute_force_search(a, b, l_a, stroke):
    """A pose with both d_i in [0, Δd] exists iff a > b and a - b - l_a <= Δd (eq. P3); search over p2 and p1."""
    assume(abs(a - b) > 1e-3 and abs(a - b - l_a - stroke) > 1e-3)
    u = np.linspace(0.0, l_a, 4001)[1:]  # u = sqrt(l_a² - p2²) over every reachable p2 (spacing < the margin)
    half_sum = a - b - u  # (d_1 + d_2) / 2; p_1 = 0 puts d_1 = d_2 = half_sum, any other p_1 spreads them
    found = bool(np.any((half_sum >= 0) & (half_sum <= stroke)))
    assert (par.geometry_problem(a, b, l_a, stroke) is None) == found


def test_validate_is_stricter_than_params():
    tight = Params.paper(b=0.5)  # a < b: valid for the perpendicular rules, not for the parallel
    with pytest.raises(InvalidParametersError, match="b must be less than a"):
        par.validate(tight)
    far = Params.paper(a=0.9, l_a=0.4)  # a - b - l_a = 0.408 > Δd = 0.3 > a - b - √2 l_a = 0.242
    with pytest.raises(InvalidParametersError, match=r"l_a must be at least 508\.0 mm"):
        par.validate(far)
    assert par.validate(P) is P


@settings(max_examples=examples(200), deadline=None, derandomize=True)
@given(params=parallel_params())
def test_home_is_inside_the_stroke_for_every_valid_design(params):
    home = par.home(params)
    d = par.inverse_kinematics(params, home)
    assert home[0] == 0.0 and 0.0 < home[1] < params.l_a
    assert par.in_stroke(params, d, tol=1e-12)
    assert par.classify(params, home) in (PoseStatus.REGULAR, PoseStatus.NEAR_INVERSE, PoseStatus.NEAR_DIRECT)
