"""Nothing is lost on a blip or a restart: the classroom's store as the app uses it (:class:`Store`), and one tab's
state taken (:func:`saved_of`) and given back (:func:`restore`).

Tabs that left are kept by :class:`tpm_viz.classroom.away.Away`; the app restores one when it can tell which tab is
back, and otherwise offers *Restore my own copy from before the drop* in that tab (it never puts a student on the
shared mechanism without saying so).

:class:`Store` is the SQLite store of :mod:`tpm_viz.classroom.store` (``platformdirs`` user data folder, or
``--session FILE``), read once at start and saved every :data:`SAVE_SECONDS` when something changed by a
:class:`~tpm_viz.classroom.saver.Saver`. ``--session FILE`` naming a JSON session file (a *Save session* download,
or the file of an older tpm-viz) imports it once into a store beside it (``FILE.sqlite3``) and never writes it. The
old ``session.json`` of the data folder is imported the same way. The cookie secret is kept beside the store.
"""

from __future__ import annotations

import hashlib
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import platformdirs

from tpm_viz.app.sessions import MAX_DOCUMENT_BYTES, Document, Saved
from tpm_viz.classroom.identity import Keys
from tpm_viz.classroom.records import Records, import_json
from tpm_viz.classroom.saver import SAVE_SECONDS, Saver
from tpm_viz.classroom.store import Limits, SqliteStore, is_sqlite, open_store
from tpm_viz.errors import TpmVizError
from tpm_viz.files import read_bytes
from tpm_viz.ui._viser import widget_value
from tpm_viz.ui.classroom import DEFAULT_KEYS
from tpm_viz.ui.session import Session
from tpm_viz.ui.teaching.playing import RunHub, following
from tpm_viz.words import Lang

__all__ = ["PRESENTATION", "SAVE_SECONDS", "Store", "default_path", "reload", "restore", "saved_of"]

PRESENTATION = "presentation"
"""The key of presentation mode (:mod:`.look`) among a saved tab's view options."""


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


class Store:
    """The classroom's store for one app: :meth:`open` (notices on stderr), :meth:`load`, :meth:`start`,
    :meth:`stop`. ``path`` None: nothing is kept (in-memory cookie keys of the process)."""

    def __init__(self, path: Path | None, fresh: bool = False, limits: Limits = Limits()) -> None:
        self.path = None if path is None else Path(path)
        self.fresh, self.limits = fresh, limits
        self.keys = DEFAULT_KEYS
        """Mints and checks the browsers' cookies (:mod:`tpm_viz.classroom.identity`)."""
        self.notices: list[str] = []
        """One-line notices of the start (a store set aside, a file imported, records skipped)."""
        self.store: SqliteStore | None = None
        self.records: Records | None = None
        self.where = "" if path is None else str(path)
        self._saver: Saver | None = None
        self._opened = False

    def _notice(self, line: str | None) -> None:
        if line:
            self.notices.append(line)
            print(f"warning: {line}", file=sys.stderr, flush=True)

    def open(self) -> None:
        """Open (or make) the store, move an unreadable one aside, import a JSON session file once; idempotent.
        Problems are notices: the app starts with the defaults rather than not at all."""
        if self._opened or self.path is None:
            return
        self._opened = True
        target, source = _places(self.path)
        self.where = str(target)
        try:
            self.store, notice = open_store(target, self.limits, fresh=self.fresh)
        except Exception as exc:  # e.g. an unwritable folder or a locked file: the lesson goes on unsaved
            self._notice(f"cannot open the session store {target} ({str(exc)[:160]}); nothing will be saved")
            return
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

    def stop(self) -> None:
        """Stop saving after a last save; close the store."""
        if self._saver is not None:
            self._saver.stop(final=True)
        if self.store is not None:
            self.store.close()


def _digest(path: Path) -> str:
    return hashlib.sha256(read_bytes(path, MAX_DOCUMENT_BYTES)).hexdigest()


# -- one tab ---------------------------------------------------------------------------------------------------------
def saved_of(view: Any) -> Saved:
    """What a tab (:class:`~.client.ClientView`) has, to give it back after a drop (:func:`restore`)."""
    ps = view.teaching.services.runs.of(view.session)
    source = ps.run.source if ps.run is not None else ps.loading
    show = {what: bool(widget_value(h)) for what, h in view.panel.show_toggles.items()}
    show[PRESENTATION] = bool(view.look.presentation)
    return Saved(view.session.state, source, view.session.state.trajectory.t, show, view.lang.value)


def reload(runs: RunHub, session: Session, saved: Saved) -> None:
    """Load ``saved``'s trajectory into ``session`` (in the background), then put the session back at the saved
    player time, or at the saved pose if it had been moved off the path (under the hub's lock)."""
    if saved.source is None:
        return

    def done(run) -> None:
        if following(saved.state, run):
            runs.seek(session, min(saved.state.trajectory.t, run.duration))
        elif run.params == saved.state.params:
            runs.hub.commit(session, saved.state)

    runs.load(session, saved.source, on_done=done)


def restore(view: Any, saved: Saved | None, private: bool) -> None:
    """Give a tab back what it had before a drop: its own copy of ``saved`` (parameters, pose, load, loaded
    trajectory and player time) or the shared mechanism, its view options and its language (under the hub's lock)."""
    if saved is not None:
        view.words.set(Lang.parse(saved.lang, default=view.lang))
        if saved.show.get(PRESENTATION, False) != view.look.presentation:
            view.panel.presentation.value = saved.show[PRESENTATION]  # echoed with client=None: ignored
            view.look.set_presentation(saved.show[PRESENTATION])
        for what, visible in saved.show.items():
            handle = view.panel.show_toggles.get(what)
            if handle is not None and bool(widget_value(handle)) != visible:
                handle.value = visible  # viser echoes it with client=None: ignored by the callback
                view.scene.set_visible(what, visible)
    if private and saved is not None:
        runs = view.teaching.services.runs
        source = Session(saved.state, shared=False)
        runs.of(source)  # an empty player: the copy does not inherit the shared run
        view.switch(True, source=source)
        view.panel.own_copy.value = True
        reload(runs, view.session, saved)
    view.client.flush()
