"""Jacobians (eqs. 8-10), singularities (11-12), statics (13), velocities (9) and accelerations (14-15).

Reference routes: finite differences of eq. (3) (tests/reference.py), the angle formulas, and
virtual work. The erratum of eq. (15) (sign of J̇_q) is demonstrated against finite differences.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tests.support.reference import ik_quadratic, jacobian_fd
from tests.support.strategies import params_sets, regular_states
from tpm_viz import (
    STATUS_LABELS,
    Params,
    SingularConfigurationError,
    actuator_acceleration,
    actuator_forces_from_platform_force,
    actuator_velocity,
    classify,
    condition_number,
    inverse_kinematics,
    leg_angles,
    platform_force_from_actuator_forces,
    platform_velocity,
)
from tpm_viz.paper.jacobians import jacobians

P = Params.paper()


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_jacobian_matches_finite_differences_of_eq3(params, data):
    p, dp, _ = data.draw(regular_states(params))
    jac = jacobians(params, p)
    assert jac.j == pytest.approx(jacobian_fd(params, p), rel=1e-6, abs=1e-7)
    assert actuator_velocity(params, p, dp) == pytest.approx(jacobian_fd(params, p) @ dp, rel=1e-6, abs=1e-7)
    assert platform_velocity(params, p, jac.j @ dp) == pytest.approx(dp, rel=1e-10, abs=1e-12)
    th = leg_angles(params, p)
    assert jac.det_jx == pytest.approx(math.cos(th[0] + th[1]), abs=1e-12)
    assert jac.det_jq == pytest.approx(math.cos(th[0]) * math.cos(th[1]), abs=1e-12)
    assert condition_number(params, p) == pytest.approx(np.linalg.cond(jacobian_fd(params, p)), rel=1e-5)


def _fd_acceleration(params, p, dp, ddp, h=1e-4):
    """d̈ along p(t) = p + ṗ t + p̈ t²/2 by a central second difference of eq. (3)."""
    d = [ik_quadratic(params, p + dp * t + 0.5 * ddp * t * t) for t in (-h, 0.0, h)]
    return (d[0] - 2 * d[1] + d[2]) / h**2


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_acceleration_eq14_with_corrected_eq15_matches_finite_differences(params, data):
    p, dp, ddp = data.draw(regular_states(params))
    assert actuator_acceleration(params, p, dp, ddp) == pytest.approx(
        _fd_acceleration(params, p, dp, ddp), rel=1e-4, abs=1e-4
    )


def _eq14_as_printed(params, p, dp, ddp):
    """Eq. (14) with eq. (15) exactly as printed: J̇_q = diag(+sin θ_i θ̇_i)."""
    th = leg_angles(params, p)
    th_dot = dp[::-1] / (params.l_a * np.cos(th))
    jx = np.array([[np.cos(th[0]), np.sin(th[0])], [np.sin(th[1]), np.cos(th[1])]])
    jx_dot = np.array(
        [
            [-np.sin(th[0]) * th_dot[0], np.cos(th[0]) * th_dot[0]],
            [np.cos(th[1]) * th_dot[1], -np.sin(th[1]) * th_dot[1]],
        ]
    )
    jq = np.diag(np.cos(th))
    jq_dot_printed = np.diag(np.sin(th) * th_dot)
    dd = np.linalg.solve(jq, jx @ dp)
    return np.linalg.solve(jq, jx_dot @ dp + jx @ ddp - jq_dot_printed @ dd)


def test_erratum_eq15_sign_of_jq_dot():
    """The printed J̇_q gives accelerations off by 2 sin θ θ̇ ḋ / cos θ; the corrected one matches FD."""
    p, dp, ddp = np.array([0.08, 0.06]), np.array([1.2, -0.8]), np.array([5.0, 3.0])
    fd = _fd_acceleration(P, p, dp, ddp)
    printed = _eq14_as_printed(P, p, dp, ddp)
    corrected = actuator_acceleration(P, p, dp, ddp)
    assert corrected == pytest.approx(fd, rel=1e-5)
    assert np.max(np.abs(printed - fd)) > 0.5  # m/s², far beyond FD error (~1e-6)


@settings(max_examples=examples(150), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data(), f=st.tuples(st.floats(-500, 500), st.floats(-500, 500)))
def test_statics_eq13_satisfies_virtual_work(params, data, f):
    """τ·δd = f·δp for every admissible virtual displacement (δd = J δp from FD of eq. 3)."""
    p, _, _ = data.draw(regular_states(params))
    f = np.array(f)
    tau = actuator_forces_from_platform_force(params, p, f)
    jac = jacobian_fd(params, p)
    for dp in (np.array([1e-3, 0.0]), np.array([0.0, 1e-3]), np.array([0.7e-3, -0.4e-3])):
        assert tau @ (jac @ dp) == pytest.approx(f @ dp, rel=1e-6, abs=1e-8)
    assert platform_force_from_actuator_forces(params, p, tau) == pytest.approx(f, rel=1e-9, abs=1e-9)


def test_classify_each_kind():
    la = P.l_a
    poses = {
        "regular": [0.0, 0.0],
        "near inverse singularity": [-0.5 * la, 0.99 * la],  # cos θ1 ≈ 0.14, cos(θ1+θ2) ≈ 0.62
        "near direct singularity": [0.69 * la, 0.69 * la],  # p1² + p2² ≈ 0.95 l_a²
        "out of stroke": [-0.135, 0.0],  # d_1 = -0.135 + 0.39 - 0.26 = -0.005 m < 0
        "unreachable": [0.0, 0.3],
    }
    long_stroke = P.replace(stroke=0.6)  # with Table 1's stroke the first two would be out of stroke
    codes = list(classify(long_stroke, np.array(list(poses.values())[:3])))
    codes += list(classify(P, np.array(list(poses.values())[3:])))
    assert [STATUS_LABELS[int(c)] for c in codes] == list(poses)
    assert inverse_kinematics(P, [-0.135, 0.0])[0] == pytest.approx(-0.005)
    assert STATUS_LABELS[int(classify(P, [0.0, 0.99 * la]))] == "out of stroke"  # d_1 = 0.353 m > 0.3 m


def test_statics_stay_finite_at_an_inverse_singularity():
    """At cos θ1 = 0 (p2 = l_a) τ = J_q J_x^{-T} f is finite, and poses approaching it converge (like sqrt(ε)).

    By hand at the limit: s1 = e_2, J_x = [[0, 1], [sin θ2, cos θ2]], J_q = diag(0, cos θ2), so
    τ = (0, f_1 / tan θ2) with tan θ2 = p1 / sqrt(l_a² - p1²).
    """
    f, p1 = np.array([3.0, -40.0]), 0.05
    by_hand = np.array([0.0, f[0] * np.sqrt(P.l_a**2 - p1**2) / p1])
    d_at = np.array([p1 + P.a - P.b, P.l_a + P.a - P.b - np.sqrt(P.l_a**2 - p1**2)])  # c_1 = 0, eq. (4) for leg 2
    assert actuator_forces_from_platform_force(P, [p1, P.l_a], f, d=d_at) == pytest.approx(by_hand, abs=1e-9)
    for eps, tol in ((1e-8, 0.1), (1e-12, 1e-3)):
        tau = actuator_forces_from_platform_force(P, [p1, P.l_a * (1 - eps)], f)
        assert tau == pytest.approx(by_hand, abs=tol)


def test_singular_configurations_raise():
    p_direct = P.l_a * np.array([math.cos(0.5), math.sin(0.5)])
    with pytest.raises(SingularConfigurationError, match=r"eq\. 12"):
        actuator_forces_from_platform_force(P, p_direct, [1.0, 0.0])
    assert condition_number(P, p_direct) > 1e6 or not np.isfinite(condition_number(P, p_direct))
