"""Home, settle-after-parameter-change and demonstration poses (tpm_viz.app.poses)."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import InputError, InvalidParametersError, Params, SingularityThresholds
from tpm_viz.app.moves import Pose, check
from tpm_viz.app.poses import DEMO_KINDS, home_pose, preset_pose, settle
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus

P = Params.paper()


def test_home_of_the_paper_prototype_is_the_origin():
    """At p = 0 eq. (4) gives d_i = a - b - l_a = 130 mm, inside the 300 mm stroke."""
    home = home_pose(P)
    np.testing.assert_allclose(home.p, 0.0)
    np.testing.assert_allclose(home.d, P.a - P.b - P.l_a)


def test_home_moves_off_the_origin_when_the_origin_is_out_of_stroke():
    params = P.replace(stroke=0.1)  # d_i(0) = 130 mm > 100 mm
    home = home_pose(params)
    assert check(params, home) == PoseStatus.REGULAR
    assert np.linalg.norm(home.p) > 0.01


def test_no_valid_pose_is_an_invalid_parameter_set():
    """Params accepts a stroke just above a - b - sqrt(2) l_a (the diagonal extreme of eq. 4), but that extreme,
    p_1 = p_2 = -l_a / sqrt(2), is on the direct singularity: no pose keeps the margins."""
    k = 0.75 - P.b
    params = P.replace(a=0.75, stroke=k - np.sqrt(2) * P.l_a + 2e-5)
    with pytest.raises(InvalidParametersError, match="no valid pose"):
        home_pose(params)


def test_settle_keeps_a_still_valid_pose():
    pose = Pose.working(P, (0.05, -0.02))
    move = settle(P.replace(m_p=5.0), pose)
    assert not move.clamped
    np.testing.assert_allclose(move.pose.p, pose.p)


def test_settle_moves_an_invalid_pose_to_a_valid_one_and_says_so():
    pose = Pose.working(P, (0.15, 0.0))  # d_1 = 280 mm
    params = P.replace(stroke=0.2)
    move = settle(params, pose)
    assert move.clamped and "nearest valid pose" in str(move.reason)
    assert check(params, move.pose) == PoseStatus.REGULAR


@pytest.mark.parametrize("kind", DEMO_KINDS)
def test_demo_poses_are_valid_and_show_their_condition(kind):
    limits, thr = MOVE_LIMITS, SingularityThresholds()
    move = preset_pose(P, kind)
    pose = move.pose
    assert not move.clamped, move.reason
    assert check(P, pose) == PoseStatus.REGULAR
    jac = jacobians(P, pose.p, pose.d)
    if kind == "inverse":
        assert limits.inverse < min(abs(jac.jq[0, 0]), abs(jac.jq[1, 1])) < thr.inverse
    elif kind == "direct":
        assert limits.direct < abs(float(jac.det_jx)) < thr.direct
    else:
        assert np.min(np.minimum(pose.d, P.stroke - pose.d)) < 1e-6


def test_demo_pose_explains_when_the_stroke_keeps_the_mechanism_away():
    params = P.replace(stroke=0.2)
    move = preset_pose(params, "direct")
    if move.clamped:
        assert "closest" in str(move.reason)
    assert check(params, move.pose) == PoseStatus.REGULAR


def test_demo_kind_is_checked():
    with pytest.raises(InputError):
        preset_pose(P, "nope")
