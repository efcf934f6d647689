"""The drag queue of a session (tpm_viz.ui.drags): latest value wins across tabs, late drags never undo newer ones."""

from __future__ import annotations

import numpy as np

from tpm_viz.ui.drags import DragQueue, PendingDrag


def _drag(arrival: int, phase: str = "update") -> PendingDrag:
    return PendingDrag(phase, np.array([arrival * 1e-3, 0.0, 0.0]), arrival)


def test_the_latest_arrival_wins_across_the_tabs_that_may_merge():
    q: DragQueue[str] = DragQueue()
    q.push("a", _drag(1))
    q.push("b", _drag(3, "end"))
    q.push("c", _drag(5))  # c may not change the session (a student in presenter mode): never merged
    q.push("a", _drag(2))
    take = q.take("a", lambda v: v != "c")
    assert take is not None and take.mover == "b" and take.latest.arrival == 3
    assert take.ended == ("b",)  # b's drag ended: its gizmo is written back by this commit
    assert q.waiting() == ["c"] and not q.has("a") and not q.has("b")


def test_a_drag_queued_late_never_undoes_a_newer_one():
    """A drag sent while the tab was being built is pushed after newer ones were committed."""
    q: DragQueue[str] = DragQueue()
    q.push("a", _drag(10))
    assert q.take("a", lambda v: True).latest.arrival == 10
    q.push("a", _drag(4))  # late
    assert q.take("a", lambda v: True) is None
    q.push("a", _drag(4))
    q.push("a", _drag(11))  # pushed after the older one: order of pushes is not the order of arrivals
    q.push("a", _drag(7))
    assert q.take("a", lambda v: True).latest.arrival == 11


def test_tabs_whose_drag_ended_inside_another_commit_are_told():
    q: DragQueue[str] = DragQueue()
    q.push("a", _drag(1, "end"))
    q.push("b", _drag(2))
    take = q.take("a", lambda v: True)
    assert take.mover == "b" and take.ended == ("a",)
    q.push("c", _drag(3, "end"))
    q.push("a", _drag(4))
    take = q.take("a", lambda v: True)
    assert take.mover == "a" and take.ended == ("c",)
