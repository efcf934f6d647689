"""Nothing is lost on a blip or a restart: tabs that left (:class:`Away`) and the session file (:class:`Store`).

viser gives every websocket connection a new client id, and its page sends nothing that identifies the tab when
it reconnects (no URL parameters, no storage of its own on reconnect). What does survive is the browser's cookie
(:mod:`.classroom`): a tab is recognised by its browser, and when the browser has several tabs, by the camera it
sends first (a reconnecting page keeps its camera). :class:`Away` keeps each tab that left (its own copy or
not, parameters, pose, load, trajectory and player time, view options and presentation mode, language) for
:data:`~tpm_viz.app.sessions.KEEP_SECONDS`; the app restores it when it can tell which tab is back, and otherwise
offers *Restore my own copy from before the drop* in that tab (it never puts a student on the shared mechanism
without saying so).

:class:`Store` writes the shared mechanism and the away tabs to the session file (``platformdirs`` user data
folder, or ``--session FILE``) every :data:`SAVE_SECONDS` when something changed, atomically, and reads it back at
start: an unreadable or old file is one warning line and the defaults.
"""

from __future__ import annotations

import sys
import threading
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import platformdirs

from tpm_viz.app import sessions
from tpm_viz.app.sessions import KEEP_SECONDS, Document, Saved
from tpm_viz.errors import TpmVizError
from tpm_viz.ui._viser import widget_value
from tpm_viz.ui.guard import report
from tpm_viz.ui.session import Session
from tpm_viz.ui.teaching.playing import RunHub, following
from tpm_viz.words import Lang

__all__ = ["PRESENTATION", "SAVE_SECONDS", "Away", "Store", "default_path", "reload", "restore", "saved_of"]

PRESENTATION = "presentation"
"""The key of presentation mode (:mod:`.look`) among a saved tab's view options."""

SAVE_SECONDS = 2.0
"""Longest time a change to the shared mechanism waits before it is on disk."""
MAX_PER_BROWSER = 8
MAX_AWAY = 2000


def default_path() -> Path:
    """The session file in the user's data folder (e.g. ``~/.local/share/tpm-viz/session.json``)."""
    return Path(platformdirs.user_data_dir("tpm-viz", appauthor=False)) / "session.json"


def _close(a: Any, b: Any) -> bool:
    if a is None or b is None:
        return False
    x, y = np.asarray(a, dtype=float), np.asarray(b, dtype=float)
    return x.shape == y.shape and bool(np.allclose(x, y, atol=1e-6))


class Away:
    """Tabs that left, per browser identity, newest last; each for :data:`KEEP_SECONDS`. Thread-safe."""

    def __init__(self, clock: Callable[[], float] = time.time) -> None:
        self._clock = clock
        self._lock = threading.Lock()
        self._tabs: dict[str, list[dict[str, Any]]] = {}

    def _prune(self) -> None:
        now = self._clock()
        for key in list(self._tabs):
            kept = [r for r in self._tabs[key] if now - r["left_at"] <= KEEP_SECONDS][-MAX_PER_BROWSER:]
            if kept:
                self._tabs[key] = kept
            else:
                del self._tabs[key]
        while len(self._tabs) > MAX_AWAY:
            del self._tabs[next(iter(self._tabs))]

    def park(self, key: str, private: bool, saved: Saved | None, camera: Any = None, presenter: bool = False) -> None:
        """A tab of browser ``key`` left: keep what it had (and whether it was the presenter's)."""
        with self._lock:
            record = {"private": private, "saved": saved, "left_at": self._clock(), "camera": camera}
            record["presenter"] = presenter
            self._tabs.setdefault(key, []).append(record)
            self._prune()

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
                if not records:
                    self._tabs.pop(key, None)
            return chosen

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
            if not records:
                self._tabs.pop(key, None)
            return True

    def snapshot(self) -> dict[str, list[dict[str, Any]]]:
        """Everything kept, for the session file."""
        with self._lock:
            self._prune()
            return {k: [dict(r) for r in v] for k, v in self._tabs.items()}

    def restore(self, tabs: dict[str, list[dict[str, Any]]]) -> None:
        """Keep the tabs of a session file (their camera is not saved)."""
        with self._lock:
            for key, records in tabs.items():
                self._tabs.setdefault(key, []).extend(dict(r, camera=None) for r in records)
            self._prune()


class Store:
    """The session file: read once at start, written atomically when the session changed."""

    def __init__(self, path: Path | None, fresh: bool = False) -> None:
        self.path = path
        self.fresh = fresh
        self._written = ""
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None
        self._lock = threading.Lock()

    def load(self) -> Document | None:
        """The saved session, or None (no file, ``--fresh``, or one warning line on stderr if it is unusable)."""
        if self.path is None or self.fresh or not self.path.exists():
            return None
        try:
            return sessions.read_file(self.path)
        except TpmVizError as exc:
            print(f"warning: {exc}; starting with the defaults", file=sys.stderr, flush=True)
            return None

    def save(self, document: Callable[[], Document]) -> bool:
        """Write the session if it changed since the last write; True if written."""
        if self.path is None:
            return False
        with self._lock:
            doc = document()
            text = sessions.dumps(doc, saved_at=0.0)
            if text == self._written:
                return False
            sessions.write_atomic(self.path, sessions.dumps(doc))
            self._written = text
            return True

    def start(self, document: Callable[[], Document]) -> None:
        """Save every :data:`SAVE_SECONDS` in a daemon thread (a failed save is logged, the next one retried)."""
        if self.path is None or self._thread is not None:
            return

        def loop() -> None:
            while not self._stop.wait(SAVE_SECONDS):
                try:
                    self.save(document)
                except Exception as exc:  # a full disk must not stop the lesson
                    report(exc, f"saving the session to {self.path}")

        self._thread = threading.Thread(target=loop, name="tpm-viz-save", daemon=True)
        self._thread.start()

    def stop(self, document: Callable[[], Document] | None = None) -> None:
        """Stop saving; write a last time if ``document`` is given."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(timeout=5.0)
        if document is not None:
            try:
                self.save(document)
            except Exception as exc:
                report(exc, f"saving the session to {self.path}")


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
