"""Tabs that left (:class:`Away`): kept per browser identity, bounded per browser, per source address and in total.

viser gives every websocket connection a new client id and its page sends nothing that identifies the tab when it
reconnects; what survives is the browser's cookie (:mod:`.identity`). A tab is recognised by its browser, and when
the browser has several tabs, by the camera it sends first (a reconnecting page keeps its camera). Each tab that
left is kept for :data:`~tpm_viz.classroom.sessionfile.KEEP_SECONDS`.

Bounds: :data:`MAX_PER_BROWSER` tabs per browser, :data:`MAX_PER_ADDRESS` browsers per source address and
:data:`MAX_AWAY` browsers in all. A new browser of an address that has its share pushes out that address's own
oldest; when all are full, the oldest browser of the address holding the most goes (never another address's while
this one has any). Evictions are logged at most once a minute per address (:data:`EVICTION_LOG_SECONDS`), the next
line counting those not said (a student minting 400 cookies is one line, not 250). The samples of uploaded trajectories
kept with the tabs are bounded too, at :data:`MAX_UPLOAD_BYTES` in all (a 20,000-row upload is 480 kB of samples, and
275 tabs that uploaded one and left held them all for 30 minutes): over it, the oldest upload of the address holding the
most is let go (its tab still comes back on its own copy, without that trajectory, and is told so:
:data:`UPLOAD_NOT_KEPT`).

The presenter's right is never restored from a cookie alone: :meth:`Away.presenter` is true only for a record of a
presenter's tab coming back from the same address within :data:`PRESENTER_SECONDS`; :meth:`Away.end_presenters`
(another tab logged in, or the presenter logged out) ends it for every record.
"""

from __future__ import annotations

import dataclasses
import logging
import threading
import time
from collections.abc import Callable
from typing import Any

from tpm_viz.classroom.guard import Faults
from tpm_viz.classroom.sessionfile import KEEP_SECONDS, Saved

__all__ = ["EVICTION_LOG_SECONDS", "MAX_AWAY", "MAX_PER_ADDRESS", "MAX_PER_BROWSER", "MAX_UPLOAD_BYTES"]
__all__ += ["PRESENTER_SECONDS", "UPLOAD_NOT_KEPT", "Away", "upload_bytes"]

log = logging.getLogger("tpm_viz.classroom")

MAX_PER_BROWSER = 8
MAX_PER_ADDRESS = 150
"""Remembered browsers per source address (a class behind one address still fits)."""
MAX_AWAY = 2000
PRESENTER_SECONDS = 120.0
"""How long [s] a presenter's tab that dropped may come back as the presenter (from the same address only)."""
EVICTION_LOG_SECONDS = 60.0
"""At most one log line per source address per this many seconds [s] about the browsers it had forgotten."""
MAX_UPLOAD_BYTES = 32 << 20
"""Bytes of uploaded trajectories' samples kept with the tabs that left, in all (about 70 of the largest)."""
UPLOAD_NOT_KEPT = "upload_not_kept"
"""The key of a record whose uploaded trajectory was let go (:data:`MAX_UPLOAD_BYTES`): True."""


def upload_bytes(record: dict[str, Any]) -> int:
    """Bytes of the uploaded trajectory's samples a record keeps (0: none)."""
    saved = record.get("saved")
    source = getattr(saved, "source", None)
    knots = getattr(source, "knots", None)
    if getattr(source, "kind", None) != "csv" or knots is None:
        return 0
    return sum(int(getattr(a, "nbytes", 0)) for a in knots)


def _close(a: Any, b: Any) -> bool:
    """Whether two cameras (tuples of numbers) are the same within 1e-6 (numpy's ``allclose``: rtol 1e-5)."""
    if a is None or b is None:
        return False
    try:
        x, y = [float(v) for v in a], [float(v) for v in b]
    except (TypeError, ValueError):
        return False
    return len(x) == len(y) and all(abs(p - q) <= 1e-6 + 1e-5 * abs(q) for p, q in zip(x, y, strict=True))


class Away:
    """Tabs that left, per browser identity (oldest browser first); each for :data:`KEEP_SECONDS`. Thread-safe.

    A record is ``{"private", "saved", "left_at", "camera", "presenter", "address"}``."""

    def __init__(self, clock: Callable[[], float] = time.time, log_clock: Callable[[], float] = time.monotonic) -> None:
        self._clock = clock
        self._said = Faults(EVICTION_LOG_SECONDS, log_clock, log, "browsers from %s: %s%s")
        """The rate-limited log of evictions (one line per address per minute, then the count suppressed)."""
        self._lock = threading.Lock()
        self._tabs: dict[str, list[dict[str, Any]]] = {}
        self._address: dict[str, str] = {}
        self.changed = 0
        """Counts changes (the saver writes only when it moved)."""
        self.let_go = 0
        """Uploads let go over :data:`MAX_UPLOAD_BYTES` so far (tests and benchmarks)."""
        self._told = (0, float("-inf"))  # let_go and time.monotonic() of the last log line

    def _prune(self) -> None:
        now = self._clock()
        for key in list(self._tabs):
            kept = [r for r in self._tabs[key] if now - r["left_at"] <= KEEP_SECONDS][-MAX_PER_BROWSER:]
            if kept != self._tabs[key]:
                self.changed += 1
            if kept:
                self._tabs[key] = kept
            else:
                self._forget(key)

    def _forget(self, key: str) -> None:
        self._tabs.pop(key, None)
        self._address.pop(key, None)
        self.changed += 1

    def _make_room(self, address: str) -> None:
        """Before a new browser of ``address``: evict that address's oldest if it has its share, or (all full) the
        oldest browser of the address with the most."""
        mine = [k for k, a in self._address.items() if a == address]
        if len(mine) >= MAX_PER_ADDRESS:
            victim, why = mine[0], f"over its {MAX_PER_ADDRESS} remembered browsers"
        elif len(self._tabs) >= MAX_AWAY:
            counts: dict[str, int] = {}
            for a in self._address.values():
                counts[a] = counts.get(a, 0) + 1
            top = max(counts, key=lambda a: (counts[a], a == address))
            victim = next(k for k, a in self._address.items() if a == top)
            why = f"{MAX_AWAY} browsers remembered in all"
        else:
            return
        self._said(self._address.get(victim), "evicted", f"forgot the oldest one's remembered tabs ({why})")
        self._forget(victim)

    def park(
        self,
        key: str,
        private: bool,
        saved: Saved | None,
        camera: Any = None,
        presenter: bool = False,
        address: str = "",
    ) -> None:
        """A tab of browser ``key`` left from ``address``: keep what it had (and whether it was the presenter's)."""
        with self._lock:
            self._prune()
            if key not in self._tabs:
                self._make_room(str(address))
            record = {"private": private, "saved": saved, "left_at": self._clock(), "camera": camera}
            record.update(presenter=presenter, address=str(address))
            self._tabs.setdefault(key, []).append(record)
            self._address[key] = str(address)
            self._prune()
            self._bound_uploads()
            self.changed += 1

    def take(self, key: str, camera: Any = None) -> dict[str, Any] | None:
        """The record of the tab of browser ``key`` that is back (removed), if it can be told apart: the only one
        of that browser, or the one whose camera it sends; else None (see :meth:`offer`)."""
        with self._lock:
            self._prune()
            records = self._tabs.get(key, [])
            matched = [r for r in records if _close(r.get("camera"), camera)]
            chosen = matched[-1] if len(matched) == 1 else records[0] if len(records) == 1 else None
            if chosen is not None:
                records.remove(chosen)
                self.changed += 1
                if not records:
                    self._forget(key)
            return chosen

    def presenter(self, record: dict[str, Any] | None, address: str) -> bool:
        """Whether ``record`` (taken back) makes its tab the presenter again: a presenter's tab, from the same
        address, within :data:`PRESENTER_SECONDS` of leaving."""
        if record is None or record.get("presenter") is not True or record.get("address") != address:
            return False
        return 0.0 <= self._clock() - float(record["left_at"]) <= PRESENTER_SECONDS

    def end_presenters(self, address: str | None = None) -> None:
        """No record (of ``address``; default: of any address) brings the presenter's right back any more (a new
        login, a logout)."""
        with self._lock:
            for records in self._tabs.values():
                for r in records:
                    if r.get("presenter") and (address is None or r.get("address") == address):
                        r["presenter"] = False
                        self.changed += 1

    def offer(self, key: str) -> dict[str, Any] | None:
        """The newest own copy of browser ``key`` that nobody took back yet (for the *Restore* button), or None."""
        with self._lock:
            self._prune()
            private = [r for r in self._tabs.get(key, []) if r["private"] and r["saved"] is not None]
            return private[-1] if private else None

    def claim(self, key: str, record: dict[str, Any]) -> bool:
        """Take ``record`` (offered earlier) if it is still there."""
        with self._lock:
            records = self._tabs.get(key, [])
            if not any(r is record for r in records):
                return False
            records[:] = [r for r in records if r is not record]
            self.changed += 1
            if not records:
                self._forget(key)
            return True

    def snapshot(self) -> dict[str, list[dict[str, Any]]]:
        """Everything kept (oldest browser first), for the store."""
        with self._lock:
            self._prune()
            return {k: [dict(r) for r in v] for k, v in self._tabs.items()}

    def restore(self, tabs: dict[str, list[dict[str, Any]]]) -> None:
        """Keep the tabs of the store (oldest first; their camera is not saved), within the same bounds."""
        with self._lock:
            for key, records in tabs.items():
                address = str(records[0].get("address", "")) if records else ""
                if key not in self._tabs:
                    self._make_room(address)
                self._tabs.setdefault(key, []).extend(dict(r, camera=None, address=address) for r in records)
                self._address[key] = address
            self._prune()
            self._bound_uploads()

    def uploads(self) -> int:
        """Bytes of uploaded samples kept (tests and benchmarks)."""
        with self._lock:
            return sum(upload_bytes(r) for records in self._tabs.values() for r in records)

    def _bound_uploads(self) -> None:
        """Over :data:`MAX_UPLOAD_BYTES` of uploaded samples: let go the oldest upload of the address holding the
        most, until under it (under the lock)."""
        kept = [(r, n, a) for k, a in self._address.items() for r in self._tabs.get(k, []) if (n := upload_bytes(r))]
        total = sum(n for _r, n, _a in kept)
        if total <= MAX_UPLOAD_BYTES:
            return
        by_address: dict[str, int] = {}
        for _r, n, a in kept:
            by_address[a] = by_address.get(a, 0) + n
        kept.sort(key=lambda e: e[0]["left_at"])
        dropped = 0
        while total > MAX_UPLOAD_BYTES and kept:
            top = max(by_address, key=lambda a: by_address[a])
            index = next(i for i, e in enumerate(kept) if e[2] == top)
            record, n, address = kept.pop(index)
            record["saved"] = dataclasses.replace(record["saved"], source=None)
            record[UPLOAD_NOT_KEPT] = True
            total, by_address[address], dropped = total - n, by_address[address] - n, dropped + 1
        self.let_go += dropped
        told, at = self._told
        if time.monotonic() - at >= 60.0:  # one line a minute at most, with the count since the last one
            log.info(
                "let go %d uploaded trajectories of tabs that left (over %d MiB kept)",
                self.let_go - told,
                MAX_UPLOAD_BYTES >> 20,
            )
            self._told = (self.let_go, time.monotonic())

    def __len__(self) -> int:
        with self._lock:
            return len(self._tabs)
