"""Callbacks that never take the server down: catch, log, tell the tab, keep going.

viser runs plain callbacks in a thread pool and prints what escapes them; a bug in one callback (or a client that
vanished half-way through a push) must not leave the lock held, the state half-written or the other tabs stuck.
:func:`guarded` wraps a callback (``def`` or ``async def``): any :class:`Exception` is logged with its traceback
on the ``tpm_viz.ui`` logger and handed to an optional ``on_error(owner, exc)`` (e.g. "refused: internal error"
for that tab); the callback returns None. Expected refusals (:class:`~tpm_viz.TpmVizError`) are the callback's own
business and never reach the guard.

:func:`guard_executor` applies the guard to every task of viser's callback pool as a safety net, so a callback
that forgot the decorator is still logged and counted.

:func:`log_fault` is the log of what a tab does wrong (malformed messages, refused uploads, wrong presenter tokens,
floods): at most one line per second per tab and kind of fault, the next line saying how many were suppressed, so
a hostile tab cannot fill the log.

:data:`ACTIVITY` counts guarded calls: how many ran, failed and are running now. The soak test and the load
benchmark read it ("no exception in the server log"); protocol-level tests wait on it
(:meth:`Activity.wait_idle`) instead of sleeping.
"""

from __future__ import annotations

import functools
import inspect
import logging
import threading
import time
from collections.abc import Callable
from concurrent.futures import Executor, Future
from typing import Any, TypeVar, overload

__all__ = ["ACTIVITY", "FAULTS", "TRACEBACK_INTERVAL", "Activity", "Faults", "guard_executor", "guarded", "log"]
__all__ += ["log_fault", "report"]

log = logging.getLogger("tpm_viz.ui")

F = TypeVar("F", bound=Callable[..., Any])
"""A guarded callback (``def`` or ``async def``): the wrapper has its signature (it returns None on an error)."""
OnError = Callable[[Any, Exception], object]
"""``on_error(owner, exc)``: ``owner`` is the callback's first argument (``self`` or the event)."""


class Activity:
    """Thread-safe counters of guarded calls."""

    def __init__(self) -> None:
        self._cond = threading.Condition()
        self.calls = 0
        self.errors = 0
        self.in_flight = 0

    def enter(self) -> None:
        with self._cond:
            self.calls += 1
            self.in_flight += 1

    def leave(self) -> None:
        with self._cond:
            self.in_flight -= 1
            self._cond.notify_all()

    def error(self) -> None:
        with self._cond:
            self.errors += 1

    def snapshot(self) -> tuple[int, int, int]:
        """``(calls, errors, in_flight)``."""
        with self._cond:
            return self.calls, self.errors, self.in_flight

    def wait_idle(self, timeout: float = 10.0) -> bool:
        """Block until no guarded call is running (True), or ``timeout`` seconds pass (False)."""
        deadline = time.monotonic() + timeout
        with self._cond:
            while self.in_flight:
                left = deadline - time.monotonic()
                if left <= 0:
                    return False
                self._cond.wait(left)
            return True


ACTIVITY = Activity()


class Faults:
    """Rate-limited warnings: one line per ``interval`` seconds per ``(tab, kind)``, with the count suppressed.
    ``logger`` and ``line`` (a ``%``-format of the tab, the text and the count) say where and how (default: the
    ``tpm_viz.ui`` logger, ``client <tab>: <text>``); a source address works as well as a tab."""

    MAX_KEYS = 10_000
    """Most ``(tab, kind)`` pairs remembered (older ones are forgotten first: tabs that left)."""

    def __init__(
        self,
        interval: float = 1.0,
        clock: Callable[[], float] = time.monotonic,
        logger: logging.Logger | None = None,
        line: str = "client %s: %s%s",
    ) -> None:
        self.interval, self._clock = interval, clock
        self._log, self._line = logger or log, line
        self._lock = threading.Lock()
        self._last: dict[tuple[object, str], list[float]] = {}  # key -> [time of the last line, suppressed since]
        self.lines = 0
        self.suppressed = 0

    def __call__(self, client_id: object, kind: str, text: str) -> bool:
        """Log ``text`` for this tab and kind unless one was logged less than ``interval`` ago (then count it).
        Returns whether a line was written."""
        now = self._clock()
        with self._lock:
            entry = self._last.get((client_id, kind))
            if entry is not None and now - entry[0] < self.interval:
                entry[1] += 1
                self.suppressed += 1
                return False
            dropped = entry[1] if entry is not None else 0
            self._last.pop((client_id, kind), None)
            self._last[(client_id, kind)] = [now, 0]
            if len(self._last) > self.MAX_KEYS:
                del self._last[next(iter(self._last))]
            self.lines += 1
        more = f" (+{dropped} more in the last {now - entry[0]:.1f} s)" if entry is not None and dropped else ""
        self._log.warning(self._line, client_id, text, more)
        return True

    def forget(self, client_id: object) -> None:
        """A tab left: drop its entries."""
        with self._lock:
            for key in [k for k in self._last if k[0] == client_id]:
                del self._last[key]


FAULTS = Faults()
log_fault = FAULTS
"""``log_fault(client_id, kind, text)``: the rate-limited warning of :class:`Faults` (one shared instance)."""


TRACEBACK_INTERVAL = 60.0
"""A tab's callback failing in the same place and way logs its traceback once per this many seconds [s]; the others
in between are one rate-limited line per tab (:func:`log_fault`), so a tab that triggers a bug on purpose cannot
fill the log (a failure of the server's own threads always logs its traceback)."""
_TRACED: dict[tuple[str, str], float] = {}
_TRACED_LOCK = threading.Lock()


def report(exc: BaseException, what: str, client: object = None) -> None:
    """Log an unexpected exception of ``what`` (for the tab ``client``, if known) with its traceback, then count it;
    the same failure again within :data:`TRACEBACK_INTERVAL` is one line through the per-tab limit.

    Logged first: whoever waits on the count (a health page, a test) then finds the log line written.
    """
    key, now = (what, type(exc).__name__), time.monotonic()
    with _TRACED_LOCK:
        first = client is None or now - _TRACED.get(key, -TRACEBACK_INTERVAL) >= TRACEBACK_INTERVAL
        if first and client is not None:
            _TRACED[key] = now
            if len(_TRACED) > Faults.MAX_KEYS:
                del _TRACED[next(iter(_TRACED))]
    if first:
        log.error("%s failed: %s: %s", what, type(exc).__name__, exc, exc_info=exc)
    else:
        log_fault(client, f"error {what}", f"{what} failed again: {type(exc).__name__}")
    ACTIVITY.error()


def _client_of(args: tuple[Any, ...]) -> object:
    """The tab a callback ran for (its event's ``client_id`` or client's), or None."""
    first = args[0] if args else None
    client = getattr(first, "client", None)
    found = getattr(first, "client_id", None) if client is None else getattr(client, "client_id", None)
    return found if isinstance(found, int) else None


def _notify(on_error: OnError | None, args: tuple[Any, ...], exc: Exception, what: str) -> None:
    if on_error is None or not args:
        return
    try:
        on_error(args[0], exc)
    except Exception as inner:  # the tab may be gone as well: log and carry on
        report(inner, f"{what} (error report)")


@overload
def guarded(func: F, *, on_error: OnError | None = None) -> F: ...


@overload
def guarded(func: None = None, *, on_error: OnError | None = None) -> Callable[[F], F]: ...


def guarded(func: F | None = None, *, on_error: OnError | None = None) -> F | Callable[[F], F]:
    """Decorator: run ``func``; on any :class:`Exception` log it, call ``on_error(args[0], exc)``, return None.

    Usable bare (``@guarded``) or with an error hook (``@guarded(on_error=...)``), on ``def`` and
    ``async def`` functions alike.
    """

    def decorate(fn: F) -> F:
        what = getattr(fn, "__qualname__", repr(fn))
        if inspect.iscoroutinefunction(fn):

            @functools.wraps(fn)
            async def async_wrapper(*args: Any, **kwargs: Any) -> Any:
                ACTIVITY.enter()
                try:
                    return await fn(*args, **kwargs)
                except Exception as exc:
                    report(exc, what, _client_of(args))
                    _notify(on_error, args, exc, what)
                    return None
                finally:
                    ACTIVITY.leave()

            return async_wrapper  # type: ignore[return-value]  # same signature, None on an error

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            ACTIVITY.enter()
            try:
                return fn(*args, **kwargs)
            except Exception as exc:
                report(exc, what, _client_of(args))
                _notify(on_error, args, exc, what)
                return None
            finally:
                ACTIVITY.leave()

        return wrapper  # type: ignore[return-value]  # same signature, None on an error

    return decorate if func is None else decorate(func)


def guard_executor(executor: Executor) -> None:
    """Guard every task later submitted to ``executor`` (viser's callback pool): a callback registered without
    :func:`guarded` still has its exception logged and counted here instead of only printed by viser."""
    submit = executor.submit

    def guarded_submit(fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> Future[Any]:
        return submit(guarded(fn), *args, **kwargs)

    executor.submit = guarded_submit  # type: ignore[method-assign]  # this pool's tasks only
