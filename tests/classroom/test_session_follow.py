"""Mid-drag, a dashboard shows the numbers of a frame at most ``LIVE_NUMBERS_INTERVAL`` old (classroom/snapshot.py
``Snapshot.follow``): watching tabs refresh their panels in turn, one at nearly every commit, and each refresh of a
new frame would evaluate the reference (Pinocchio) model again. Checked on a hub with 120 watching tabs: a 2 s drag
at 20 Hz evaluates the reference model about 2 / 0.25 times, not 40; the numbers a dashboard shows are those of one
earlier frame of the drag, both models of the same pose; the frame where the drag ends has its own numbers."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tpm_viz.app.state import AppState
from tpm_viz.classroom import snapshot
from tpm_viz.classroom.pacing import LIVE_NUMBERS_INTERVAL
from tpm_viz.classroom.session import Hub
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang
from tpm_viz.multibody import inverse_dynamics as pinocchio_inverse_dynamics
from tpm_viz.paper.kinematics import forward_kinematics

P = Params.paper()


class Clock:
    def __init__(self) -> None:
        self.now = 500.0

    def monotonic(self) -> float:
        return self.now


class Watcher:
    """A tab that refreshes its dashboard at every frame it is given (the worst case: all of them)."""

    def __init__(self) -> None:
        self.shown: list[str] = []

    def render(self, frame, *, dragging: bool = False) -> None:
        self.shown.append(frame.dashboard_in(Lang.EN))


def test_a_watched_drag_evaluates_the_reference_model_a_few_times_a_second(monkeypatch):
    clock = Clock()
    monkeypatch.setattr(snapshot, "time", clock)
    calls: list[np.ndarray] = []

    def reference(params, p, dp, ddp, f_ext=None):
        calls.append(np.array(p, dtype=float))
        return pinocchio_inverse_dynamics(params, p, dp, ddp, f_ext)

    hub = Hub(AppState.initial(P), reference=reference)
    watcher = Watcher()  # stands for the tab whose turn it is at each commit
    hub.join(watcher, private=False)
    state, calls[:] = hub.shared.state, []
    frames = []
    for n in range(40):  # 2 s at 20 Hz, committed as a drag of the shared mechanism
        clock.now = 500.0 + n / 20.0
        d = state.pose.d + np.array([0.001, -0.0005]) * n
        pose = dataclasses.replace(state.pose, d=d, p=forward_kinematics(P, d))
        hub.commit(hub.shared, dataclasses.replace(state, pose=pose), dragging=True)
        frames.append(hub.shared.frame)
    assert 2.0 / LIVE_NUMBERS_INTERVAL <= len(calls) <= 2.0 / LIVE_NUMBERS_INTERVAL + 1  # 8 or 9, not 40
    for frame in frames:  # each dashboard: the numbers of a frame at most 0.25 s older, of that frame's pose
        numbers = frame.numbers
        assert 0.0 <= frame.made_at - numbers.made_at < LIVE_NUMBERS_INTERVAL
        assert any(np.allclose(numbers.state.pose.p, p, rtol=0, atol=1e-15) for p in calls)
        assert frame.dashboard_in(Lang.EN) == numbers.dashboard_in(Lang.EN)
    assert len({id(f.numbers) for f in frames}) == len(calls)
    assert len(watcher.shown) == 41 and len(set(watcher.shown[1:])) == len(calls)
    hub.commit(hub.shared, frames[-1].state, dragging=False)  # the drag ends: its own numbers, at once
    assert hub.shared.frame.numbers is hub.shared.frame


@pytest.mark.parametrize("age", [0.0, 0.1, 0.24])
def test_a_frame_follows_a_recent_numbers_frame_only_mid_drag(monkeypatch, age):
    clock = Clock()
    monkeypatch.setattr(snapshot, "time", clock)
    hub = Hub(AppState.initial(P))
    first = hub.frame(hub.shared.state, dragging=True)
    clock.now += age
    later = hub.frame(hub.shared.state, dragging=True)
    later.follow(first, LIVE_NUMBERS_INTERVAL)
    assert later.numbers is first
    clock.now += LIVE_NUMBERS_INTERVAL  # too old now: new numbers
    last = hub.frame(hub.shared.state, dragging=True)
    last.follow(later, LIVE_NUMBERS_INTERVAL)
    assert last.numbers is last
