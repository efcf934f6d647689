"""Nothing is lost on a blip or a restart: one tab's state taken (:func:`saved_of`) and given back
(:func:`restore`), and the lecture's store of this app (:func:`lecture_store`: :mod:`tpm_viz.classroom.lecture`,
saved every :data:`SAVE_SECONDS` when something changed).

Tabs that left are kept by :class:`tpm_viz.classroom.away.Away`; the app restores one when it can tell which tab is
back, and otherwise offers *Restore my own copy from before the drop* in that tab (it never puts a student on the
shared mechanism without saying so).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tpm_viz.classroom.lecture import LectureStore, default_path
from tpm_viz.classroom.runhub import RunHub, following
from tpm_viz.classroom.saver import SAVE_SECONDS
from tpm_viz.classroom.session import Session
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.core.words import Lang
from tpm_viz.ui.classroom import DEFAULT_KEYS
from tpm_viz.viserkit.core import widget_value

__all__ = [
    "PRESENTATION",
    "SAVE_SECONDS",
    "LectureStore",
    "default_path",
    "lecture_store",
    "reload",
    "restore",
    "saved_of",
]

PRESENTATION = "presentation"
"""The key of presentation mode (:mod:`.look`) among a saved tab's view options."""


def lecture_store(path: Path | None, fresh: bool = False) -> LectureStore:
    """The lecture's store of this app at ``path`` (None: nothing kept), signing cookies with the process's keys
    until it opens and reads the keys kept beside it."""
    return LectureStore(path, DEFAULT_KEYS, fresh)


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


def restore(view: Any, saved: Saved | None, private: bool, built: bool = False) -> None:
    """Give a tab back what it had before a drop: its own copy of ``saved`` (parameters, pose, load, loaded
    trajectory and player time) or the shared mechanism, its view options and its language (under the hub's lock).
    ``built``: the tab was built on its own copy of ``saved`` already (:meth:`.room.Room.build`); only the
    trajectory is loaded again."""
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
        if not built:
            source = Session(saved.state, shared=False)
            runs.of(source)  # an empty player: the copy does not inherit the shared run
            view.switch(True, source=source)
            view.panel.own_copy.value = True
        reload(runs, view.session, saved)
    view.client.flush()
