"""One browser tab: its scene and panel, and the callbacks that turn its inputs into state changes.

Every callback has the same shape: under the hub's lock, read the widget's *current* value, validate it, call a
pure library function (:mod:`tpm_viz.app.moves`, :mod:`tpm_viz.app.poses`, ``Params.replace``, trajectories),
and commit the new state, which redraws every view of the session. Events that the server caused itself (a
value written by :meth:`Panel.show`, which viser echoes synchronously with ``client=None``) are ignored.
A refused input is reported to this tab only, its widgets are re-synced and the last good state stays. The state
transitions themselves are the pure functions of :mod:`.transitions`; every callback is wrapped by
:func:`.guard.guarded`, so an unexpected exception is logged and reported to the tab, never left to the pool.
"""

from __future__ import annotations

import functools
import time
from typing import cast

import numpy as np
import viser

from tpm_viz.app import transitions
from tpm_viz.app.poses import DEMO_KINDS
from tpm_viz.app.state import AppState
from tpm_viz.classroom.dragging import Dragging
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.pacing import watch_phase, watch_slot
from tpm_viz.classroom.session import Hub, Session
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.markup import html
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, say
from tpm_viz.drawing import meshes
from tpm_viz.ui.fields import Place, Typing, control
from tpm_viz.ui.language import TabWords, first_language
from tpm_viz.ui.login import LoginPanel
from tpm_viz.ui.look import Look
from tpm_viz.ui.panels import CLASS_LINE, Panel
from tpm_viz.ui.scene import MechanismScene
from tpm_viz.ui.share import ShareBox
from tpm_viz.ui.tabscene import TabScene
from tpm_viz.ui.teaching.tabs import Services, Teaching
from tpm_viz.ui.worded import TabGui
from tpm_viz.viserkit.core import widget_value

__all__ = ["ClientView"]

NOTIFY_AGAIN_SECONDS = 5.0  # the same refusal pops up at most once per this many seconds per tab


def _size(params: Params) -> float:
    """Side of the base plate [m]: what the camera frames."""
    lo, hi = meshes.base_extent(params)
    return hi - lo


def _internal_error(view: ClientView, exc: Exception) -> None:
    """The guard's report to the tab whose callback failed (the traceback is in the server log)."""
    view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__))


_callback = control
"""Run a handler under the hub's lock, ignore echoes, refuse next to the control (:func:`.fields.control`)."""


class ClientView:
    """The scene, panel and callbacks of one connected browser tab."""

    def __init__(self, client: viser.ClientHandle, hub: Hub, services: Services, saved: Saved | None = None) -> None:
        """Build the tab, then join the shared mechanism, or with ``saved`` (a returning tab's own copy) a private
        copy of it from the first draw."""
        self.client = client
        self.hub = hub
        self.session: Session = hub.shared
        """The session this tab shows, set when it joins (:meth:`Hub.join`); until then (the tab being built under
        the hub's lock) the shared one, so a callback that arrives meanwhile finds it, then waits for the lock."""
        self.closed = False
        self.lang = first_language(client)
        """The language of this tab's words (:mod:`tpm_viz.core.words`): render a phrase with ``say(view.lang,
        ...)``."""
        self.gui = TabGui(client.gui, self.lang)
        """This tab's GUI: every element made through it shows its fixed texts in ``lang`` (:mod:`.worded`)."""
        self.login: LoginPanel | None = None
        """The presenter login of this tab (presenter mode only)."""
        self._notified: tuple[str, float] = ("", 0.0)
        self._slot: int | None = None  # the watch slot of this tab's last render (None: draw the next frame)
        self._phase = watch_phase(client.client_id)  # watching tabs draw in turn, not all at one commit
        self.typing = Typing(self)
        """The typed number fields of this tab (Enter, Apply, the quiet time: :mod:`.fields`)."""
        self.drags = Dragging(self)
        """The gizmo drags of this tab (:mod:`.dragging`)."""
        with hub.locked(), client.atomic():  # built and drawn, then sent as one: no wake-up of the loop per widget
            state = hub.shared.state if saved is None else saved.state
            self.words = TabWords(self)  # the Language selector, first in the panel; switches lang (ui/language.py)
            self.scene = TabScene(client, cast(MechanismScene, hub.shared.scene))
            self.teaching = Teaching(self, services)  # player, explorer, lessons (ui/teaching/)
            later = None if services.later is None else self.teaching.open  # Player, Equations, Lab: a moment later
            self.panel = Panel(self.gui, state, extra_tabs=self.teaching.build_tabs, later=later)
            with self.panel.tabs["setup"].add_tab("Share", icon=viser.Icon.SHARE):
                self.share = ShareBox(self, self.gui)  # *Copy share link* beside Class & view (ui/share.py)
            self.look = Look(self)  # phone layout, presentation mode, camera framed for the canvas (ui/look.py)
            self._wire()
            self.frame_camera(state.params)
            if saved is None:
                hub.join(self, private=False)
            else:
                self._join_own_copy(saved)
            self.scene.gizmo.on_update(self.drags.on_drag)  # once joined: a drag always finds its session
            self.teaching.attach()
            self._catch_up()

    def _catch_up(self) -> None:
        """Inputs that arrived while the tab was being built, before its callbacks were wired (viser stored the
        value and ran no callback): apply every widget value that differs from what the tab shows. The motion and
        parameter inputs are written by the first render, so only the choices the server never writes are read."""
        private = bool(widget_value(self.panel.own_copy))
        if private != (not self.session.shared):
            self.switch(private)
        for what, handle in self.panel.show_toggles.items():
            visible = bool(widget_value(handle))
            if visible != self.scene.show.get(what, True):
                self.scene.set_visible(what, visible)
        self.client.flush()

    def _join_own_copy(self, saved: Saved) -> None:
        """Join a new own copy of ``saved`` (with an empty player: it does not inherit the shared run; the saved
        trajectory is loaded again by :func:`.continuity.restore`), the box ticked."""
        source = Session(saved.state, shared=False)
        runs = self.teaching.services.runs
        runs.of(source)
        self.hub.join(self, private=True, session=source, scene=self.scene.open_private(saved.state.params))
        runs.adopt(self.session, source)
        self.panel.own_copy.value = True  # echoed with client=None: ignored

    def switch(self, private: bool, source: Session | None = None) -> None:
        """Move this tab to a new own copy of ``source`` (default: its session; a copy of ``source`` starts with its
        player, not the shared one's), or back to the shared mechanism (under the lock)."""
        old = self.session
        self.hub.leave(self, old)
        if private:
            origin = old if source is None else source
            scene = self.scene.open_private(origin.state.params)
            self.hub.join(self, private=True, session=origin, scene=scene)
            if source is not None:
                self.teaching.services.runs.adopt(self.session, source)
        else:
            self.scene.close_private()
            self.hub.join(self, private=False)
        self._slot = None
        self.teaching.switched(old)
        self.hub.membership_changed()

    # -- drawing -------------------------------------------------------------------------------------------
    def render(self, frame: Snapshot, *, dragging: bool = False) -> None:
        """Draw this tab's part of ``frame`` (called by the hub under its lock, after the session's mechanism) and
        flush at once; another tab's intermediate frames once per watch slot
        (:func:`~tpm_viz.classroom.pacing.watch_slot`:
        20 Hz, less in a lecture hall, the tabs in turn)."""
        if self.closed:
            return
        slot = watch_slot(time.monotonic(), len(self.session.views), self._phase)
        if frame.in_drag and not dragging and slot == self._slot:
            return
        self._slot = slot
        with self.client.atomic():
            self.scene.update(frame, dragging=dragging)
            self.panel.show(frame, self.lang)
            self.look.show()
            self.teaching.render(frame)
            size = _size(frame.state.params)
            if not 0.8 < size / self._framed_size < 1.25:  # the mechanism grew or shrank a lot: reframe
                self.frame_camera(frame.state.params)
        self.client.flush()

    def refuse(self, what: str | Phrase | BaseException, resync: bool = True, where: Place | None = None) -> None:
        """Tell this tab (only) that its input was refused (``what`` in the tab's language): next to the control
        that caused it (``where``: a note or typed box of the panel) or at the top of the panel; the mechanism keeps
        its last good state and, with ``resync``, this tab's widgets and gizmo show that state again."""
        text = say(self.lang, what)
        if where is not None:
            where.tell(what, self.lang)
        else:
            self.panel.tell(say(self.lang, "Refused: {text}", text=text))
        now = time.monotonic()
        if self._notified[0] != text or now - self._notified[1] > NOTIFY_AGAIN_SECONDS:
            self._notified = (text, now)
            self.client.add_notification(say(self.lang, "Input refused"), text, color="red", auto_close_seconds=8.0)
        if resync and self.session.frame is not None:
            self.panel.forget()
            self.scene.forget()
            if self.session.scene is not None:
                self.session.scene.update(self.session.frame)  # a private copy written again
            self._slot = None
            self.render(self.session.frame)
        self.client.flush()

    def frame_camera(self, params: Params) -> None:
        """Point this tab's camera at the whole mechanism, framed for its canvas (:mod:`.look`)."""
        self._framed_size = _size(params)
        self.look.frame(params)

    def close(self) -> None:
        """The tab went away: stop drawing and leave the session."""
        with self.hub.locked():
            self.closed = True
            self.typing.close()
            self.look.close()
            self.hub.leave(self, self.session)
            self.teaching.close()

    def set_class_info(self, text: str | Phrase) -> None:
        """The classroom line of the *Class & view* tab."""
        content = html(CLASS_LINE, text=say(self.lang, text))
        if self.panel.class_info.content != content:  # a line for every tab at every join: only what changed
            self.panel.class_info.content = content

    # -- commits -------------------------------------------------------------------------------------------
    def _commit(self, state: AppState, dragging: bool = False) -> None:
        self.panel.tell("")
        self.hub.commit(self.session, state, origin=self, dragging=dragging)  # checks that this tab may
        self.session.play_token += 1  # an input that changed the mechanism stops a playing trajectory

    # -- wiring --------------------------------------------------------------------------------------------
    def _wire(self) -> None:
        panel = self.panel
        self.typing.add(panel.p, self._apply_p)
        self.typing.add(panel.d_typed, self._apply_d)
        for name in ("f_ext", "dp", "ddp"):
            self.typing.add(panel.boxes()[name], functools.partial(self._apply_load, name))
        self.typing.add(panel.params, self._apply_params)
        for i, slider in enumerate(panel.d):
            slider.on_update(lambda event, i=i: self._on_d(event, i))
        panel.switch_mode.on_click(self._on_switch_mode)
        panel.home.on_click(self._on_home)
        for kind in DEMO_KINDS:
            panel.demo[kind].on_click(lambda event, kind=kind: self._on_demo(event, kind))
        panel.load_mode.on_update(self._on_load)
        panel.apply.on_click(self._on_apply)
        panel.paper.on_click(self._on_paper)
        panel.own_copy.on_update(self._on_own_copy)
        for what, handle in panel.show_toggles.items():
            handle.on_update(lambda event, what=what: self._on_show(event, what))
        panel.frame_camera.on_click(self.on_frame)

    def commit_drag(self, phase: str, position: np.ndarray) -> None:
        """Commit this tab's drag to ``position`` [m] (under the hub's lock; geared on a touch tab: ui/phone.py)."""
        state = self.session.state
        target = self.scene.geared(phase, position, state.pose.p)
        self._commit(transitions.drag(state, target), dragging=phase != "end")

    def commit_key(self, state: AppState) -> None:
        """Commit a key's move (:mod:`.keyboard`; under the hub's lock), with the permission of any input."""
        self._commit(state)

    def drag_ended(self) -> None:
        """This tab's drag ended inside another tab's commit: its gizmo is written back by that commit."""
        self.scene.forget()

    def tell(self, text: str | Phrase) -> None:
        """Show ``text`` in this tab's message line (empty: clear it)."""
        self.panel.tell(say(self.lang, text) if text else "")

    def run_changed(self) -> None:
        """The session's run changed: redraw this tab's player."""
        self.teaching.run_changed()

    def _apply_p(self, values) -> None:
        """The typed platform position (mm), settled (under the lock)."""
        self._commit(transitions.move(self.session.state, (values["p1"], values["p2"])))

    def _apply_d(self, values) -> None:
        """The typed actuator positions (mm, each already in the stroke), settled (under the lock)."""
        self._commit(transitions.drive_both(self.session.state, (values["d1"], values["d2"])))

    def _apply_load(self, name: str, values) -> None:
        """A typed load vector (``f_ext`` N, ``dp`` m/s, ``ddp`` m/s²), settled (under the lock)."""
        state = self.session.state
        load = {"f_ext": state.load.f_ext, "dp": state.load.dp, "ddp": state.load.ddp, name: tuple(values.values())}
        new = transitions.set_load(state, state.load.mode, load["f_ext"], load["dp"], load["ddp"])
        if new is not state:
            self._commit(new)

    def _apply_params(self, values) -> None:
        """The typed parameters (mm, kg), settled by Enter or *Apply parameters* (under the lock)."""
        self._commit(transitions.apply_params(self.session.state, values))

    @_callback(place="move_note")
    def _on_d(self, event, i: int) -> None:
        if self.panel.is_echo(self.panel.d[i]):
            return
        self._commit(transitions.drive(self.session.state, i, self.panel.d[i].value))

    @_callback(place="move_note")
    def _on_switch_mode(self, event) -> None:
        self._commit(transitions.switch(self.session.state))

    @_callback(place="move_note")
    def _on_home(self, event) -> None:
        self._commit(transitions.home(self.session.state))

    @_callback(place="move_note")
    def _on_demo(self, event, kind: str) -> None:
        self._commit(transitions.demo(self.session.state, kind))

    @_callback(place="forces_note")
    def _on_load(self, event) -> None:
        panel = self.panel
        if panel.is_echo(panel.load_mode):
            return
        state = self.session.state
        load = state.load
        new = transitions.set_load(state, panel.load_mode.value, load.f_ext, load.dp, load.ddp)
        if new is not state:
            self._commit(new)

    @_callback
    def _on_apply(self, event) -> None:  # the parameter fields settle as on Enter (refusals under the button)
        self.typing.settle(self.panel.params)

    @_callback(place="params")
    def _on_paper(self, event) -> None:
        self._commit(transitions.paper_params(self.session.state))
        self.panel.show_params(self.session.state.params, force=True)  # over anything typed there

    @_callback
    def _on_own_copy(self, event) -> None:
        private = bool(self.panel.own_copy.value)
        if private == (not self.session.shared):
            return
        self.panel.restore.visible = False  # a fresh copy (or the shared one): the old copy is no longer offered
        self.switch(private)

    @guarded
    def _on_show(self, event, what: str) -> None:
        if getattr(event, "client", None) is None:
            return
        with self.hub.locked():
            self.scene.set_visible(what, bool(self.panel.show_toggles[what].value))
            if self.session.scene is not None and self.session.frame is not None:
                self.session.scene.update(self.session.frame)  # a private copy: the flags apply at its next draw
            self.client.flush()

    @guarded
    def on_frame(self, event) -> None:
        """*Frame the mechanism* (the panel's, the box of live numbers'): the camera framed again for the canvas."""
        if getattr(event, "client", None) is None or self.closed:
            return
        with self.hub.locked():
            self.frame_camera(self.session.state.params)
            self.client.flush()
