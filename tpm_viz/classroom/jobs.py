"""A fair queue of heavy jobs per tab, run by a small pool of threads.

Every tab (any hashable owner: a browser tab, a session) submits jobs of a few kinds (a trajectory run, a floor
map, a control-lab simulation, a plan), each 20-200 ms of computation. The rules:

- **Latest wins**: at most one job is pending per tab and kind; a newer one replaces it (a slider dragged through
  30 values computes the last one) and the replaced job's ``dropped`` is called. A tab's next job of a kind waits
  for its running one (never two of one slot at once, whatever the pool size).
- **Light tabs first, flooders in turns**: the next job is the one of the pending tab that asked least lately
  (:class:`Demand`: requests in the last few seconds, capped at :data:`FLOODER`); tabs at the cap, and ties, go
  by how long they have waited (round robin). With every flooder holding one pending job, a round of theirs is
  10 jobs; a tab that asks now and then skips it and waits for the jobs already running only.
- **Bounded**: ``per_tab`` pending jobs per tab and ``total`` in all; a job over a bound is refused: its ``done``
  gets :class:`~tpm_viz.core.errors.BusyError` (one line for the tab), it never runs.
- **A tab that leaves** (:meth:`FairJobs.leave`) has its pending jobs dropped.
- **Faults stay with their tab**: a job that raises hands the exception to its own ``done`` (a bug is also
  reported with its traceback) and the pool carries on.

``done(result, error)`` and ``dropped()`` always run on a pool thread, never inside :meth:`FairJobs.submit` or
:meth:`FairJobs.leave`, so a caller may submit while holding the locks its callbacks take. Threads start on
demand and end when nothing is left (an idle server holds none).
"""

from __future__ import annotations

import logging
import math
import threading
import time
import weakref
from collections import OrderedDict, deque
from collections.abc import Callable, Hashable, MutableMapping
from dataclasses import dataclass
from typing import Any

from tpm_viz.core.errors import BusyError, TpmVizError
from tpm_viz.core.words import T

__all__ = ["BURST", "FLOODER", "TAU", "Demand", "Done", "FairJobs", "Job"]

TAU = 3.0
"""Memory of :class:`Demand` [s]: a tab's request counts ``exp(-age / TAU)``."""
BURST = 0.05
"""Requests of one tab this close [s] are one action for :class:`Demand`."""
FLOODER = 4.0
"""Demand at which a tab counts as flooding (about one request every 0.9 s or faster): flooders take turns by how
long they have waited, after every lighter tab."""

Done = Callable[[object, Exception | None], None]
"""``done(result, error)``: the job's result and None, or None and the exception it raised (or its refusal)."""

log = logging.getLogger("tpm_viz.classroom")


def _log_bug(exc: Exception, what: str) -> None:
    log.error("%s failed", what, exc_info=exc)


class Demand:
    """How much each tab asked lately: +1 per request (a replaced one too), decaying as ``exp(-age / tau)``. The
    requests of one action (a parameter change re-plans and redraws the map: a burst within ``burst`` [s]) count
    once.

    A tab that can be referenced weakly (a browser tab's view, a session) is remembered weakly: the memory of its
    demand never keeps it alive (a private session holds its tab's whole page: a class that uploaded and left kept
    up to 256 of them, ~2 MB each, until enough others asked). Other keys (names, tuples) are kept, bounded by
    :meth:`prune`."""

    def __init__(self, tau: float = TAU, clock: Callable[[], float] = time.monotonic, burst: float = BURST) -> None:
        self.tau, self.burst = tau, burst
        self._clock = clock
        self._last: dict[Hashable, tuple[float, float]] = {}  # tab -> (demand, at [s]): keys held strongly
        self._weak: weakref.WeakKeyDictionary[Any, tuple[float, float]] = weakref.WeakKeyDictionary()

    def _table(self, tab: Hashable) -> MutableMapping[Any, tuple[float, float]]:
        """Where ``tab`` is remembered: weakly if it can be."""
        try:
            weakref.ref(tab)
        except TypeError:
            return self._last
        return self._weak

    def of(self, tab: Hashable) -> float:
        """The demand of ``tab`` now (0 for a tab never seen)."""
        value, at = self._table(tab).get(tab, (0.0, 0.0))
        return self._decayed(value, at)

    def _decayed(self, value: float, at: float) -> float:
        return value * math.exp(-max(0.0, self._clock() - at) / self.tau) if value else 0.0

    def add(self, tab: Hashable) -> None:
        table = self._table(tab)
        _value, at = table.get(tab, (0.0, -math.inf))
        now = self._clock()
        if now - at >= self.burst:
            table[tab] = (self.of(tab) + 1.0, now)

    def forget(self, tab: Hashable) -> None:
        self._table(tab).pop(tab, None)

    def prune(self, keep: int = 256) -> None:
        """Bounded memory (and no closed tab or old session kept alive): over ``keep`` tabs, forget those whose
        demand has faded (< 0.01: nothing for about 14 s), then if still over, those that asked least."""
        if len(self) <= keep:
            return
        tables: tuple[MutableMapping[Any, tuple[float, float]], ...] = (self._last, self._weak)
        entries = [(table, tab, self._decayed(*entry)) for table in tables for tab, entry in list(table.items())]
        for table, tab, demand in entries:
            if demand < 0.01:
                table.pop(tab, None)
        if len(self) > keep:
            alive = sorted((e for e in entries if e[2] >= 0.01), key=lambda e: e[2])
            for table, tab, _demand in alive[: len(self) - keep // 2]:
                table.pop(tab, None)

    def __len__(self) -> int:
        return len(self._last) + len(self._weak)


@dataclass(frozen=True)
class Job:
    """One job: ``fn()`` computes, ``done`` publishes, ``dropped`` is told when it will never run."""

    fn: Callable[[], object]
    done: Done | None = None
    dropped: Callable[[], None] | None = None


class FairJobs:
    """The queue and its pool (see the module docstring).

    ``threads``: pool size; ``per_tab``, ``total``: bounds on pending jobs; ``report(exc, what)``: where a job's
    bug (an exception that is not a :class:`~tpm_viz.core.errors.TpmVizError`) is logged."""

    def __init__(
        self,
        threads: int = 1,
        per_tab: int = 8,
        total: int = 1024,
        name: str = "tpm-viz-jobs",
        report: Callable[[Exception, str], None] = _log_bug,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        if threads < 1 or per_tab < 1 or total < 1:
            raise ValueError("threads, per_tab and total must be at least 1")
        self.threads, self.per_tab, self.total = threads, per_tab, total
        self._name = name
        self._report = report
        self._cond = threading.Condition()
        self._pending: dict[Hashable, OrderedDict[Hashable, Job]] = {}
        self._since: dict[Hashable, int] = {}  # tab -> turn at which its queue became non-empty
        self.demand = Demand(clock=clock)
        self._notices: deque[tuple[Callable, tuple]] = deque()  # callbacks of jobs that will never run
        self._busy: set[tuple[Hashable, Hashable]] = set()  # (tab, kind) running: its next job waits for it
        self._turn = 0
        self._size = 0
        self._running = 0
        self._alive = 0
        self.ran = 0
        """Jobs run so far (for tests and benchmarks)."""

    # -- what callers do ---------------------------------------------------------------------------------------
    def submit(
        self,
        tab: Hashable,
        kind: Hashable,
        fn: Callable[[], object],
        done: Done | None = None,
        dropped: Callable[[], None] | None = None,
    ) -> bool:
        """Queue ``fn`` as ``tab``'s job of ``kind``, replacing a pending one (latest wins). False: refused (a
        bound), and ``done`` will get :class:`~tpm_viz.core.errors.BusyError`."""
        job = Job(fn, done, dropped)
        with self._cond:
            self.demand.add(tab)
            queue = self._pending.get(tab)
            if queue is not None and kind in queue:
                old = queue[kind]
                queue[kind] = job  # keeps its place in the tab's own order
                if old.dropped is not None:
                    self._notices.append((old.dropped, ()))
                accepted = True
            elif self._size >= self.total or (queue is not None and len(queue) >= self.per_tab):
                busy = BusyError(T("the server is busy with other tabs' computations: try again in a moment"))
                if done is not None:
                    self._notices.append((done, (None, busy)))
                accepted = False
            else:
                if queue is None:
                    queue = self._pending[tab] = OrderedDict()
                    self._since[tab] = self._tick()
                queue[kind] = job
                self._size += 1
                accepted = True
            self._wake()
        return accepted

    def leave(self, tab: Hashable) -> None:
        """``tab`` went away: its pending jobs are dropped (a running one finishes; its ``done`` is still called)."""
        with self._cond:
            queue = self._pending.pop(tab, None)
            self._since.pop(tab, None)
            self.demand.forget(tab)
            if queue:
                self._size -= len(queue)
                self._notices.extend((job.dropped, ()) for job in queue.values() if job.dropped is not None)
                self._wake()

    def pending(self, tab: Hashable | None = None) -> int:
        """Jobs waiting (of ``tab``, or in all)."""
        with self._cond:
            if tab is None:
                return self._size
            return len(self._pending.get(tab, ()))

    def idle(self) -> bool:
        """Whether nothing is queued, running or left to tell (for tests and benchmarks)."""
        with self._cond:
            return not self._size and not self._running and not self._notices

    def wait_idle(self, timeout: float | None = None) -> bool:
        """Block until :meth:`idle` (True) or ``timeout`` [s] passes (False)."""
        with self._cond:
            return self._cond.wait_for(lambda: not self._size and not self._running and not self._notices, timeout)

    # -- the pool ----------------------------------------------------------------------------------------------
    def _tick(self) -> int:
        self._turn += 1
        return self._turn

    def _wake(self) -> None:
        """Under the condition: a thread more if work waits and the pool is not full, else wake a waiting one."""
        waiting = len(self._notices) + len(self._pending)
        if waiting and self._alive < self.threads and self._alive - self._running < waiting:
            self._alive += 1
            threading.Thread(target=self._loop, name=f"{self._name}-{self._alive}", daemon=True).start()
        self._cond.notify_all()

    def _take(self) -> tuple[tuple[Hashable, Hashable] | None, Callable, tuple] | None:
        """Under the condition: ``(slot, callable, args)`` of the next notice (slot None), else of the next job
        by turns (slot ``(tab, kind)``, not one already running), else None."""
        if self._notices:
            callback, args = self._notices.popleft()
            return None, callback, args
        ready = [t for t, queue in self._pending.items() if any((t, k) not in self._busy for k in queue)]
        if not ready:
            return None
        tab = min(ready, key=lambda t: (min(self.demand.of(t), FLOODER), self._since[t]))
        queue = self._pending[tab]
        kind = next(k for k in queue if (tab, k) not in self._busy)
        job = queue.pop(kind)
        self._size -= 1
        if not queue:
            del self._pending[tab], self._since[tab]
        self.demand.prune()
        self._busy.add((tab, kind))
        return (tab, kind), self._run, (job,)

    def _loop(self) -> None:
        while True:
            with self._cond:
                item = self._take()
                if item is None:
                    self._alive -= 1
                    self._cond.notify_all()
                    return
                self._running += 1
            slot, callback, args = item
            try:
                self._call(callback, *args)
            finally:
                with self._cond:
                    self._running -= 1
                    if slot is not None:
                        self._busy.discard(slot)
                        self.ran += 1
                        self._wake()  # its tab's next job of that kind may wait for a thread
                    self._cond.notify_all()

    def _run(self, job: Job) -> None:
        result: object = None
        error: Exception | None = None
        try:
            result = job.fn()
        except TpmVizError as exc:  # a refusal: the tab's business
            error = exc
        except Exception as exc:  # a bug: logged with its traceback, told to the tab, the pool carries on
            self._report(exc, "background job")
            error = exc
        if job.done is not None:
            self._call(job.done, result, error)

    def _call(self, callback: Callable[..., object], *args: object) -> None:
        try:
            callback(*args)
        except Exception as exc:  # a bug in a publisher: logged, the pool carries on
            self._report(exc, "publishing a background result")
