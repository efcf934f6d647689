"""Gizmo drags waiting to be committed to one session: the latest value wins across the tabs allowed to change it.

A class pulling the shared platform at once must make one commit per round, not one per student. Each tab pushes
its drag events here (in arrival order, numbered by the hub); the queue says when the session's next drain is due
(:meth:`DragQueue.push`, :meth:`DragQueue.begin`): at once, or when the pacing interval since the last round is over,
and only one drain is scheduled at a time. A drain empties the queue: the latest event of the tabs that may change the
session is committed, on behalf of the tab that sent it; the other tabs whose drag ended are told so (their gizmos
are written back by that commit). No viser here.
"""

from __future__ import annotations

import weakref
from collections.abc import Callable, Hashable
from dataclasses import dataclass, field
from typing import Generic, TypeVar

import numpy as np

__all__ = ["DragQueue", "PendingDrag", "Take"]

V = TypeVar("V", bound=Hashable)
"""A tab (any object that can be weakly referenced: the queue never looks inside it, and never keeps a tab that
left alive, even if one of its drags arrives after it left)."""


@dataclass(frozen=True)
class PendingDrag:
    """One gizmo event: ``phase`` (``start``, ``update``, ``end``), ``position`` [m] (x, y, z), arrival number."""

    phase: str
    position: np.ndarray
    arrival: int


@dataclass(frozen=True)
class Take(Generic[V]):
    """What a drain commits: the latest drag (``mover``'s), and the tabs whose drag ended in this round."""

    mover: V
    latest: PendingDrag
    ended: tuple[V, ...] = ()


@dataclass
class DragQueue(Generic[V]):
    """The pending drags of one session's tabs (mutated under the hub's lock, or on the event loop for ``push``)."""

    scheduled: bool = False
    """A drain is scheduled (a drag that arrives meanwhile is taken by it)."""
    next_at: float = 0.0
    """``time.monotonic()`` before which no further drag is committed (pacing of a session shown by many tabs)."""
    _pending: weakref.WeakKeyDictionary[V, list[PendingDrag]] = field(default_factory=weakref.WeakKeyDictionary)
    _taken: weakref.WeakKeyDictionary[V, int] = field(default_factory=weakref.WeakKeyDictionary)
    """Per tab, the arrival number of its drag last taken: an older one of that tab queued late is dropped."""

    def push(self, view: V, drag: PendingDrag, now: float | None = None) -> float | None:
        """Queue ``view``'s drag event; with ``now`` (``time.monotonic()``), also schedule the session's drain:
        returns the delay [s] after which it must run (0: at once), or None if one is already scheduled (it takes
        this drag)."""
        self._pending.setdefault(view, []).append(drag)
        if now is None or self.scheduled:
            return None
        self.scheduled = True
        return max(0.0, self.next_at - now)

    def begin(self, now: float, interval: float) -> None:
        """A drain starts at ``now``: a drag that arrives from now on schedules the next one, due ``interval`` [s]
        later at the earliest."""
        self.scheduled = False
        self.next_at = now + interval

    def first(self) -> V | None:
        """The tab with the oldest waiting drag (the next to drain), or None."""
        best: tuple[int, V] | None = None
        for view, drags in list(self._pending.items()):
            arrival = min((d.arrival for d in drags), default=None)
            if arrival is not None and (best is None or arrival < best[0]):
                best = (arrival, view)
        return None if best is None else best[1]

    def has(self, view: V) -> bool:
        """Whether ``view`` has drags waiting."""
        return bool(self._pending.get(view))

    def waiting(self) -> list[V]:
        """The views with drags waiting."""
        return [v for v, drags in self._pending.items() if drags]

    def drop(self, view: V) -> None:
        """Forget ``view``'s drags (it left the session or closed)."""
        self._pending.pop(view, None)
        self._taken.pop(view, None)

    def take(self, origin: V, may_merge: Callable[[V], bool]) -> Take[V] | None:
        """Remove ``origin``'s drags and, if ``may_merge(origin)``, those of every other view with
        ``may_merge(view)``; return the latest of them by arrival, or None if none is newer than what was taken from
        the same tab before (a drag queued late must not undo a newer one of that tab). ``may_merge`` is asked only
        when other tabs have drags waiting: a lone dragger's permission is the commit's to check."""
        own = self._fresh(origin, self._pending.pop(origin, []))
        if not own:
            return None
        latest, mover = max(own, key=lambda d: d.arrival), origin
        ended: list[V] = []
        if self.waiting() and may_merge(origin):
            for view in list(self._pending):
                drags = self._fresh(view, self._pending[view])
                if not drags or not may_merge(view):
                    continue
                del self._pending[view]
                if any(d.phase == "end" for d in drags):
                    ended.append(view)
                newest = max(drags, key=lambda d: d.arrival)
                if newest.arrival > latest.arrival:
                    latest, mover = newest, view
        if mover is not origin and any(d.phase == "end" for d in own):
            ended.append(origin)
        return Take(mover, latest, tuple(ended))

    def _fresh(self, view: V, drags: list[PendingDrag]) -> list[PendingDrag]:
        """``drags`` newer than the last one taken from ``view`` (and remember the newest as taken)."""
        last = self._taken.get(view, -1)
        fresh = [d for d in drags if d.arrival > last]
        if fresh:
            self._taken[view] = max(d.arrival for d in fresh)
        return fresh
