"""Server-level limits: one tab cannot freeze or fill the server.

:func:`harden_server` (called once by :func:`~.adapter.install`) installs, on one viser server:

- **Bounded work per tab** (:class:`Gate`, in front of viser's callback thread pool): a tab's callbacks run one at a
  time (a flooding tab holds one pool thread, not 32), in the order the tab sent its inputs; a call of the same
  callback as the last one waiting replaces it (repeated clicks on an export, a dragged slider: latest event wins)
  except clicks in the 3D view, which each carry their own point and wait in turn; at most
  :attr:`Limits.max_callbacks_per_tab` wait, the rest are dropped with a rate-limited log line. Connect and
  disconnect callbacks are never gated.
- **Bounded memory**: websocket messages over :attr:`Limits.max_frame_bytes` close that connection (viser accepts
  50 MiB; the largest thing a browser sends is a 512 KiB upload part; :class:`~.patches.GuardedProtocol`,
  installed by :mod:`.adapter`); a watchdog thread drops a connection whose
  outgoing backlog (messages queued and not yet written: a tab that stopped reading) stays over
  :attr:`Limits.max_backlog_bytes` for :attr:`Limits.backlog_grace` seconds, and meanwhile runs none of its callbacks;
  after tabs leave it returns freed heap to the system (``malloc_trim``); at most :attr:`Limits.max_connections`
  tabs (the next one is told so in a notification, then closed). Uploads are bounded per tab, per address and per
  server in :mod:`.transport` and :mod:`.uploads` (a tab's bytes in flight given back when it leaves).
- **Well-formed messages only**: every incoming message is checked against its declared field types
  (:func:`~.transport.message_problem`) before viser dispatches it; a handler that still fails is one log line. A
  tab that sends more than :attr:`Limits.max_malformed` malformed messages within :attr:`Limits.malformed_window`
  seconds is dropped.
- **HTTP**: a path the app does not serve is a 404 (414 for an over-long one), never a 500 (with the frame limit).

All drops are logged through :func:`~.guard.log_fault` (one line per second per tab and kind, with counts).
"""

from __future__ import annotations

import collections
import concurrent.futures
import ctypes
import dataclasses
import functools
import threading
import time
from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.classroom.guard import FAULTS, log_fault, report
from tpm_viz.viserkit.core import ServerDoor, thread_pool
from tpm_viz.viserkit.inputs import abandon, stamp
from tpm_viz.viserkit.transport import message_problem
from tpm_viz.viserkit.uploads import budget_of
from tpm_viz.viserkit.wire import Incoming, Wrapper

__all__ = [
    "DEFAULT_MAX_CONNECTIONS",
    "Gate",
    "Limits",
    "ServerGuard",
    "guard_of",
    "harden_server",
    "set_max_connections",
]

DEFAULT_MAX_CONNECTIONS = 200


@dataclasses.dataclass
class Limits:
    """The limits of one server (see the module docstring)."""

    max_connections: int = DEFAULT_MAX_CONNECTIONS
    max_frame_bytes: int = 1 << 20
    max_callbacks_per_tab: int = 8
    max_backlog_bytes: int = 32 << 20
    max_backlog_messages: int = 20_000
    backlog_grace: float = 5.0
    check_interval: float = 0.25
    refuse_close_delay: float = 1.0
    max_malformed: int = 1000
    malformed_window: float = 10.0


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


@functools.cache
def _libc() -> Any:
    try:
        return ctypes.CDLL("libc.so.6")
    except OSError:
        return None


def _malloc_trim() -> None:
    """Give freed heap back to the system (glibc; a no-op elsewhere)."""
    trim = getattr(_libc(), "malloc_trim", None)
    if trim is not None:
        trim(0)


class ServerGuard:
    """The limits of one server, installed by :func:`harden_server`."""

    def __init__(self, server: viser.ViserServer, limits: Limits) -> None:
        self.limits = limits
        self.door = ServerDoor(server)
        self._pool = pool = thread_pool(server)
        self._submit = pool.__dict__.get("submit")  # an instance's own (the callbacks' guard), or None: the class's
        self.gate = Gate(pool.submit, limits.max_callbacks_per_tab)
        self.uploads = budget_of(server)
        """The server's bytes of uploads in flight (:mod:`.uploads`): a tab's are given back when it leaves."""
        pool.submit = self.gate.submit
        self.accepted: set[int] = set()
        self.refused: set[int] = set()
        self._malformed: dict[int, collections.deque[float]] = {}
        """Times of each tab's recent malformed messages (at most ``max_malformed + 1`` each)."""
        self.dropped = 0
        self.aborted = 0
        self.trims = 0
        self.door.on_connect(self._connected, self._wrap(log=True))
        self.door.on_disconnect(self._disconnected)
        self.door.wrap_server_dispatch(self._wrap(log=False))
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._watch, name="tpm-viz-limits", daemon=True)
        self._thread.start()

    # -- connections ---------------------------------------------------------------------------------------------
    def _connected(self, client_id: int) -> None:
        if len(self.accepted) < self.limits.max_connections:
            self.accepted.add(client_id)
            return
        self.refused.add(client_id)
        n = self.limits.max_connections
        log_fault("server", "full", f"connection {client_id} refused: {n} tabs are connected (max_connections)")
        self.door.notify(client_id, "Too many tabs", f"This server takes at most {n} tabs. Try again later.")
        loop = self.door.loop
        if loop is not None:
            loop.call_later(self.limits.refuse_close_delay, self.door.close, client_id, 1013, "too many tabs")

    def _disconnected(self, client_id: int) -> None:
        self.accepted.discard(client_id)
        self.refused.discard(client_id)
        self._malformed.pop(client_id, None)
        self.gate.forget(client_id)
        self.uploads.leave(client_id)
        FAULTS.forget(client_id)

    def _wrap(self, log: bool) -> Wrapper:
        def wrap(dispatch: Incoming) -> Incoming:
            async def handle(client_id: int, message: Any) -> None:
                if client_id in self.refused:
                    return
                problem = message_problem(message)
                if problem is not None:
                    if log:
                        log_fault(client_id, "message", f"message dropped: {problem}")
                        self._count_malformed(client_id)
                    return
                try:
                    await dispatch(client_id, message)
                except Exception as exc:  # viser's own handler choked on a message: one line, not a traceback
                    name = type(message).__name__
                    log_fault(client_id, "handler", f"{name} failed in viser: {type(exc).__name__}: {str(exc)[:200]}")
                    if log:
                        self._count_malformed(client_id)

            return handle

        return wrap

    def _count_malformed(self, client_id: int) -> None:
        """One more malformed message from this tab: over ``max_malformed`` in ``malformed_window`` seconds, the
        tab is dropped (a browser never sends one; a script that keeps trying costs the server only this count)."""
        now, window = time.monotonic(), self.limits.malformed_window
        times = self._malformed.setdefault(client_id, collections.deque(maxlen=self.limits.max_malformed + 1))
        times.append(now)
        if len(times) > self.limits.max_malformed and now - times[0] <= window:
            self.refused.add(client_id)  # nothing more of it is handled
            self._malformed.pop(client_id, None)
            self.dropped += 1
            log_fault(
                client_id,
                "dropped",
                f"connection closed: over {self.limits.max_malformed} malformed messages in {window:g} s",
            )
            self.door.close(client_id, 1008, "malformed messages")

    # -- the watchdog --------------------------------------------------------------------------------------------
    def _watch(self) -> None:
        over: dict[int, float] = {}
        known: set[int] = set()
        trim_at = 0.0
        while not self._stop.wait(self.limits.check_interval):
            loop = self.door.loop
            if loop is None or loop.is_closed():
                return
            now = time.monotonic()
            live = set(self.door.live())
            try:
                self._check(live, over, now)
            except Exception as exc:  # one bad round must not stop the watchdog: logged, the next one runs
                report(exc, "the watchdog's round")
            if known - live:
                trim_at = trim_at or now + 1.0  # once the departed tabs' teardown has run
            known = live
            if trim_at and now >= trim_at:
                _malloc_trim()
                self.trims += 1
                trim_at = 0.0

    def _check(self, live: set[int], over: dict[int, float], now: float) -> None:
        """Block the tabs whose backlog is over the limit (``over``: since when), drop those over it for too long."""
        for client_id in live:
            if self._over(client_id):
                since = over.setdefault(client_id, now)
                self.gate.blocked.add(client_id)
                if now - since >= self.limits.backlog_grace:
                    mb = self.limits.max_backlog_bytes / 2**20
                    log_fault(client_id, "backlog", f"connection dropped: over {mb:g} MiB unsent for a while")
                    self.door.abort(client_id)
                    self.aborted += 1
                    del over[client_id]
            elif over.pop(client_id, None) is not None:
                self.gate.blocked.discard(client_id)
        for client_id in set(over) - live:
            del over[client_id]

    def _over(self, client_id: int) -> bool:
        _count, size = self.door.backlog(client_id, self.limits.max_backlog_messages)
        return size < 0 or size > self.limits.max_backlog_bytes

    def stop(self) -> None:
        """Stop the watchdog."""
        self._stop.set()

    def remove(self) -> None:
        """Stop the watchdog and take the limits off the server (connections already open keep their filter)."""
        self.stop()
        if self._submit is None:
            self._pool.__dict__.pop("submit", None)
        else:
            self._pool.submit = self._submit
        for remove in self.door.removers:
            remove()
        self.door.unwrap_server_dispatch()


_ATTR = "tpm_viz_limits"


def harden_server(server: viser.ViserServer, limits: Limits | None = None) -> ServerGuard:
    """Install the limits of the module docstring on ``server`` (once; later calls return the same guard). The guard
    lives as long as the server (it is kept on it)."""
    guard = guard_of(server)
    if guard is None:
        guard = ServerGuard(server, limits or Limits())
        setattr(server, _ATTR, guard)
    return guard


def guard_of(server: viser.ViserServer) -> ServerGuard | None:
    """The guard installed on ``server``, if any (``TpmApp(max_connections=...)`` sets its limit)."""
    guard = getattr(server, _ATTR, None)
    return guard if isinstance(guard, ServerGuard) else None


def set_max_connections(server: viser.ViserServer, max_connections: int) -> None:
    """The most tabs ``server`` serves at once (installs the limits first if needed)."""
    if not (isinstance(max_connections, int) and max_connections >= 1):
        raise ValueError(f"max_connections must be a positive integer, got {max_connections!r}")
    harden_server(server).limits.max_connections = max_connections
