"""One tab's gizmo drags: queued on the event loop, committed in the hub's drag pool.

A gizmo event arrives on viser's event loop. It is pushed onto the session's :class:`~.drags.DragQueue` (latest
value wins), which says when the session's one drain is due: at once, or when the session's interval since its last
round is over (:data:`SHARED_DRAG_INTERVAL` for the shared mechanism, the load-dependent interval of
:mod:`tpm_viz.classroom.pacing` for an own copy). The drain runs in the hub's drag pool and empties the queue; the
event loop itself never computes a commit: it stays free to read every tab's messages and send every tab its
updates (``benchmarks/bench_load.py --mode hall``). Whether a tab may change the session is checked by the commit
(:meth:`~.session.Hub.commit`), which refuses it to that tab only; the commit itself is the view's
(:meth:`~.session.View.commit_drag`). The gizmo is wired once the tab has joined its session.
"""

from __future__ import annotations

import asyncio
import time
from typing import Protocol

import numpy as np
import numpy.typing as npt

from tpm_viz.classroom.drags import PendingDrag, Take
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.session import Session, View
from tpm_viz.core.errors import TpmVizError

__all__ = ["SHARED_DRAG_INTERVAL", "Dragging", "GizmoEvent"]

SHARED_DRAG_INTERVAL = 0.025
"""Drags of the shared mechanism are committed at most once per this many seconds (40 Hz; latest value wins in
between), however many students pull it at once: one dragger at the browser's 20 Hz is never delayed, thirty keep
the server responsive (bench_load.py --mode shared). Own copies are paced by the load
(:mod:`tpm_viz.classroom.pacing`)."""


class Gizmo(Protocol):
    """The dragged gizmo as an event carries it (viser's ``TransformControlsHandle``)."""

    @property
    def position(self) -> npt.ArrayLike:
        """Its position [m] (x, y, z)."""


class GizmoEvent(Protocol):
    """A gizmo event (viser's ``TransformControlsEvent``): the drag's phase and the gizmo."""

    @property
    def phase(self) -> str:
        """``start``, ``update`` or ``end``."""

    @property
    def target(self) -> Gizmo:
        """The gizmo, at the dragged position."""


def _internal_error(drags: Dragging, exc: Exception) -> None:
    """The guard's report to the tab whose drag failed (the traceback is in the server log)."""
    drags.view.refuse(f"internal error ({type(exc).__name__}), logged on the server")


class Dragging:
    """The gizmo drags of one tab (``view``)."""

    def __init__(self, view: View) -> None:
        self.view = view

    @guarded
    async def on_drag(self, event: GizmoEvent) -> None:
        """Gizmo events, in arrival order on the event loop: queue a snapshot; schedule the session's drain if the
        queue says one is due (a drag that arrives while one is scheduled is taken by it)."""
        view, hub = self.view, self.view.hub
        drag = PendingDrag(event.phase, np.array(event.target.position, dtype=float), next(hub.arrivals))
        session = view.session
        delay = session.drags.push(view, drag, time.monotonic())
        if delay is None:
            return
        if delay > 0:
            asyncio.get_running_loop().call_later(delay, self._submit_drain, session)
            return
        self._submit_drain(session)

    def _submit_drain(self, session: Session) -> None:
        try:
            self.view.hub.drag_pool.submit(self.drain, session)  # guarded: errors are logged, never lost in a future
        except RuntimeError:  # the interpreter is shutting down
            return

    @guarded(on_error=_internal_error)
    def drain(self, session: Session | None = None) -> None:
        """One round of ``session``'s drags (default: the tab's; the drain is the session's it was scheduled for,
        even if this tab left it since): the tabs that may change it are merged into one commit, the latest value
        winning (30 students pulling the shared platform make one commit per round, not 30); a tab that may not
        is refused by its own commit. The queue is empty afterwards."""
        hub = self.view.hub
        with hub.lock:
            session = self.view.session if session is None else session
            queue = session.drags
            now = time.monotonic()
            queue.begin(now, SHARED_DRAG_INTERVAL if session.shared else hub.pacer.interval(now))  # own copies: load
            for gone in [v for v in queue.waiting() if v.closed]:
                queue.drop(gone)
            try:
                for _ in range(len(queue.waiting())):  # the tabs waiting now: later drags are the next round's
                    origin = queue.first()
                    if origin is None:
                        break
                    take = queue.take(origin, lambda other: hub.access.may_change(other, session))
                    if take is not None:
                        self._commit(take)
            finally:
                if not session.shared:
                    end = time.monotonic()  # wall time: the commits hold the hub, however the GIL is shared
                    hub.pacer.spent(end - now, end)

    @staticmethod
    def _commit(take: Take[View]) -> None:
        for other in take.ended:
            other.drag_ended()  # its drag ended: its gizmo is written back by this commit
        mover, latest = take.mover, take.latest
        try:
            mover.commit_drag(latest.phase, latest.position)
        except TpmVizError as exc:  # refused (presenter mode) or undrawable: the gizmo goes back when the drag ends
            mover.refuse(exc, resync=latest.phase == "end")
