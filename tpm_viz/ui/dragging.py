"""One tab's gizmo drags: when and where they are committed (on the event loop, or in the hub's drag pool).

A gizmo event arrives on viser's event loop. It is queued in the session's :class:`~.drags.DragQueue` (latest value
wins) and applied at once on the event loop when the session is shown by few tabs and the hub is free (a private
copy: no thread hop); otherwise a drain runs in the hub's drag pool, at most every :data:`SHARED_DRAG_INTERVAL` for
a session shown by many tabs. The commit itself is the view's (:meth:`~.session.View.commit_drag`).
"""

from __future__ import annotations

import asyncio
import time

import numpy as np

from tpm_viz.errors import TpmVizError
from tpm_viz.ui.drags import PendingDrag
from tpm_viz.ui.guard import guarded
from tpm_viz.ui.session import View

__all__ = ["INLINE_DRAG_VIEWS", "SHARED_DRAG_INTERVAL", "Dragging"]

INLINE_DRAG_VIEWS = 4
"""A drag of a session shown by at most this many tabs is applied on the event loop itself (bench_load.py)."""
SHARED_DRAG_INTERVAL = 0.025
"""Drags of a session shown by more than :data:`INLINE_DRAG_VIEWS` tabs are committed at most once per this many
seconds (40 Hz; latest value wins in between), however many students pull the shared platform at once: one
dragger at the browser's 20 Hz is never delayed, thirty keep the server responsive (bench_load.py --mode shared)."""


def _internal_error(drags: Dragging, exc: Exception) -> None:
    """The guard's report to the tab whose drag failed (the traceback is in the server log)."""
    drags.view.refuse(f"internal error ({type(exc).__name__}), logged on the server")


class Dragging:
    """The gizmo drags of one tab (``view``)."""

    def __init__(self, view: View) -> None:
        self.view = view

    @guarded
    async def on_drag(self, event) -> None:
        """Gizmo events, in arrival order on the event loop: keep a snapshot, then apply the latest one, here if
        the hub is free and few tabs show this session (a private copy: no thread hop), else in the pool, at most
        every :data:`SHARED_DRAG_INTERVAL` for a session shown by many tabs."""
        view, hub = self.view, self.view.hub
        drag = PendingDrag(event.phase, np.array(event.target.position, dtype=float), next(hub.arrivals))
        session = getattr(view, "session", None)  # None while the tab is still being built (under the lock)
        if session is None:
            hub.drag_pool.submit(self._after_build, drag)  # waits for the lock the build holds
            return
        session.drags.push(view, drag)
        if len(session.views) <= INLINE_DRAG_VIEWS:
            if hub.lock.acquire(blocking=False):
                try:
                    self.drain()  # ~1 ms, never blocks (the lock is ours, pushes and flushes are queued)
                finally:
                    hub.lock.release()
                return
        elif hub.access.may_change(view, session):
            if session.drags.scheduled:
                return  # the scheduled drain takes this drag (latest value wins)
            session.drags.scheduled = True
            delay = session.drags.next_at - time.monotonic()
            if delay > 0:
                asyncio.get_running_loop().call_later(delay, self._submit_drain)
                return
        self._submit_drain()

    def _submit_drain(self) -> None:
        try:
            self.view.hub.drag_pool.submit(self.drain)  # guarded: its errors are logged, never lost in a future
        except RuntimeError:  # the interpreter is shutting down
            return

    @guarded(on_error=_internal_error)
    def drain(self) -> None:
        """Apply the latest pending gizmo position (latest value wins); ``end`` writes the gizmo back.

        Latest value wins across the session: the pending drags of every other tab that may change this
        mechanism are merged into the one commit (30 students pulling the shared platform at once make one
        commit per round, not 30)."""
        view, hub = self.view, self.view.hub
        with hub.lock:
            session = view.session
            queue = session.drags
            queue.scheduled = False  # first: a drag that arrives from now on schedules the next drain,
            queue.next_at = time.monotonic() + SHARED_DRAG_INTERVAL  # not before this
            take = None if view.closed else queue.take(view, lambda other: hub.access.may_change(other, session))
            if take is None:
                if view.closed:
                    queue.drop(view)
                for other in queue.waiting():  # this tab left (or was merged) with the session's drain: hand it on
                    if not other.closed:
                        other.drain_drags()
                        break
                return
            for other in take.ended:
                other.drag_ended()  # its drag ended: its gizmo is written back by this commit
            mover, latest = take.mover, take.latest
            try:
                mover.commit_drag(latest.phase, latest.position)
            except TpmVizError as exc:  # the gizmo goes back to the last good pose when the drag ends
                mover.refuse(exc, resync=latest.phase == "end")

    @guarded(on_error=_internal_error)
    def _after_build(self, drag: PendingDrag) -> None:
        with self.view.hub.lock:
            self.view.session.drags.push(self.view, drag)
            self.drain()
