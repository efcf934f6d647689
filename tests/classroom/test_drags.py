"""The drag queue of a session (tpm_viz.classroom.drags): latest value wins across tabs, late drags never undo newer
ones."""

from __future__ import annotations

import gc
import weakref

import numpy as np
import pytest

from tpm_viz.classroom.drags import DragQueue, PendingDrag


class Tab:
    """A stand-in for a browser tab (the queue holds its tabs weakly)."""

    def __init__(self, name: str) -> None:
        self.name = name

    def __repr__(self) -> str:
        return self.name


def _tabs(*names: str) -> list[Tab]:
    return [Tab(n) for n in names]


def _drag(arrival: int, phase: str = "update") -> PendingDrag:
    return PendingDrag(phase, np.array([arrival * 1e-3, 0.0, 0.0]), arrival)


def test_the_latest_arrival_wins_across_the_tabs_that_may_merge():
    q: DragQueue[Tab] = DragQueue()
    a, b, c = _tabs("a", "b", "c")
    q.push(a, _drag(1))
    q.push(b, _drag(3, "end"))
    q.push(c, _drag(5))  # c may not change the session (a student in presenter mode): never merged
    q.push(a, _drag(2))
    take = q.take(a, lambda v: v is not c)
    assert take is not None and take.mover is b and take.latest.arrival == 3
    assert take.ended == (b,)  # b's drag ended: its gizmo is written back by this commit
    assert q.waiting() == [c] and not q.has(a) and not q.has(b)


def test_a_drag_queued_late_never_undoes_a_newer_one():
    """A drag sent while the tab was being built is pushed after newer ones were committed."""
    q: DragQueue[Tab] = DragQueue()
    (a,) = _tabs("a")
    q.push(a, _drag(10))
    assert q.take(a, lambda v: True).latest.arrival == 10
    q.push(a, _drag(4))  # late
    assert q.take(a, lambda v: True) is None
    q.push(a, _drag(4))
    q.push(a, _drag(11))  # pushed after the older one: order of pushes is not the order of arrivals
    q.push(a, _drag(7))
    assert q.take(a, lambda v: True).latest.arrival == 11


def test_tabs_whose_drag_ended_inside_another_commit_are_told():
    q: DragQueue[Tab] = DragQueue()
    a, b, c = _tabs("a", "b", "c")
    q.push(a, _drag(1, "end"))
    q.push(b, _drag(2))
    take = q.take(a, lambda v: True)
    assert take.mover is b and take.ended == (a,)
    q.push(c, _drag(3, "end"))
    q.push(a, _drag(4))
    take = q.take(a, lambda v: True)
    assert take.mover is a and take.ended == (c,)


def test_a_tab_that_may_not_merge_never_makes_anothers_drags_stale():
    """Presenter mode: a student's drag (refused on the shared mechanism) arrives last; the presenter's drag that
    arrived before it is still committed."""
    q: DragQueue[Tab] = DragQueue()
    presenter, student = _tabs("presenter", "student")
    q.push(presenter, _drag(1))
    q.push(student, _drag(2))
    assert q.take(student, lambda v: v is presenter).mover is student  # not merged: refused by its commit
    assert q.take(presenter, lambda v: v is presenter).latest.arrival == 1


def test_a_tab_that_left_is_not_kept_alive_by_a_late_drag():
    """A drag that arrives after its tab left the session (a switch to an own copy, a closed tab) must not keep the
    tab, its scene and its panel in memory for the life of the shared mechanism."""
    q: DragQueue[Tab] = DragQueue()
    gone, stays = _tabs("gone", "stays")
    q.push(gone, _drag(1))
    q.push(stays, _drag(2))
    assert q.take(stays, lambda v: True).mover is stays  # merged: gone's drag taken, gone remembered as taken
    q.push(gone, _drag(3))  # late, after it left
    ref = weakref.ref(gone)
    del gone
    gc.collect()
    assert ref() is None and q.waiting() == []


def test_the_queue_schedules_one_drain_at_a_time_and_paces_the_rounds():
    q: DragQueue[Tab] = DragQueue()
    a, b = _tabs("a", "b")
    assert q.push(a, _drag(1), now=10.0) == 0.0  # the first drag: a drain at once
    assert q.push(b, _drag(2), now=10.001) is None  # one is scheduled: it takes this drag too
    q.begin(now=10.002, interval=0.025)  # the drain starts: the next round not before 10.027
    assert q.push(a, _drag(3), now=10.010) == pytest.approx(0.017)
    assert q.push(a, _drag(4), now=10.011) is None
    q.begin(now=10.030, interval=0.0)
    assert q.push(a, _drag(5), now=10.040) == 0.0  # the interval is over: at once
    assert q.push(b, _drag(6)) is None  # without ``now``: only queued (nothing scheduled by it)


def test_the_next_tab_to_drain_is_the_one_with_the_oldest_drag():
    q: DragQueue[Tab] = DragQueue()
    a, b = _tabs("a", "b")
    assert q.first() is None
    q.push(a, _drag(7))
    q.push(b, _drag(3))
    q.push(a, _drag(9))
    assert q.first() is b
    q.take(b, lambda v: False)  # b may not merge: only its own drags taken
    assert q.first() is a
