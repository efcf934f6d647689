"""Uploads in flight: bounded per tab, per address and per server, and never kept after their tab or their end.

viser buffers every part of an upload in the tab's ``_current_file_upload_states`` until the declared size has
arrived, then hands the whole file to the upload button's callback as the button's value. What a hostile or simply
large class can make a server hold is therefore bounded here, before any byte is buffered:

- per tab: ``transport.MAX_UPLOADS`` uploads in flight (each at most ``MAX_UPLOAD_BYTES``);
- per client address: :data:`MAX_BYTES_PER_ADDRESS` bytes announced and not yet finished (a class behind one
  address, 30 students uploading a 540 kB CSV at once, fits);
- per server: :data:`MAX_BYTES_IN_FLIGHT`.

An upload over a bound is refused with one line (:class:`Refusal`: its phrase, shown in the tab's language by
:mod:`.transport`). Bytes are given back when the upload ends, is refused, runs out of time
(``transport.UPLOAD_TIMEOUT``) or its tab leaves (:meth:`UploadBudget.leave`, called when the tab's connection
ends). The timer of an unfinished upload holds its tab weakly: a tab that left is freed at once, not when the timer
fires.

Measured with ``benchmarks/bench_upload_flood.py`` (docs/classroom.md §5).
"""

from __future__ import annotations

import threading
import weakref
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from tpm_viz.core.words import Phrase, T

__all__ = ["BUSY_ADDRESS", "BUSY_SERVER", "MAX_BYTES_IN_FLIGHT", "MAX_BYTES_PER_ADDRESS", "Refusal", "UploadBudget"]
__all__ += ["budget_of", "expire_later"]
MAX_BYTES_PER_ADDRESS = 16 << 20
"""Bytes of unfinished uploads from one client address (16 MiB: 30 uploads of a 540 kB CSV at once)."""
MAX_BYTES_IN_FLIGHT = 64 << 20
"""Bytes of unfinished uploads on one server."""

BUSY_ADDRESS = T("too many uploads from your network are on their way: try again in a moment")
BUSY_SERVER = T("the server is receiving too many uploads: try again in a moment")


@dataclass(frozen=True)
class Refusal:
    """Why an upload is refused (its phrase, told to the tab)."""

    why: Phrase


class UploadBudget:
    """The bytes of the uploads in flight on one server, by tab and address (thread-safe)."""

    def __init__(self, per_address: int = MAX_BYTES_PER_ADDRESS, total: int = MAX_BYTES_IN_FLIGHT) -> None:
        self.per_address, self.total = per_address, total
        self._lock = threading.Lock()
        self._held: dict[tuple[int, str], tuple[str, int]] = {}  # (tab, transfer) -> (address, bytes)
        self.refused = 0
        """Uploads refused over a bound (tests and benchmarks)."""

    def take(self, tab: int, address: str, transfer: str, size: int) -> Refusal | None:
        """Hold ``size`` bytes for ``tab``'s upload ``transfer`` from ``address`` (None), or why not."""
        with self._lock:
            if (tab, transfer) in self._held:
                return None
            by_address = sum(n for a, n in self._held.values() if a == address)
            in_all = sum(n for _a, n in self._held.values())
            refusal = None
            if by_address + size > self.per_address:
                refusal = Refusal(BUSY_ADDRESS)
            elif in_all + size > self.total:
                refusal = Refusal(BUSY_SERVER)
            if refusal is not None:
                self.refused += 1
                return refusal
            self._held[(tab, transfer)] = (address, max(0, int(size)))
            return None

    def give(self, tab: int, transfer: str) -> None:
        """``tab``'s upload ``transfer`` ended (finished, refused, timed out): its bytes are free again."""
        with self._lock:
            self._held.pop((tab, transfer), None)

    def leave(self, tab: int) -> None:
        """``tab``'s connection ended: the bytes of its unfinished uploads are free again."""
        with self._lock:
            for key in [k for k in self._held if k[0] == tab]:
                del self._held[key]

    def held(self, address: str | None = None) -> int:
        """Bytes held (from ``address``, or in all)."""
        with self._lock:
            return sum(n for a, n in self._held.values() if address is None or a == address)


_BUDGETS: weakref.WeakKeyDictionary[Any, UploadBudget] = weakref.WeakKeyDictionary()
_BUDGETS_LOCK = threading.Lock()


def budget_of(server: Any) -> UploadBudget:
    """The upload budget of a viser server (made on first use)."""
    with _BUDGETS_LOCK:
        budget = _BUDGETS.get(server)
        if budget is None:
            budget = _BUDGETS[server] = UploadBudget()
        return budget


def expire_later(loop: Any, seconds: float, owner: Any, expire: Callable[[Any, str], None], transfer: str) -> Any:
    """Call ``expire(owner, transfer)`` after ``seconds`` on ``loop`` unless ``owner`` (a tab's upload handling) is
    gone by then: the timer holds it weakly. -> the timer handle (``cancel()`` it)."""
    ref = weakref.ref(owner)

    def fire() -> None:
        alive = ref()
        if alive is not None:
            expire(alive, transfer)

    return loop.call_later(seconds, fire)
