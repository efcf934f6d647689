"""The app's background jobs (trajectory runs, floor maps, control-lab simulations, plans), off the callback path.

viser runs callbacks in a thread pool and the app serialises every state change under the hub's lock; a
computation of 20-200 ms inside that lock would stall every other tab's drag. Jobs submitted here run in
:class:`tpm_viz.classroom.jobs.FairJobs`, *outside* the lock: one pending job per tab and kind (latest wins), tabs
served in turns (the tab served longest ago first), bounded per tab and in all; a job's ``done`` callback publishes
the result (taking the lock itself, briefly). This module is the thin adapter: the pool size, the log of bugs
(:func:`~tpm_viz.classroom.guard.report`), and the tab a job belongs to.
"""

from __future__ import annotations

from collections.abc import Callable, Hashable

from tpm_viz.classroom.guard import report
from tpm_viz.classroom.jobs import Done, FairJobs

__all__ = ["THREADS", "Worker"]

THREADS = 1
"""Pool size: jobs are numpy/pinocchio/toppra code that holds the GIL most of the time, so a second thread adds
contention with the drags, not throughput (``benchmarks/bench_worker_flood.py``)."""


def _report(exc: Exception, what: str) -> None:
    """A job's bug, to the app's log (looked up at each call: tests replace :func:`report`)."""
    report(exc, what)


class Worker:
    """Run ``fn()`` in the pool, then ``done(result, error)`` (``error`` a :class:`TpmVizError`, a bug, or
    :class:`~tpm_viz.core.errors.BusyError` when the queue refused the job)."""

    def __init__(self, name: str = "tpm-viz-worker", threads: int | None = None) -> None:
        self.jobs = FairJobs(THREADS if threads is None else threads, name=name, report=_report)

    def submit(
        self,
        key: Hashable,
        fn: Callable[[], object],
        done: Done | None,
        tab: Hashable | None = None,
        dropped: Callable[[], None] | None = None,
    ) -> bool:
        """Queue ``fn`` as ``tab``'s job ``key`` (a pending job of the same tab and key is replaced: latest wins);
        ``tab`` None: the job is its own tab. ``dropped()`` is called if it will never run. False: refused."""
        return self.jobs.submit(key if tab is None else tab, key, fn, done, dropped)

    def leave(self, tab: Hashable) -> None:
        """``tab`` closed: its pending jobs are dropped."""
        self.jobs.leave(tab)

    def idle(self) -> bool:
        """Whether nothing is queued or running (for tests and benchmarks)."""
        return self.jobs.idle()
