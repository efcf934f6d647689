"""The guided demonstrations of one tab: choose a scene (or step with Previous / Next), read its paragraph,
play its motion.

A demonstration (a lesson file read by :mod:`tpm_viz.app.lesson_files`: the packaged tour
:data:`tpm_viz.app.lessons.DEMOS`, or a lecturer's folder given to ``tpm-viz serve --lessons DIR``) sets the
session's mechanism (parameters, pose and its trajectory, loaded into the player), this tab's camera and this
tab's explorer settings (map, ellipses). The numbers that back its claim (:func:`tpm_viz.app.lessons.effect`)
are computed when it is applied, outside the hub's lock, and shown under the paragraph. Lesson files that were
refused are listed under the tab's introduction, one line each.

Words: the paragraph is the lesson's own in the tab's language (``[text] ko``, else English); titles, buttons and
the introduction are shown in it by the tab's connection (:mod:`tpm_viz.ui.language`); :meth:`DemosView.retell`
writes the paragraph again when the tab's language changes.
"""

from __future__ import annotations

import html
from collections.abc import Callable, Sequence

import numpy as np
import viser

from tpm_viz.app.lessons import DEMOS, PROBLEMS, Demo, demo_params, demo_pose, demo_source, effect
from tpm_viz.app.readouts import Load
from tpm_viz.app.state import TrajectorySample
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.runhub import RunHub
from tpm_viz.classroom.session import View
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.markup import Html, Markdown
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.ui.scene import camera_pose
from tpm_viz.ui.teaching.explorer import ExplorerView
from tpm_viz.ui.worded import TabGui
from tpm_viz.viserkit.core import point_camera

__all__ = ["DemosView"]

NONE = "(no lessons)"
PRESS_SHOW = T("Press 'Show this one' to set up the scene.")


def _internal_error(owner, exc: Exception) -> None:
    what = Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__)
    owner.view.refuse(what, resync=False)


def problems_html(problems: Sequence[str], lang: Lang = Lang.EN) -> Html:
    """The lesson files that were refused, one line each (``file:line: what is wrong``), in ``lang`` (a
    :class:`~tpm_viz.app.lesson_toml.Problem` keeps its phrase; any other line is shown as it is)."""
    lines = "".join(f"<li>{html.escape(say(lang, getattr(p, 'phrase', p)))}</li>" for p in problems)
    head = say(lang, "{count} lesson file(s) refused:", count=len(problems))
    return Html(
        f'<div data-q="demo-problems" style="font-size:0.8em;color:#b91c1c"><b>{html.escape(head)}'
        f'</b><ul style="margin:2px 0 0 16px;padding:0">{lines}</ul></div>'
    )


def demo_html(demo: Demo, facts: str, lang: Lang = Lang.EN) -> Html:
    """The paragraph of a demonstration in ``lang`` (English if the lesson has none in it) and the line of numbers
    that backs it."""
    esc = html.escape
    return Html(
        f'<div data-q="demo" lang="{lang.value}" style="font-size:0.85em;color:#1e293b;line-height:1.45">'
        f"<p style='margin:0 0 6px 0'>{esc(demo.text_in(lang.value))}</p>"
        + (
            f'<div data-q="demo-effect" style="background:#f1f5f9;border-left:3px solid #0d9488;padding:4px 6px;'
            f'border-radius:3px;font-variant-numeric:tabular-nums">{esc(facts)}</div>'
            if facts
            else ""
        )
        + "</div>"
    )


class DemosView:
    """Demonstration widgets of one tab."""

    def __init__(
        self,
        view: View,
        runs: RunHub,
        explorer: ExplorerView,
        speed: Callable[[], float],
        lessons: Sequence[Demo] | None = None,
        problems: Sequence[str] = (),
    ) -> None:
        """``lessons``: the tour (default: the packaged one, with its own ``problems``); ``problems``: the lesson
        files refused (:func:`tpm_viz.app.lessons.load_lessons`), shown under the introduction."""
        self.view = view
        self.lessons = tuple(DEMOS if lessons is None else lessons)
        self.problems = tuple(PROBLEMS if lessons is None else problems)
        self.titles = tuple(d.title for d in self.lessons)
        self._speed = speed
        """The player's playback speed (x real time): *Play the motion* plays at it."""
        self.runs = runs
        self.explorer = explorer
        self.index = 0
        self._written: str | None = None
        self._facts: object = PRESS_SHOW
        """What the line under the paragraph says: the numbers of the lesson applied last (a text or a phrase)."""

    def build(self, gui: TabGui) -> None:
        """The *Demos* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            Markdown(
                "A guided tour for a lecture. Each scene sets the mechanism (shared with the class unless you work on "
                "your own copy), your camera and your floor map; *Play the motion* runs its trajectory in the Player."
            )
        )
        if self.problems:
            self.problems_note = gui.add_html(problems_html(self.problems, self.view.lang))
        titles = self.titles or (NONE,)
        self.choice = gui.add_dropdown("Demonstration", titles, initial_value=titles[0])
        self.steps = gui.add_button_group("Step", ("Previous", "Show this one", "Next"))
        self.play = gui.add_button("Play the motion", icon=viser.Icon.PLAYER_PLAY)
        self.text = gui.add_html(self._paragraph())
        if not self.lessons:
            self.choice.disabled = self.steps.disabled = self.play.disabled = True
        self.choice.on_update(self._on_choice)
        self.steps.on_click(self._on_step)
        self.play.on_click(self._on_play)

    def _paragraph(self) -> Html:
        """The current lesson's paragraph and numbers in the tab's language."""
        lang = self.view.lang
        if not self.lessons:
            return Html(f"<p>{html.escape(say(lang, 'No lessons to show.'))}</p>")
        return Html(demo_html(self.lessons[self.index], say(lang, self._facts), lang))

    def retell(self) -> None:
        """The tab's language changed: the paragraph and the refused files again, in it (under the hub's lock)."""
        if hasattr(self, "text"):
            self.text.content = self._paragraph()
        if self.problems and hasattr(self, "problems_note"):
            self.problems_note.content = problems_html(self.problems, self.view.lang)

    def _refuse(self, exc: Exception) -> None:
        with self.view.hub.locked():
            self.view.refuse(exc)

    def _user(self, event) -> bool:
        return getattr(event, "client", None) is not None and not getattr(self.view, "closed", False)

    @guarded(on_error=_internal_error)
    def _on_choice(self, event) -> None:
        if not self._user(event) or self.choice.value == self._written:
            return
        if self.choice.value in self.titles:
            self.show(self.titles.index(self.choice.value))

    @guarded(on_error=_internal_error)
    def _on_step(self, event) -> None:
        if not self._user(event) or not self.lessons:
            return
        step = {"Previous": -1, "Show this one": 0, "Next": 1}.get(self.steps.value, 0)
        self.show((self.index + step) % len(self.lessons))

    @guarded(on_error=_internal_error)
    def _on_play(self, event) -> None:
        if not self._user(event):
            return
        try:
            self.runs.play(self.view.session, self._speed(), origin=self.view)
        except TpmVizError as exc:
            self._refuse(exc)

    def show(self, index: int) -> None:
        """Apply demonstration ``index``: mechanism, trajectory, camera, explorer; explain it."""
        demo = self.lessons[index]
        try:
            params = demo_params(demo)
            pose = demo_pose(demo, params)
            source = demo_source(demo)
            facts = effect(demo)
        except TpmVizError as exc:  # pragma: no cover - a lesson is checked when it is loaded
            self._refuse(exc)
            return
        camera = (demo.camera.position, demo.camera.look_at) if demo.camera is not None else camera_pose(params)
        view = self.view
        with view.hub.locked():
            self.index = index
            self._written = demo.title
            self.choice.value = demo.title
            self._facts = facts
            self.text.content = self._paragraph()
            self.play.disabled = source is None
            session = view.session
            state = session.state
            sample = TrajectorySample("none", state.trajectory.duration, 0.0)
            new = state.replace(params=params, pose=pose, load=Load(), trajectory=sample, note="")
            try:
                view.hub.authorize(view, session)
                if source is not None:
                    self.runs.of(session).extra = source
                else:  # a still scene: no trajectory (the previous one may not fit the new parameters)
                    self.runs.unload(session)
                view.tell("")
                session.play_token += 1
                view.hub.commit(session, new, origin=view)
            except TpmVizError as exc:
                view.refuse(exc)
                return
            position, look_at = (np.asarray(v, dtype=float) for v in camera)  # the canvas is free (docked panel)
            point_camera(view.client.camera, position, look_at)
            self.explorer.set(kind=demo.map_kind, ellipses=demo.ellipses)
            view.client.flush()
        if source is not None:
            try:
                self.runs.load(session, source, origin=view)
            except TpmVizError as exc:
                self._refuse(exc)

    def render(self, frame: Snapshot) -> None:
        """Nothing per frame: the paragraph changes only when a demonstration is applied."""
