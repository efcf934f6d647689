"""Server-level limits: one tab cannot freeze or fill the server.

:func:`harden_server` (called once by :func:`~.adapter.install`) installs, on one viser server:

- **Bounded work per tab** (:class:`~.gate.Gate`, in front of viser's callback thread pool): a tab's callbacks run one
  at a time (a flooding tab holds one pool thread, not 32), in the order the tab sent its inputs; a call of the same
  callback as the last one waiting replaces it (repeated clicks on an export, a dragged slider: latest event wins)
  except clicks in the 3D view, which each carry their own point and wait in turn; at most
  :attr:`Limits.max_callbacks_per_tab` wait, the rest are dropped with a rate-limited log line. Connect and disconnect
  callbacks are never gated.
- **Bounded memory**: websocket messages over :attr:`Limits.max_frame_bytes` close that connection (viser accepts
  50 MiB; the largest thing a browser sends is a 512 KiB upload part; :class:`~.patches.GuardedProtocol`,
  installed by :mod:`.adapter`); a watchdog thread drops a connection whose
  outgoing backlog (messages queued and not yet written: a tab that stopped reading) stays over
  :attr:`Limits.max_backlog_bytes` for :attr:`Limits.backlog_grace` seconds, and meanwhile runs none of its callbacks;
  after tabs leave it returns freed heap to the system (``malloc_trim``). Uploads are bounded per tab, per address
  and per server in :mod:`.transport` and :mod:`.uploads` (a tab's bytes in flight given back when it leaves).
- **Bounded connections** (:class:`~.admission.Admission`): at most :attr:`Limits.max_connections` tabs, at most
  :attr:`Limits.max_per_address` from one source address, :attr:`Limits.lecturer_slots` kept for the lecturer's
  machine, and a socket that sends nothing within :attr:`Limits.first_message_seconds` is dropped (a refused tab is
  told why in a notification, then closed).
- **Well-formed messages only**: every incoming message is checked against its declared field types
  (:func:`~.transport.message_problem`) before viser dispatches it; a handler that still fails is one log line. A
  tab that sends more than :attr:`Limits.max_malformed` malformed messages within :attr:`Limits.malformed_window`
  seconds is dropped.
- **HTTP**: a path the app does not serve is a 404 (414 for an over-long one), never a 500 (with the frame limit).

All drops are logged through :func:`~.guard.log_fault` (one line per second per tab and kind, with counts).
"""

from __future__ import annotations

import collections
import ctypes
import dataclasses
import functools
import threading
import time
from collections.abc import Callable
from typing import Any

import viser

from tpm_viz.classroom.guard import FAULTS, log_fault, report
from tpm_viz.classroom.network import is_loopback
from tpm_viz.viserkit.admission import Admission
from tpm_viz.viserkit.core import thread_pool
from tpm_viz.viserkit.doors import ServerDoor
from tpm_viz.viserkit.gate import Gate
from tpm_viz.viserkit.transport import message_problem
from tpm_viz.viserkit.uploads import budget_of
from tpm_viz.viserkit.wire import Incoming, Wrapper

__all__ = [
    "DEFAULT_MAX_CONNECTIONS",
    "DEFAULT_MAX_PER_ADDRESS",
    "Gate",
    "Limits",
    "ServerGuard",
    "guard_of",
    "harden_server",
    "set_admission",
    "set_max_connections",
]

DEFAULT_MAX_CONNECTIONS = 200
"""Most tabs at once (a lecture hall of 150 with room to spare; ``bench_load.py --mode hall`` measures 150)."""
DEFAULT_MAX_PER_ADDRESS = 50
"""Most tabs from one source address: a quarter of the total, so one student's sockets leave the class room, and a
class of 50 behind one router (NAT) still fits."""


@dataclasses.dataclass
class Limits:
    """The limits of one server (see the module docstring)."""

    max_connections: int = DEFAULT_MAX_CONNECTIONS
    max_per_address: int = DEFAULT_MAX_PER_ADDRESS
    lecturer_slots: int = 10
    """Places only the lecturer's tabs may take (at most a quarter of ``max_connections``)."""
    first_message_seconds: float = 10.0
    lecturer: Callable[[str], bool] = is_loopback
    """Whether a source address is the lecturer's machine (no per-address cap, the kept places)."""
    max_frame_bytes: int = 1 << 20
    max_callbacks_per_tab: int = 8
    max_backlog_bytes: int = 32 << 20
    max_backlog_messages: int = 20_000
    backlog_grace: float = 5.0
    check_interval: float = 0.25
    refuse_close_delay: float = 1.0
    max_malformed: int = 1000
    malformed_window: float = 10.0


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
        self.admission = Admission(self.door, limits, time.monotonic)
        """Who gets a connection (:mod:`.admission`)."""
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
    @property
    def accepted(self) -> dict[int, str]:
        """The connections that hold a place, with their source address."""
        return self.admission.accepted

    @property
    def refused(self) -> set[int]:
        """The connections refused (told, closing) or dropped for malformed messages."""
        return self.admission.refused

    def _connected(self, client_id: int) -> None:
        self.admission.admit(client_id)

    def _disconnected(self, client_id: int) -> None:
        self.admission.left(client_id)
        self._malformed.pop(client_id, None)
        self.gate.forget(client_id)
        self.uploads.leave(client_id)
        FAULTS.forget(client_id)

    def _wrap(self, log: bool) -> Wrapper:
        def wrap(dispatch: Incoming) -> Incoming:
            async def handle(client_id: int, message: Any) -> None:
                self.admission.heard(client_id)  # its first message: the deadline is met
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
                self.admission.expire(now)
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


def set_admission(
    server: viser.ViserServer, lecturer: Callable[[str], bool] | None = None, max_per_address: int | None = None
) -> None:
    """Who the lecturer's machine is (``lecturer(address)``) and the most tabs per address, on ``server``
    (installs the limits first if needed; :mod:`.admission`)."""
    limits = harden_server(server).limits
    if lecturer is not None:
        limits.lecturer = lecturer
    if max_per_address is not None:
        if not (isinstance(max_per_address, int) and max_per_address >= 1):
            raise ValueError(f"max_per_address must be a positive integer, got {max_per_address!r}")
        limits.max_per_address = max_per_address


def set_max_connections(server: viser.ViserServer, max_connections: int) -> None:
    """The most tabs ``server`` serves at once (installs the limits first if needed)."""
    if not (isinstance(max_connections, int) and max_connections >= 1):
        raise ValueError(f"max_connections must be a positive integer, got {max_connections!r}")
    harden_server(server).limits.max_connections = max_connections
