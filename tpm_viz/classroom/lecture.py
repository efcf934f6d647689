"""The lecture's store as the app uses it: where it lives (the user data folder, or ``--session FILE``), opening it
(an unreadable one moved aside, a JSON session file imported once), loading the lecture and the remembered tabs,
and saving from then on (:class:`~tpm_viz.classroom.saver.Saver`). No viser: the UI gives it a document to save and
a way to tell the terminal and the lecturer.

``--session FILE`` naming a JSON session file (a *Save session* download, or the file of an older tpm-viz) imports
it once into a store beside it (``FILE.sqlite3``) and never writes it; the old ``session.json`` of the data folder is
imported the same way. The cookie secret is kept beside the store.

One server per store: :meth:`LectureStore.open` first takes the store's lock (:mod:`.storelock`) and refuses, with
one line naming the other server's port, a store another live server holds; a store path that exists and is not a
regular file (a device, a FIFO, a folder) is refused in one line too (:func:`tpm_viz.core.files.output_target`).
Both refusals stop the start (:class:`~tpm_viz.core.errors.InputError`); every other problem is a notice and the
lesson goes on unsaved.
"""

from __future__ import annotations

import hashlib
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import platformdirs

from tpm_viz.classroom.identity import Keys
from tpm_viz.classroom.records import Records, import_json
from tpm_viz.classroom.saver import Saver
from tpm_viz.classroom.sessionfile import MAX_DOCUMENT_BYTES, Document
from tpm_viz.classroom.store import Limits, SqliteStore, is_sqlite, open_store
from tpm_viz.classroom.storelock import StoreLock
from tpm_viz.core.errors import FileRefusedError, InputError, TpmVizError
from tpm_viz.core.files import output_target, read_bytes
from tpm_viz.core.words import Phrase

__all__ = ["LectureStore", "default_path"]


def default_path() -> Path:
    """The store in the user's data folder (e.g. ``~/.local/share/tpm-viz/classroom.sqlite3``)."""
    return Path(platformdirs.user_data_dir("tpm-viz", appauthor=False)) / "classroom.sqlite3"


def _places(path: Path) -> tuple[Path, Path | None]:
    """``(store, JSON file to import or None)`` for ``--session path``."""
    if path.exists() and path.is_file() and path.stat().st_size > 0 and not is_sqlite(path):
        with open(path, "rb") as handle:
            start = handle.read(64).lstrip(b"\xef\xbb\xbf \t\r\n")
        if start.startswith(b"{") or path.suffix.lower() == ".json":
            return path.with_name(path.name + ".sqlite3"), path
    old = path.with_name("session.json")
    return path, old if path == default_path() and old.is_file() else None


class LectureStore:
    """The classroom's store for one app: :meth:`open` (notices on stderr), :meth:`load`, :meth:`start`,
    :meth:`stop`. ``path`` None: nothing is kept, and ``keys`` (the process's, in memory) sign the cookies; else the
    keys kept beside the store replace them when it opens."""

    def __init__(self, path: Path | None, keys: Keys, fresh: bool = False, limits: Limits = Limits()) -> None:
        self.path = None if path is None else Path(path)
        self.fresh, self.limits = fresh, limits
        self.keys = keys
        """Mints and checks the browsers' cookies (:mod:`tpm_viz.classroom.identity`)."""
        self.notices: list[str] = []
        """One-line notices of the start (a store set aside, a file imported, records skipped)."""
        self.store: SqliteStore | None = None
        self.records: Records | None = None
        self.where = "" if path is None else str(path)
        self._saver: Saver | None = None
        self._lock: StoreLock | None = None
        self._opened = False

    def _notice(self, line: str | None) -> None:
        if line:
            self.notices.append(line)
            print(f"warning: {line}", file=sys.stderr, flush=True)

    def open(self) -> None:
        """Open (or make) the store, move an unreadable one aside, import a JSON session file once; idempotent.
        Problems are notices: the app starts with the defaults rather than not at all, except a store another live
        server holds (:class:`~tpm_viz.classroom.storelock.StoreBusyError`) or a path that is not a regular file:
        one-line :class:`~tpm_viz.core.errors.InputError`, nothing read, moved or written."""
        if self._opened or self.path is None:
            return
        target, source = _places(self.path)
        try:
            output_target(target, folder=False)  # the store makes its folder
        except FileRefusedError as exc:
            raise InputError(Phrase("session store {why}", why=exc.args[0])) from None
        self._lock, lock_notice = StoreLock.take(target)  # before anything is read or moved aside (--fresh)
        self._opened = True
        self.where = str(target)
        try:
            self.store, notice = open_store(target, self.limits, fresh=self.fresh)
        except Exception as exc:  # e.g. an unwritable folder or a locked file: the lesson goes on unsaved
            self._notice(f"cannot open the session store {target} ({str(exc)[:160]}); nothing will be saved")
            return
        self._notice(lock_notice)  # a store that saves without a lock (a store that cannot save said so above)
        self._notice(notice)
        self.records = Records(self.store)
        self.keys, notice = Keys.in_folder(target.parent)
        self._notice(notice)
        if source is not None:
            try:
                if self.fresh:
                    self.store.mark_imported(_digest(source), str(source))
                else:
                    self._notice(import_json(self.store, source, self.records))
            except Exception as exc:  # the import is a bonus: never a reason not to start
                self._notice(f"{source} not imported ({str(exc)[:160]})")

    def load(self, steps: int | None = None) -> tuple[Document | None, dict[str, list[dict[str, Any]]]]:
        """The lecture (None: none kept, or unreadable: one notice) and the remembered tabs (keyed by hashed
        identity, each record with its address). An unreadable record is skipped with one notice."""
        self.open()
        if self.store is None or self.records is None:
            return None, {}
        contents = self.store.load()
        skipped = contents.skipped
        doc = None
        if contents.lecture is not None:
            try:
                shared, step = self.records.read_lecture(contents.lecture, steps)
                doc = Document(shared, step)
            except TpmVizError as exc:
                self._notice(f"the lecture in {self.where} could not be read ({exc}); the defaults instead")
        tabs, bad = self.records.read_copies(contents.copies, time.time())
        if skipped + bad:
            self._notice(f"{skipped + bad} record(s) of {self.where} could not be read and were skipped")
        return doc, tabs

    def start(self, document: Callable[[], Document], say: Callable[[str, bool], None]) -> None:
        """Save ``document()`` from now on; ``say(line, problem)`` tells the terminal and the lecturer."""
        if self.records is None or self._saver is not None:
            return
        self._saver = Saver(self.records, document, say, self.where)
        self._saver.start()

    def serving(self, port: int) -> None:
        """The server listens on ``port``: a second server refused on this store is told which one holds it."""
        if self._lock is not None:
            self._lock.serving(port)

    def stop(self) -> None:
        """Stop saving after a last save; close the store; let the next server take it."""
        if self._saver is not None:
            self._saver.stop(final=True)
        if self.store is not None:
            self.store.close()
        if self._lock is not None:
            self._lock.release()


def _digest(path: Path) -> str:
    return hashlib.sha256(read_bytes(path, MAX_DOCUMENT_BYTES)).hexdigest()
