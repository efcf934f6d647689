"""A background worker for slow, rare computations (workspace maps, trajectory runs), off the callback path.

viser runs callbacks in a thread pool and the app serialises every state change under the hub's lock; a
computation of 40-70 ms inside that lock would stall every other tab's drag. Jobs submitted here run one
after the other in one daemon thread, *outside* the lock; a job's ``done`` callback publishes the result
(taking the lock itself, briefly). A newer job with the same key replaces a queued older one (latest value
wins). The thread starts on demand and ends when the queue is empty, so idle apps hold no thread.
"""

from __future__ import annotations

import threading
from collections import OrderedDict
from collections.abc import Callable, Hashable

from tpm_viz.errors import TpmVizError
from tpm_viz.ui.guard import report

__all__ = ["Worker"]


class Worker:
    """Run ``fn()`` in a background thread, then ``done(result, error)`` (``error`` a :class:`TpmVizError`)."""

    def __init__(self, name: str = "tpm-viz-worker") -> None:
        self._name = name
        self._cond = threading.Condition()
        self._jobs: OrderedDict[Hashable, tuple[Callable, Callable | None]] = OrderedDict()
        self._thread: threading.Thread | None = None
        self._busy = False

    def submit(self, key: Hashable, fn: Callable[[], object], done: Callable[[object, Exception | None], None] | None):
        """Queue ``fn`` under ``key`` (replacing a queued job with the same key)."""
        with self._cond:
            self._jobs.pop(key, None)
            self._jobs[key] = (fn, done)
            if self._thread is None:
                self._thread = threading.Thread(target=self._loop, name=self._name, daemon=True)
                self._thread.start()
            self._cond.notify()

    def idle(self) -> bool:
        """Whether nothing is queued or running (for tests and benchmarks)."""
        with self._cond:
            return not self._jobs and not self._busy

    def _loop(self) -> None:
        while True:
            with self._cond:
                if not self._jobs:
                    self._thread = None
                    return
                _key, (fn, done) = self._jobs.popitem(last=False)
                self._busy = True
            result = None
            error: Exception | None = None  # the TpmVizError refusal, or the bug that was logged
            try:
                result = fn()
            except TpmVizError as exc:
                error = exc
            except Exception as exc:  # a bug: log it with its traceback, keep the worker alive
                report(exc, "background job")
                error = exc
            try:
                if done is not None:
                    done(result, error)
            except Exception as exc:  # pragma: no cover - a bug in a publisher
                report(exc, "publishing a background result")
            finally:
                with self._cond:
                    self._busy = False
