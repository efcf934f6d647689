"""Who gets a connection: one student cannot lock the class out with idle websockets.

Two hundred websocket handshakes from one address that never sent their first message used to fill the server's
connection limit, and every other tab, the lecturer's included, was refused; a burst every 45 s kept the room
locked. :class:`Admission` (used by :class:`~.limits.ServerGuard` for every new websocket, before any of its
messages is handled) now applies, with the numbers of :class:`~.limits.Limits`:

- **a cap per source address** (``max_per_address``, 50): well under the total, and room for a class behind one
  router (NAT) when no ``--trusted-proxy`` names the students' own addresses (``tpm-viz serve --tabs-per-address N``
  raises it, up to the total);
- **a share kept for the lecturer** (``lecturer_slots``, 10, at most a quarter of the total): students fill at most
  ``max_connections - lecturer_slots``; a tab whose address is the lecturer's (``lecturer(address)``: by default
  this machine's loopback addresses, i.e. a tab opened on the serving laptop, as classroom mode's presenter rule
  says) has no per-address cap and may take any place, so a student's sockets never refuse it. Before its first
  message a tab has nothing else that tells who it is (the presenter token is typed later, and a cookie can be
  copied), so the address it connects from is the rule; a lecturer on another device is a student until they log
  in, like any tab of their address;
- **a deadline for the first message** (``first_message_seconds``, 10 s): a browser sends its camera as soon as the
  socket opens (milliseconds; 10 s leaves a phone on a weak network room); a socket that has sent nothing by then is
  dropped (a hidden tab's page reconnects by itself once it is shown).

A refused tab is told why in a notification, in its browser's language (``Accept-Language``), then closed (1013),
and dropped outright if it does not answer the close. Every refusal and drop is one rate-limited log line.
"""

from __future__ import annotations

import threading
from collections.abc import Callable
from typing import Any

from tpm_viz.classroom.guard import log_fault
from tpm_viz.core.words import Phrase, T, preferred, say

__all__ = ["Admission"]

_CLOSE_GRACE = 2.0
"""Seconds a refused connection has to answer the close handshake before it is dropped."""
_FULL = T("This server takes at most {n} tabs. Try again later.")
_CROWDED = T(
    "This server takes at most {n} tabs from one network address. Close a tab you do not need; a class behind one "
    "router: ask the lecturer to start the app with --tabs-per-address."
)


class Admission:
    """The admission of one server's websockets (see the module docstring). ``door`` is its
    :class:`~.core.ServerDoor`, ``limits`` its :class:`~.limits.Limits` (read at each decision: a change applies
    to the next tab). Thread-safe: connections come and go on the event loop, the deadline is checked by the
    watchdog thread."""

    def __init__(self, door: Any, limits: Any, clock: Callable[[], float]) -> None:
        self.door, self.limits, self._clock = door, limits, clock
        self._lock = threading.Lock()
        self.accepted: dict[int, str] = {}
        """The connections that hold a place, with their source address."""
        self.refused: set[int] = set()
        self._waiting: dict[int, float] = {}  # connection -> when it opened, until its first message
        self.dropped_idle = 0
        """Connections dropped for sending nothing within the deadline."""
        self.refusals = {"crowded": 0, "full": 0}
        """Connections refused: over their address's cap, or the server (the students' share of it) full."""

    def _reserved(self) -> int:
        return min(self.limits.lecturer_slots, self.limits.max_connections // 4)

    def admit(self, client_id: int) -> bool:
        """A new websocket: take it (True) or refuse it (False: told why, closed)."""
        address = self.door.address(client_id)
        lecturer = self.limits.lecturer(address)
        with self._lock:
            total, mine = len(self.accepted), sum(1 for a in self.accepted.values() if a == address)
            students = sum(1 for a in self.accepted.values() if not self.limits.lecturer(a))
            if lecturer:
                why = None if total < self.limits.max_connections else "full"
            elif mine >= self.limits.max_per_address:
                why = "crowded"
            elif students >= self.limits.max_connections - self._reserved() or total >= self.limits.max_connections:
                why = "full"
            else:
                why = None
            if why is None:
                self.accepted[client_id] = address
                self._waiting[client_id] = self._clock()
                return True
            self.refused.add(client_id)
            self.refusals[why] += 1
        self._refuse(client_id, address, why)
        return False

    def _refuse(self, client_id: int, address: str, why: str) -> None:
        if why == "crowded":
            n = self.limits.max_per_address
            text = f"connection {client_id} from {address} refused: {n} tabs from that address (max_per_address)"
            body = Phrase(_CROWDED.template, n=n)
        else:
            n = self.limits.max_connections
            text = f"connection {client_id} refused: the server is full ({n} tabs, max_connections)"
            body = Phrase(_FULL.template, n=n)
        log_fault("server", why, text)
        lang = preferred(self.door.header(client_id, "Accept-Language"))
        self.door.notify(client_id, say(lang, T("Too many tabs")), say(lang, body))
        loop, delay = self.door.loop, self.limits.refuse_close_delay
        if loop is not None:
            loop.call_later(delay, self.door.close, client_id, 1013, "too many tabs")
            loop.call_later(delay + _CLOSE_GRACE, self.door.abort, client_id)  # no answer to the close: dropped

    def heard(self, client_id: int) -> None:
        """A message of this connection arrived: its deadline is met."""
        if client_id in self._waiting:
            with self._lock:
                self._waiting.pop(client_id, None)

    def left(self, client_id: int) -> None:
        """A connection ended: its place is free."""
        with self._lock:
            self.accepted.pop(client_id, None)
            self.refused.discard(client_id)
            self._waiting.pop(client_id, None)

    def expire(self, now: float) -> None:
        """Drop the connections that sent nothing within ``first_message_seconds`` of opening (the watchdog)."""
        deadline = self.limits.first_message_seconds
        with self._lock:
            late = [cid for cid, since in self._waiting.items() if now - since > deadline]
            for cid in late:
                del self._waiting[cid]
        for cid in late:
            self.dropped_idle += 1
            address = self.accepted.get(cid, "?")
            log_fault("server", "idle", f"connection {cid} from {address} dropped: no message within {deadline:g} s")
            self.door.abort(cid)
