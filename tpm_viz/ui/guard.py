"""Callbacks that never take the server down: catch, log, tell the tab, keep going.

viser runs plain callbacks in a thread pool and prints what escapes them; a bug in one callback (or a client that
vanished half-way through a push) must not leave the lock held, the state half-written or the other tabs stuck.
:func:`guarded` wraps a callback (``def`` or ``async def``): any :class:`Exception` is logged with its traceback
on the ``tpm_viz.ui`` logger and handed to an optional ``on_error(owner, exc)`` (e.g. "refused: internal error"
for that tab); the callback returns None. Expected refusals (:class:`~tpm_viz.TpmVizError`) are the callback's own
business and never reach the guard.

:func:`guard_executor` applies the guard to every task of viser's callback pool as a safety net, so a callback
that forgot the decorator is still logged and counted.

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

__all__ = ["ACTIVITY", "Activity", "guard_executor", "guarded", "log", "report"]

log = logging.getLogger("tpm_viz.ui")


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


def report(exc: BaseException, what: str) -> None:
    """Log an unexpected exception of ``what`` with its traceback and count it."""
    ACTIVITY.error()
    log.error("%s failed: %s: %s", what, type(exc).__name__, exc, exc_info=exc)


def _notify(on_error, args, exc: Exception, what: str) -> None:
    if on_error is None or not args:
        return
    try:
        on_error(args[0], exc)
    except Exception as inner:  # the tab may be gone as well: log and carry on
        report(inner, f"{what} (error report)")


def guarded(func=None, *, on_error=None):
    """Decorator: run ``func``; on any :class:`Exception` log it, call ``on_error(args[0], exc)``, return None.

    Usable bare (``@guarded``) or with an error hook (``@guarded(on_error=...)``), on ``def`` and
    ``async def`` functions alike.
    """

    def decorate(fn):
        what = getattr(fn, "__qualname__", repr(fn))
        if inspect.iscoroutinefunction(fn):

            @functools.wraps(fn)
            async def async_wrapper(*args, **kwargs):
                ACTIVITY.enter()
                try:
                    return await fn(*args, **kwargs)
                except Exception as exc:
                    report(exc, what)
                    _notify(on_error, args, exc, what)
                    return None
                finally:
                    ACTIVITY.leave()

            return async_wrapper

        @functools.wraps(fn)
        def wrapper(*args, **kwargs):
            ACTIVITY.enter()
            try:
                return fn(*args, **kwargs)
            except Exception as exc:
                report(exc, what)
                _notify(on_error, args, exc, what)
                return None
            finally:
                ACTIVITY.leave()

        return wrapper

    return decorate if func is None else decorate(func)


def guard_executor(executor) -> None:
    """Guard every task later submitted to ``executor`` (viser's callback pool): a callback registered without
    :func:`guarded` still has its exception logged and counted here instead of only printed by viser."""
    submit = executor.submit

    def guarded_submit(fn, /, *args, **kwargs):
        return submit(guarded(fn), *args, **kwargs)

    executor.submit = guarded_submit
