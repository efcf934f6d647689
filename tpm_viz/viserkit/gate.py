"""Bounded work per tab: a :class:`Gate` in front of viser's callback thread pool (the ``limits`` patch, installed by
:func:`~.limits.harden_server`).

viser runs every plain ``def`` callback in one thread pool (32 threads), as many at once as a tab sends events: a
tab that floods clicks holds every thread. Behind the gate a tab's callbacks run one at a time, in the order the tab
sent its inputs; a call of the same callback as the last one waiting replaces it (repeated clicks on an export, a
dragged slider: latest event wins) except clicks in the 3D view, which each carry their own point and wait in turn;
at most ``max_per_tab`` wait, the rest are dropped with a rate-limited log line
(:func:`~tpm_viz.classroom.guard.log_fault`). Connect and disconnect callbacks, and the server's own tasks, are never
gated. Each event's value is stamped as it arrives (:func:`~.inputs.stamp`).
"""

from __future__ import annotations

import concurrent.futures
import functools
import threading
from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.classroom.guard import log_fault
from tpm_viz.viserkit.inputs import abandon, stamp

__all__ = ["Gate"]


def _client_of(args: tuple) -> int | None:
    """The tab a pool task works for (its event's ``client_id``), or None (connect/disconnect, server tasks)."""
    event = args[0] if args else None
    if event is None or isinstance(event, viser.ClientHandle):
        return None
    client_id = getattr(event, "client_id", None)
    return client_id if isinstance(client_id, int) and not isinstance(client_id, bool) else None


_CLICKS = (viser.SceneClickEvent, viser.ScenePointerEvent, viser.SceneNodePointerEvent, viser.SceneRectSelectEvent)
"""Events that carry where the tab clicked: never merged with another."""


def _done() -> concurrent.futures.Future:
    future: concurrent.futures.Future = concurrent.futures.Future()
    future.set_result(None)
    return future


class Gate:
    """Per-tab admission in front of an executor's ``submit`` (see the module docstring): one call of a tab runs at a
    time; the others wait in arrival order. A call of the same callback as the last one waiting replaces it (latest
    wins: a slider dragged through 30 values, a burst of keystrokes); a call of another callback in between keeps
    both, so that a tab's inputs are applied in the order it sent them (*Work on my own copy* then ``d1``: ``d1``
    on the own copy). At most ``max_per_tab`` calls wait: beyond, a call replaces the waiting one of its callback,
    moved to the end (still latest wins, after the others), or is dropped. A click in the 3D view waits as its own
    call (its point is not another's)."""

    def __init__(self, submit: Callable[..., concurrent.futures.Future[Any]], max_per_tab: int = 8) -> None:
        self._submit, self.max_per_tab = submit, max_per_tab
        self._lock = threading.Lock()
        self._waiting: dict[int, list[tuple[Any, Callable[..., Any], tuple, dict]]] = {}  # present = one running
        self._clicks = 0  # numbers the waiting 3D clicks (each its own key)
        self.blocked: set[int] = set()
        self.merged = 0
        self.dropped = 0

    def submit(self, fn: Callable[..., Any], /, *args: Any, **kwargs: Any) -> concurrent.futures.Future[Any]:
        client_id = _client_of(args)
        if client_id is None:  # connect and disconnect callbacks: never gated
            try:
                return self._submit(fn, *args, **kwargs)
            except RuntimeError:  # the pool is shut down (a tab left while the server stops): nothing to run
                return _done()
        stamp(args[0])  # the value this event brought, before a later one is stored (viserkit/inputs.py)
        with self._lock:
            waiting = self._waiting.get(client_id)
            if isinstance(args[0], _CLICKS):  # each click its own key: never merged
                self._clicks += 1
                key: Any = (fn, self._clicks)
            else:
                key = fn
            call = (key, fn, args, kwargs)
            reason = ""
            if client_id in self.blocked:
                reason = "the tab is not reading what it is sent"
            elif waiting is None:
                self._waiting[client_id] = []
            elif waiting and waiting[-1][0] == key:
                waiting[-1] = call
                self.merged += 1
                return _done()
            elif len(waiting) < self.max_per_tab:
                waiting.append(call)
                return _done()
            elif any(w[0] == key for w in waiting):
                waiting[:] = [w for w in waiting if w[0] != key] + [call]
                self.merged += 1
                return _done()
            else:
                reason = "too many of its callbacks are queued"
            if reason:
                self.dropped += 1
        if reason:
            log_fault(client_id, "flood", f"callback dropped: {reason}")
            abandon(getattr(args[0], "target", None))  # that widget is written again from the state
            return _done()
        return self._start(client_id, fn, args, kwargs)

    def _start(
        self, client_id: int, fn: Callable[..., Any], args: tuple[Any, ...], kwargs: dict[str, Any]
    ) -> concurrent.futures.Future[Any]:
        @functools.wraps(fn)
        def run(*a: Any, **k: Any) -> Any:
            try:
                return fn(*a, **k)
            finally:
                self._next(client_id)

        try:
            return self._submit(run, *args, **kwargs)
        except RuntimeError:  # the pool is shut down (the server is stopping): nothing runs any more
            with self._lock:
                self._waiting.pop(client_id, None)
            return _done()

    def _next(self, client_id: int) -> None:
        with self._lock:
            waiting = self._waiting.get(client_id)
            if not waiting:
                self._waiting.pop(client_id, None)
                return
            _key, fn, args, kwargs = waiting.pop(0)
        self._start(client_id, fn, args, kwargs)

    def forget(self, client_id: int) -> None:
        """A tab left: its waiting calls are dropped (a running one finishes)."""
        with self._lock:
            self.blocked.discard(client_id)
            if client_id in self._waiting:
                self._waiting[client_id] = []

    def pending(self, client_id: int) -> int:
        """Calls of this tab running or waiting."""
        with self._lock:
            waiting = self._waiting.get(client_id)
            return 0 if waiting is None else 1 + len(waiting)
