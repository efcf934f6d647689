"""A busy server draws a dragged own copy's mechanism at every commit and its numbers less often (classroom/session.py,
classroom/pacing.py ``BUSY_NUMBERS_INTERVAL``): with the pacer pacing, the panel of a copy dragged for 1.2 s is
refreshed
at the start, once a second and at the end, however many commits there were; without pacing it keeps its 4 Hz.
The mechanism itself follows every commit either way, and the numbers shown at the end are those of the last pose,
with both models."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz.app.readouts import Load
from tpm_viz.classroom.pacing import BUSY_NUMBERS_INTERVAL
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.ui import panels


class Clock:
    def __init__(self) -> None:
        self.now = 1000.0

    def monotonic(self) -> float:
        return self.now


@pytest.mark.parametrize("busy", [False, True])
def test_a_paced_own_copy_moves_at_every_commit_and_refreshes_its_numbers_once_a_second(connect, monkeypatch, busy):
    client, view = connect()
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: not view.session.shared, what="the own copy")
    with view.hub.lock:  # the switch is over (it joins the copy, then draws it, under the lock)
        pass
    clock = Clock()
    monkeypatch.setattr(panels, "time", clock)
    monkeypatch.setattr(view.hub.pacer, "interval", lambda now: 0.2 if busy else 0.0)
    refreshed: list[float] = []
    moved: list[tuple[float, float]] = []
    dashboard_in = Snapshot.dashboard_in

    def counting(self, lang):
        refreshed.append(clock.now)
        return dashboard_in(self, lang)

    monkeypatch.setattr(Snapshot, "dashboard_in", counting)
    update = view.scene.update

    def drawn(frame, dragging=False):
        moved.append(tuple(np.round(frame.readout.p, 6)))
        return update(frame, dragging=dragging)

    monkeypatch.setattr(view.scene, "update", drawn)
    targets = [(round(0.01 * k, 6), round(0.004 * k, 6)) for k in range(13)]  # 13 commits, 0.1 s apart: 0 .. 1.2 s
    with view.hub.lock:  # a platform in motion: both models have something to say
        state = view.session.state
        view.hub.commit(view.session, dataclasses.replace(state, load=Load("dynamic", dp=(0.3, -0.2), ddp=(4, 1))))
        for k, (x, y) in enumerate(targets):
            clock.now = 1000.0 + 0.1 * k
            view.commit_drag("update", np.array([x, y, 0.09]))
        clock.now += 0.05
        view.commit_drag("end", np.array([*targets[-1], 0.09]))
    assert moved[-14:] == [(x, y) for x, y in targets] + [targets[-1]]  # the mechanism: every commit
    expected = [1000.0, 1001.0, 1001.25] if busy else [1000.0, 1000.3, 1000.6, 1000.9, 1001.2, 1001.25]
    assert refreshed == pytest.approx(expected, abs=1e-9)
    assert BUSY_NUMBERS_INTERVAL == pytest.approx(1.0)
    shown = view.session.frame.displayed_readout  # the last pose, both models
    params, p = view.session.state.params, np.array(targets[-1])
    tau = inverse_dynamics(params, p, [0.3, -0.2], [4.0, 1.0])
    assert np.all(np.abs(tau) > 1.0)
    np.testing.assert_allclose(shown.forces.tau, tau, rtol=1e-12)
    np.testing.assert_allclose(shown.forces.tau_ref, tau, rtol=1e-9)
