"""One tab's gizmo drags: when they are committed.

A gizmo event arrives on viser's event loop. It is queued in the session's :class:`~.drags.DragQueue` (latest value
wins) and one drain per session is scheduled in the hub's drag pool: at once, or when the session's interval since
its last commit is over (:data:`SHARED_DRAG_INTERVAL` for the shared mechanism, the load-dependent interval of
:mod:`tpm_viz.classroom.pacing` for an own copy). The event loop itself never computes a commit: it stays free to read
every tab's messages and send every tab its updates (``benchmarks/bench_load.py --mode hall``: with commits of own
copies on the loop, the watchers' updates waited behind them). The commit itself is the view's
(:meth:`~.session.View.commit_drag`).
"""

from __future__ import annotations

import asyncio
import time

import numpy as np

from tpm_viz.classroom.drags import PendingDrag
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.session import Session, View
from tpm_viz.errors import TpmVizError

__all__ = ["SHARED_DRAG_INTERVAL", "Dragging"]

SHARED_DRAG_INTERVAL = 0.025
"""Drags of the shared mechanism are committed at most once per this many seconds (40 Hz; latest value wins in
between), however many students pull it at once: one dragger at the browser's 20 Hz is never delayed, thirty keep
the server responsive (bench_load.py --mode shared). Own copies are paced by the load
(:mod:`tpm_viz.classroom.pacing`)."""


def _internal_error(drags: Dragging, exc: Exception) -> None:
    """The guard's report to the tab whose drag failed (the traceback is in the server log)."""
    drags.view.refuse(f"internal error ({type(exc).__name__}), logged on the server")


class Dragging:
    """The gizmo drags of one tab (``view``)."""

    def __init__(self, view: View) -> None:
        self.view = view
        self._refusing = False  # a refusal of this tab's drags is queued in the pool

    @guarded
    async def on_drag(self, event) -> None:
        """Gizmo events, in arrival order on the event loop: queue a snapshot and schedule the session's drain (one
        at a time; a drag that arrives while one is scheduled is taken by it)."""
        view, hub = self.view, self.view.hub
        drag = PendingDrag(event.phase, np.array(event.target.position, dtype=float), next(hub.arrivals))
        session = getattr(view, "session", None)  # None while the tab is still being built (under the lock)
        if session is None:
            hub.drag_pool.submit(self._after_build, drag)  # waits for the lock the build holds
            return
        session.drags.push(view, drag)
        queue = session.drags
        if not hub.access.may_change(view, session):  # refused in the pool, to this tab only, once per round:
            if not self._refusing:  # a student tugging at the presenter's mechanism does not fill the pool
                self._refusing = True
                hub.drag_pool.submit(self._refuse, session)
            return
        if queue.scheduled:
            return  # the scheduled drain takes this drag (latest value wins)
        queue.scheduled = True
        delay = queue.next_at - time.monotonic()
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
        """Apply the latest pending gizmo position of ``session`` (default: the tab's; latest value wins); ``end``
        writes the gizmo back. The drain is the session's it was scheduled for, even if this tab left it since.

        Latest value wins across the session: the pending drags of every other tab that may change this
        mechanism are merged into the one commit (30 students pulling the shared platform at once make one
        commit per round, not 30)."""
        view, hub = self.view, self.view.hub
        with hub.lock:
            session = view.session if session is None else session
            queue = session.drags
            now = time.monotonic()
            if hub.access.may_change(view, session):  # the session's drain (not a refusal to one tab)
                queue.scheduled = False  # first: a drag that arrives from now on schedules the next drain,
                paced = SHARED_DRAG_INTERVAL if session.shared else hub.pacer.interval(now)  # own copies: by load
                queue.next_at = now + paced  # not before this
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
            finally:
                if not session.shared:
                    end = time.monotonic()  # wall time: the commits hold the hub, however the GIL is shared
                    hub.pacer.spent(end - now, end)

    @guarded(on_error=_internal_error)
    def _refuse(self, session: Session) -> None:
        self._refusing = False  # first: a drag that arrives from now on queues the next refusal
        self.drain(session)

    @guarded(on_error=_internal_error)
    def _after_build(self, drag: PendingDrag) -> None:
        with self.view.hub.lock:
            self.view.session.drags.push(self.view, drag)
            self.drain()
