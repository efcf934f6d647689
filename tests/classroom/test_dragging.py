"""Where and when drags are committed (classroom/dragging.py): never on the event loop (it must stay free to read and
send
every tab's messages), one drain per session, and a drain scheduled for a session is that session's even if the tab
that scheduled it switched to its own copy meanwhile (the shared mechanism must never be left with a drain that
nobody runs)."""

from __future__ import annotations

import threading

import numpy as np

from tests.support.protocol import wait_for
from tpm_viz.classroom.drags import PendingDrag


def _state(view):
    with view.hub.lock:
        return view.session.state


def test_an_own_copy_drag_is_committed_in_the_drag_pool_not_on_the_event_loop(connect, monkeypatch):
    client, view = connect()
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: not view.session.shared, what="the own copy")
    threads: list[str] = []
    original = type(view).commit_drag

    def commit_drag(self, phase, position):
        threads.append(threading.current_thread().name)
        return original(self, phase, position)

    monkeypatch.setattr(type(view), "commit_drag", commit_drag)
    client.drag(view.scene.gizmo, str(view.client.client_id), [(0.03, 0.02, 0.09), (0.04, 0.01, 0.09)])
    wait_for(lambda: np.allclose(_state(view).pose.p, (0.04, 0.01)), what="the last drag applied")
    assert threads and all(name.startswith("tpm-viz-drag") for name in threads), threads


def test_a_drain_scheduled_for_the_shared_mechanism_stays_its_own_after_the_tab_leaves(connect):
    (_c1, v1), (c2, v2) = connect(), connect()
    hub = v1.hub
    shared = v1.session
    with hub.lock:  # a drag queued and its drain scheduled, then the tab switches before the drain runs
        shared.drags.push(v1, PendingDrag("update", np.array([0.05, 0.0, 0.09]), next(hub.arrivals)))
        shared.drags.scheduled = True
        v1.switch(True)
    v1.drags.drain(shared)  # the late drain: of the shared session, whatever v1 shows now
    assert not shared.drags.scheduled
    c2.drag(v2.scene.gizmo, str(v2.client.client_id), [(-0.03, 0.02, 0.09)])
    wait_for(lambda: np.allclose(_state(v2).pose.p, (-0.03, 0.02)), what="the next drag of the shared mechanism")
    assert not np.allclose(_state(v1).pose.p, (-0.03, 0.02))  # the own copy did not follow


def test_a_drag_asks_whether_the_tab_may_change_its_session_once_per_commit(connect, monkeypatch):
    """Permission is checked where the commit happens, not on arrival, in the drain and again in the commit."""
    client, view = connect()
    hub = view.hub
    asked: list[object] = []
    commits: list[object] = []
    may_change, commit = hub.access.may_change, hub.commit
    monkeypatch.setattr(hub.access, "may_change", lambda v, s: asked.append(v) or may_change(v, s))
    monkeypatch.setattr(hub, "commit", lambda *a, **k: commits.append(a[0]) or commit(*a, **k))
    client.drag(view.scene.gizmo, str(view.client.client_id), [(0.03, 0.02, 0.09), (0.04, 0.01, 0.09)])
    wait_for(lambda: np.allclose(_state(view).pose.p, (0.04, 0.01)), what="the last drag applied")
    with hub.lock:
        assert commits and asked == [view] * len(commits)
