"""Saving the classroom: every :data:`SAVE_SECONDS` when something changed, one transaction per save.

:meth:`Saver.save` writes only the records that changed since the last successful save (the lecture, the browsers
whose tabs changed) and removes the browsers that are gone, in one :meth:`~.store.Store.save`. A save that fails (a
full disk, an unwritable folder, a locked file) is said once (``say(line, True)``: the terminal and the lecturer's
panel), retried after 2, 4, 8 ... up to :data:`MAX_BACKOFF_SECONDS` seconds, and its recovery is said once
(``say(line, False)``); nothing is logged in between, no traceback.
"""

from __future__ import annotations

import json
import sqlite3
import threading
from collections.abc import Callable

from tpm_viz.classroom.records import Records
from tpm_viz.classroom.sessionfile import Document
from tpm_viz.core.errors import TpmVizError

__all__ = ["MAX_BACKOFF_SECONDS", "SAVE_SECONDS", "Saver"]

SAVE_SECONDS = 2.0
"""Longest time a change to the classroom waits before it is on disk (when saving works)."""
MAX_BACKOFF_SECONDS = 60.0


class Saver:
    """Saves ``document()`` through ``records`` (see the module docstring); ``where`` names the store in lines."""

    def __init__(
        self,
        records: Records,
        document: Callable[[], Document],
        say: Callable[[str, bool], None],
        where: str,
        period: float = SAVE_SECONDS,
    ) -> None:
        self.records, self.document, self.say, self.where = records, document, say, where
        self.period = period
        self.failing = False
        self.delay = period
        self._lecture = ""
        self._written: dict[str, str] = {}
        self._lock = threading.Lock()
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def save(self) -> bool:
        """Write what changed; True if something was written. Raises what the store raised."""
        with self._lock:
            doc = self.document()
            lecture = self.records.lecture(doc)
            copies = self.records.copies(doc)
            lecture_text = json.dumps(lecture, sort_keys=True)
            texts = {k: json.dumps([c.address, c.body], sort_keys=True) for k, c in copies.items()}
            changed = {k: c for k, c in copies.items() if self._written.get(k) != texts[k]}
            gone = [k for k in self._written if k not in copies]
            if lecture_text == self._lecture and not changed and not gone:
                return False
            self.records.store.save(lecture if lecture_text != self._lecture else None, changed, gone)
            self._lecture, self._written = lecture_text, texts
            return True

    def tick(self) -> None:
        """One save attempt, with the failure said once and the recovery said once."""
        try:
            self.save()
        except (sqlite3.Error, OSError, TpmVizError, ValueError) as exc:
            if not self.failing:
                self.failing = True
                why = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
                self.say(f"cannot save the session to {self.where} ({why}); retrying, nothing is lost yet", True)
            self.delay = min(self.delay * 2, MAX_BACKOFF_SECONDS)
            return
        if self.failing:
            self.failing = False
            self.say(f"the session is saved again to {self.where}", False)
        self.delay = self.period

    def start(self) -> None:
        """Save in a daemon thread from now on."""
        if self._thread is not None:
            return

        def loop() -> None:
            while not self._stop.wait(self.delay):
                self.tick()

        self._thread = threading.Thread(target=loop, name="tpm-viz-save", daemon=True)
        self._thread.start()

    def stop(self, final: bool = True) -> None:
        """Stop the thread; save a last time if ``final``."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        if final:
            self.tick()
