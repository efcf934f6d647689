"""Clamped drags and drives, assembly-mode switches and placements (tpm_viz.app.moves)."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz import InputError, Params, forward_kinematics_both, inverse_kinematics
from tpm_viz.app.moves import (
    Pose,
    check,
    drag_to,
    drive_to,
    ik_branch,
    place,
    pose_codes,
    switch_mode,
    why_not,
)
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus

P = Params.paper()
HOME = Pose.working(P, (0.0, 0.0))


def _assert_valid(params: Params, pose: Pose, mode: int = 1) -> None:
    assert check(params, pose) == PoseStatus.REGULAR
    assert pose.mode(params) == mode
    # d and p are one assembled configuration: both leg constraints of eq. (27) hold.
    c = pose.p - pose.d + (params.a - params.b)
    np.testing.assert_allclose(c**2 + pose.p[::-1] ** 2, params.l_a**2, rtol=1e-9)


def test_pose_is_frozen_and_validated():
    with pytest.raises(InputError):
        Pose((0.0, np.nan), (0.1, 0.1))
    with pytest.raises(ValueError):
        HOME.p[0] = 1.0


def test_ik_branch_plus_is_eq_4():
    p = np.array([0.03, -0.05])
    np.testing.assert_allclose(ik_branch(P, p, (1, 1)), inverse_kinematics(P, p))


def test_ik_branch_minus_is_the_other_root_of_eq_3():
    """Independent route: the other root of |p + (a-b) e_i - d e_i|^2 = l_a^2 (eq. 3)."""
    p = np.array([0.03, -0.05])
    d = ik_branch(P, p, (-1, -1))
    for i in range(2):
        m = p.copy()
        m[i] += P.a - P.b - d[i]
        assert np.hypot(*m) == pytest.approx(P.l_a)
    assert np.all(d > inverse_kinematics(P, p))


def test_home_is_valid_working_mode():
    _assert_valid(P, HOME)
    np.testing.assert_array_equal(HOME.branch(P), [1, 1])


def test_drag_inside_the_valid_set_reaches_the_request():
    move = drag_to(P, HOME, (0.05, 0.03))
    assert not move.clamped and move.reason == ""
    np.testing.assert_allclose(move.pose.p, (0.05, 0.03))
    np.testing.assert_allclose(move.pose.d, inverse_kinematics(P, (0.05, 0.03)))


def test_drag_past_the_stroke_stops_at_the_stroke_end():
    """d_1 = p_1 + a - b - l_a at p_2 = 0 (eq. 4): the stroke end d_1 = 300 mm is at p_1 = 170 mm."""
    move = drag_to(P, HOME, (0.5, 0.0))
    assert move.clamped
    assert str(move.reason).startswith("stopped: slider 1 is against its end-stop at the end of its rail")
    assert "(d1 = Δd = 300.0 mm)" in str(move.reason)
    assert move.pose.p[0] == pytest.approx(0.170, abs=1e-5)
    assert move.pose.d[0] == pytest.approx(P.stroke, abs=1e-5)
    _assert_valid(P, move.pose)


def test_drag_towards_the_direct_singularity_stops_before_it():
    move = drag_to(P, HOME, (-0.3, -0.3))
    why = str(move.reason)
    assert move.clamped and "direct singularity" in why and "modes merge" in why
    # the physics first (a degree of freedom gained, the stiffness lost, the forces unbounded), then the equation
    for words in ("gains a degree of freedom", "loses its stiffness in one direction", "grow without bound"):
        assert why.index(words) < why.index("eq. 12")
    det = float(jacobians(P, move.pose.p, move.pose.d).det_jx)
    assert det == pytest.approx(MOVE_LIMITS.direct, abs=1e-4)
    _assert_valid(P, move.pose)


def test_drag_slides_along_a_boundary():
    """From the stroke end d_1 = Δd, a request up and right slides up along that edge.

    The edge d_1 = Δd is the circle p_1 = Δd - (a - b) + sqrt(l_a² - p_2²) about (Δd - a + b, 0); its point
    nearest (0.2, 0.15) m lies along the ray from the centre: p ≈ (0.141, 0.119) m.
    """
    start = drag_to(P, HOME, (0.5, 0.0)).pose
    move = drag_to(P, start, (0.2, 0.15))
    straight = drag_to(P, start, (0.2, 0.15)).pose  # same call: deterministic
    centre = np.array([P.stroke - P.a + P.b, 0.0])
    expected = centre + P.l_a * (np.array([0.2, 0.15]) - centre) / np.linalg.norm(np.array([0.2, 0.15]) - centre)
    np.testing.assert_allclose(move.pose.p, expected, atol=2e-4)
    np.testing.assert_allclose(straight.p, move.pose.p)
    assert move.pose.d[0] == pytest.approx(P.stroke, abs=1e-5)  # ... along the stroke end
    _assert_valid(P, move.pose)


@settings(max_examples=examples(60), deadline=None)
@given(st.floats(-1.0, 1.0), st.floats(-1.0, 1.0), st.floats(-0.1, 0.1), st.floats(-0.1, 0.1))
def test_any_drag_ends_valid_and_never_jumps(x, y, x0, y0):
    start = drag_to(P, HOME, (x0, y0)).pose
    move = drag_to(P, start, (x, y))
    _assert_valid(P, move.pose)
    # The platform never moves further than the request (no jump past it).
    assert np.linalg.norm(move.pose.p - start.p) <= np.linalg.norm(np.array([x, y]) - start.p) * np.sqrt(2) + 1e-9


def test_drive_inside_the_valid_set_is_forward_kinematics_in_the_same_mode():
    move = drive_to(P, HOME, (0.2, 0.1))
    assert not move.clamped
    np.testing.assert_allclose(move.pose.p, forward_kinematics_both(P, (0.2, 0.1)).plus)
    np.testing.assert_allclose(inverse_kinematics(P, move.pose.p), (0.2, 0.1))


def test_drive_to_both_zero_stops_where_the_assembly_modes_merge():
    """d = (0, 0) puts the leg circles 0.55 m apart, more than 2 l_a: the modes merge on the way."""
    move = drive_to(P, HOME, (0.0, 0.0))
    assert move.clamped and "modes merge" in str(move.reason)
    sol = forward_kinematics_both(P, move.pose.d)
    assert np.linalg.norm(sol.plus - sol.minus) < 0.1 * P.l_a  # the two solutions are close
    _assert_valid(P, move.pose)


def test_drive_past_the_stroke_stops_at_the_end():
    move = drive_to(P, HOME, (0.5, 0.13))
    assert move.clamped and "slider 1 is against its end-stop at the end of its rail (d1 = Δd = 300.0 mm)" in str(
        move.reason
    )
    assert move.pose.d[0] == pytest.approx(P.stroke, abs=1e-6)


def test_switch_mode_goes_to_the_other_circle_intersection_and_back():
    pose = drive_to(P, HOME, (0.2, 0.25)).pose
    other = switch_mode(P, pose)
    assert not other.clamped
    np.testing.assert_allclose(other.pose.d, pose.d)
    assert other.pose.mode(P) == -1
    np.testing.assert_allclose(other.pose.p, forward_kinematics_both(P, pose.d).minus)
    back = switch_mode(P, other.pose)
    np.testing.assert_allclose(back.pose.p, pose.p, atol=1e-12)


def test_switch_mode_is_refused_at_home_where_the_other_mode_is_singular():
    """At home the other intersection is (-l_a, -l_a): c_1 = 0, leg 1 at an inverse singularity."""
    move = switch_mode(P, HOME)
    why = str(move.reason)
    assert why.startswith("the other assembly mode is not usable here: leg 1 would come too close to an inverse")
    assert "perpendicular to rail 1" in why and "actuator 1 loses its authority" in why
    assert "(cos θ1 = 0.000, eq. 11)" in why  # c_1 = 0 exactly there: never "-0.000"
    assert move.pose is HOME


def test_place_accepts_valid_and_refuses_invalid_positions():
    assert not place(P, HOME, (0.1, 0.05)).clamped
    refused = place(P, HOME, (0.25, 0.0))
    # d_1 = 0.25 + 0.39 - 0.26 = 380 mm (eq. 4), beyond the 300 mm stroke
    assert refused.clamped and refused.pose is HOME
    assert "actuator 1 would leave its stroke: slider 1 would have to be at d1 = 380.0 mm" in str(refused.reason)
    with pytest.raises(InputError):
        place(P, HOME, (np.inf, 0.0))


def test_pose_codes_name_the_first_failing_rule():
    p = np.array([[0.0, 0.0], [0.2, 0.0], [-0.183, -0.183]])
    d = inverse_kinematics(P, p)
    codes = pose_codes(P, p, d, mode=1)
    assert codes.tolist() == [PoseStatus.REGULAR, PoseStatus.OUT_OF_STROKE, PoseStatus.NEAR_DIRECT]
    near_edge = np.array([-0.2599, -0.24])  # |p_1| -> l_a: cos θ_2 -> 0
    assert pose_codes(P, near_edge, ik_branch(P, near_edge, (1, 1)), mode=-1) in (
        PoseStatus.NEAR_INVERSE,
        PoseStatus.OUT_OF_STROKE,
    )


def test_requests_must_be_finite():
    with pytest.raises(InputError):
        drag_to(P, HOME, (np.nan, 0.0))
    with pytest.raises(InputError):
        drive_to(P, HOME, (0.1,))


def test_why_not_names_the_leg_and_its_cosine_from_the_geometry():
    """Lesson 6's pose: cos θ1 = c_1 / l_a with c_1 = p_1 - d_1 + a - b (eq. 23), read off the joints."""
    p = np.array([-0.2252, -0.2582])
    d = inverse_kinematics(P, p)
    a1, b1 = np.array([d[0] - P.a, 0.0]), p - np.array([P.b, 0.0])  # A_1 = (d_1 - a) e_1, B_1 = P - b e_1
    cos1 = (b1 - a1)[0] / np.linalg.norm(b1 - a1)
    why = str(why_not(P, PoseStatus.NEAR_INVERSE, p, d, "drag"))
    assert why.startswith("leg 1 would come too close to an inverse singularity")
    assert f"(cos θ1 = {cos1:.3f}, eq. 11)" in why


def test_why_not_never_writes_a_negative_zero():
    p = np.array([0.1, 0.05])
    d = inverse_kinematics(P, p)
    d_bad = d + np.array([np.sqrt(P.l_a**2 - p[1] ** 2) + 1e-13, 0.0])  # c_1 = -1e-13 m: cos θ1 = -4e-13
    why = str(why_not(P, PoseStatus.NEAR_INVERSE, p, d_bad, "drag"))
    assert "cos θ1 = 0.000" in why and "-0.0" not in why and "−0.0" not in why
