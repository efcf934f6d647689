"""Work that can wait for a quiet moment: the parts of a tab nobody needs in its first second.

A reconnect storm (a lecture hall's wifi blip: 100 tabs back at once) is served one tab at a time under the hub's
lock, so every millisecond of a tab's build delays every tab behind it. A tab therefore builds at once only what
it shows first (its mechanism, the *Explore* and *Setup* tabs, its own copy) and hands the rest (the *Player*,
*Equations* and *Lab* tabs: :mod:`tpm_viz.ui.teaching.tabs`) to :class:`Later`, which runs those jobs one at a time
on a thread of its own once no tab has arrived for :data:`QUIET` seconds: the storm first, then everyone's remaining
tabs. A job is also run at once by whoever needs its result (a test or a lesson asking for the player: the job's
owner makes it idempotent), so nothing ever depends on the timing here.

A tab that leaves asks for a collection of its garbage at the next quiet moment (:meth:`Later.tidy`), so that it is
not collected in the middle of the next storm. What a job or a timer still held at that moment becomes garbage a
moment later, and the collector's own schedule (thresholds raised for serving: :mod:`.runtime`) may not come for
hours on a quiet server: so the collection is asked for again, :data:`TIDY_AGAIN` seconds apart, while the caller
says garbage of tabs that left is still alive (at most :data:`TIDY_TRIES` times, then one log line).

Bounded: at most :data:`LIMIT` jobs wait (a job beyond it is run by the thread at once, never dropped); the thread
exists only while jobs wait.
"""

from __future__ import annotations

import gc
import logging
import threading
import time
from collections import deque
from collections.abc import Callable

from tpm_viz.classroom.guard import report

__all__ = ["LIMIT", "QUIET", "TIDY_AGAIN", "TIDY_TRIES", "Later"]

log = logging.getLogger("tpm_viz.classroom")

QUIET = 0.25
"""Seconds without a tab arriving before a waiting job runs (tabs of a storm arrive every ~50 ms)."""
LIMIT = 2000
"""Jobs kept waiting at most (a class of 150 tabs leaves two jobs each)."""
TIDY_AGAIN = 2.0
"""Seconds between two collections while the garbage of tabs that left is still alive (:meth:`Later.tidy`)."""
TIDY_TRIES = 30
"""Collections at most for one departure before it is logged as kept alive (a minute: a leak, not a slow job)."""


class Later:
    """A queue of jobs run one at a time on a daemon thread, each after :data:`QUIET` seconds without an arrival."""

    def __init__(self, quiet: float = QUIET, limit: int = LIMIT, name: str = "tpm-viz-later") -> None:
        self.quiet = quiet
        self.limit = limit
        self.name = name
        self._jobs: deque[Callable[[], object]] = deque()
        self._cond = threading.Condition()
        self._last = float("-inf")  # time.monotonic() of the last arrival
        self._thread: threading.Thread | None = None
        self._running = 0
        self._tidying = False  # a collection of the garbage of tabs that left is waiting
        self._tries = 0  # collections since the last departure
        self._kept: Callable[[], int] = lambda: 0

    def arrived(self) -> None:
        """A tab arrived (its build is starting): waiting jobs give it the next :data:`QUIET` seconds."""
        with self._cond:
            self._last = time.monotonic()

    def add(self, job: Callable[[], object]) -> None:
        """Run ``job()`` once the server is quiet (its exceptions are logged, never raised here)."""
        with self._cond:
            self._jobs.append(job)
            urgent = len(self._jobs) > self.limit
            if self._thread is None:
                self._thread = threading.Thread(target=self._run, name=self.name, daemon=True)
                self._thread.start()
            self._cond.notify_all()
        if urgent:  # a queue this long is a bug or an attack: the oldest job runs now on this thread
            self._take_and_run()

    def tidy(self, kept: Callable[[], int] | None = None) -> None:
        """A tab left: collect the garbage it left (its view's reference cycles, a few thousand objects that only
        Python's cyclic collector frees) at the next quiet moment. Left to the collector's own schedule, the
        garbage of 100 tabs is freed by a full collection of ~0.3-0.7 s in the middle of the next storm.
        ``kept()``: how many tabs that left are still alive after a collection (asked again while it is not 0)."""
        with self._cond:
            self._last = max(self._last, time.monotonic())  # after the departure is over, like an arrival's
            self._tries = 0
            if kept is not None:
                self._kept = kept
            if self._tidying:
                return
            self._tidying = True
        self.add(self._tidy)

    def _tidy(self) -> None:
        with self._cond:
            self._tidying = False
            self._tries += 1
            tries, kept = self._tries, self._kept
        gc.collect()
        alive = kept()
        if alive == 0:
            return
        if tries >= TIDY_TRIES:
            log.warning(
                "tabs that left still in memory %.0f s later: %d (a reference kept by mistake)",
                tries * TIDY_AGAIN,
                alive,
            )
            return
        timer = threading.Timer(TIDY_AGAIN, self._again)
        timer.daemon = True
        timer.name = f"{self.name}-tidy"
        timer.start()

    def _again(self) -> None:
        with self._cond:
            if self._tidying:
                return
            self._tidying = True
        self.add(self._tidy)

    def pending(self) -> int:
        """Jobs waiting or running (tests and benchmarks wait for 0)."""
        with self._cond:
            return len(self._jobs) + self._running

    def _take_and_run(self) -> None:
        with self._cond:
            if not self._jobs:
                return
            job = self._jobs.popleft()
            self._running += 1
        try:
            job()
        except Exception as exc:  # a job's bug: logged, the next jobs still run
            report(exc, "a deferred job")
        finally:
            with self._cond:
                self._running -= 1

    def _run(self) -> None:
        while True:
            with self._cond:
                while True:
                    if not self._jobs:
                        self._thread = None  # the next add() starts a new thread
                        return
                    wait = self._last + self.quiet - time.monotonic()
                    if wait <= 0:
                        break
                    self._cond.wait(wait)
            self._take_and_run()
