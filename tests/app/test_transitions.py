"""State transitions that a lecturer meets after a demo or a playback (tpm_viz.app.transitions)."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz.app import transitions as T
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState, TrajectorySample
from tpm_viz.paper.jacobians import jacobians

P_STATE = AppState.initial()


def _sample_of_the_circle(t: float = 0.17) -> AppState:
    """The state the player leaves behind at time ``t`` of the paper's circle (T = 0.5 s)."""
    source = Source.paper("circle", 0.5)
    p, dp, ddp = (x[0] for x in source.motion(np.array([t])))
    pose = Pose.working(P_STATE.params, p)
    return P_STATE.replace(
        pose=pose, load=Load("dynamic", dp=tuple(dp), ddp=tuple(ddp)), trajectory=TrajectorySample("circle", 0.5, t)
    )


@pytest.mark.parametrize(
    "action",
    [
        T.home,
        T.switch,
        lambda s: T.drag(s, (0.02, 0.01, 0.0)),
        lambda s: T.move(s, (10.0, -5.0)),
        lambda s: T.drive(s, 0, 150.0),
    ],
)
def test_moving_by_hand_after_a_playback_shows_the_forces_at_rest(action):
    """Issue 11: Home after a playback showed τ = -17.94 N for a platform at rest. At rest with no external force the
    statics of eq. (13) give τ = J⁻ᵀ(-f_ext) = 0 exactly."""
    sampled = _sample_of_the_circle()
    assert np.linalg.norm(evaluate(sampled.params, sampled.pose, sampled.load).forces.tau) > 10.0  # moving: forces
    after = action(sampled)
    assert after.load.mode == "static" and after.trajectory.kind == "none"
    tau = evaluate(after.params, after.pose, after.load).forces.tau
    assert tau == pytest.approx([0.0, 0.0], abs=1e-12)


def test_a_typed_external_force_survives_and_gives_eq13():
    sampled = _sample_of_the_circle().replace(load=Load("dynamic", f_ext=(3.0, -4.0), dp=(0.5, 0.0), ddp=(2.0, 1.0)))
    after = T.home(sampled)
    jac = jacobians(after.params, after.pose.p, after.pose.d)
    expected = np.linalg.solve(jac.j.T, -np.array([3.0, -4.0]))  # eq. (13) with f = -f_ext
    assert evaluate(after.params, after.pose, after.load).forces.tau == pytest.approx(expected, rel=1e-12)


def test_a_dynamic_load_typed_by_hand_stays_when_the_platform_is_dragged():
    typed = P_STATE.replace(load=Load("dynamic", dp=(0.4, -0.2), ddp=(3.0, 1.0)))
    after = T.drag(typed, (0.03, 0.02, 0.0))
    assert after.load == typed.load
