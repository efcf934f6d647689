"""The *Control* tab of one browser tab: simulate a controller tracking a reference on the Pinocchio
plant, play the run, compare the controllers.

Widgets: controller (PD, PD + feedforward, computed torque), ω_n and ζ (gains shown), mismatch (payload, mass
error), limits (force limit, controller rate, position noise), reference (the paper's line or circle, the Player's
uploaded CSV). *Simulate* runs :func:`tpm_viz.multibody.control.simulate` in the background worker (off the hub's
lock); the run is then played on the tab's session by a :class:`~.motion.MotionPlayer`: the mechanism follows the
*actual* platform path (drawn at ``p_ref + k (p - p_ref)`` with the error magnified ``k`` times on request), a
translucent ghost platform in the tab's own scope follows the reference. Charts: tracking error (µm) and the
applied forces against the feedforward. The comparison table collects the controllers run on the same setup;
*Why computed torque?* runs all three at once and words the lesson from their numbers.
"""

from __future__ import annotations

import dataclasses
import time

import numpy as np
import viser

from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.runhub import RunHub
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.worker import Worker
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.markup import Html, Markdown, html
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T, say
from tpm_viz.drawing.palette import hex_colour
from tpm_viz.multibody.control import ControlRun, ControlSetup
from tpm_viz.paper.control import ControllerKind, axis_masses, model_with_errors
from tpm_viz.ui.teaching.control.run import (
    PAPER,
    ControlMotion,
    all_three,
    lab_reference,
    lab_setup,
    timed,
    upload_label,
)
from tpm_viz.ui.teaching.control.text import (
    LABELS,
    comparison_html,
    gains_html,
    label_of,
    lesson_html,
    run_html,
    setup_phrase,
)
from tpm_viz.ui.teaching.motion import MotionPlayer, TimeChart
from tpm_viz.ui.teaching.player.tab import SPEEDS, time_quantity
from tpm_viz.ui.teaching.settings import CONTROL_SETTINGS
from tpm_viz.ui.teaching.stage import CONTROL, ControlNodes, bring, front
from tpm_viz.ui.widgets.typed_sliders import TypedSlider, add_sliders
from tpm_viz.ui.worded import TabGui

__all__ = ["CONTROLLERS", "MAGNIFY", "ControlView"]

CONTROLLERS = {label: kind for kind, label in LABELS.items()}
MAGNIFY = {"×1 (true error)": 1.0, "×10": 10.0, "×100": 100.0, "×1000": 1000.0}
LESSON_PAYLOAD = 1.0  # kg, set by the lesson when the payload slider is at zero
CHART_HZ = 4.0


def _failure(exc: BaseException) -> Phrase:
    """What to tell about a failed simulation: the refusal's words, or that a bug was logged."""
    if isinstance(exc, TpmVizError):
        return reason(exc)
    return Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__)


def _internal_error(owner, exc: Exception) -> None:
    owner.view.refuse(_failure(exc), resync=False)


class ControlView:
    """Control-lab widgets, scene nodes and runs of one tab."""

    def __init__(self, view, worker: Worker, runs: RunHub) -> None:
        self.view = view
        self.worker = worker
        self.runs = runs
        self.player = MotionPlayer(view, "control", on_stop=self._refresh_status)
        self.run: ControlRun | None = None
        self.seconds: float | None = None
        self.busy: str | Phrase = ""
        self.status: str | Phrase = ""
        self._lesson: tuple[float, float] | None = None
        """The payload [kg] and mass error of the last lesson run (to word it again in another language)."""
        self.table: dict[ControllerKind, ControlRun] = {}
        self._table_key: tuple | None = None
        self.charts: tuple[TimeChart, ...] = ()  # built with the tab
        self.nodes = ControlNodes(view.client.scene)
        self._last_push = 0.0
        self._request = 0

    def build(self, gui: TabGui) -> None:
        """The *Control* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            Markdown(
                "Track a reference with a controller on the multibody plant (Pinocchio). The green ghost is the "
                "reference, the mechanism the actual platform; magnify the error to see it. Playback moves the "
                "mechanism you are on (shared with the class unless you work on your own copy)."
            )
        )
        self.controller = gui.add_dropdown("Controller", tuple(CONTROLLERS), initial_value=LABELS[ControllerKind.CTC])
        self.typed: dict[
            str, TypedSlider
        ] = {}  # each slider with a typed number beside it (ui/widgets/typed_sliders.py)
        self.wn, self.zeta = add_sliders(self.view, CONTROL_SETTINGS, ("wn", "zeta"), self._show_gains, self.typed)
        self.gains = gui.add_html("")
        with gui.add_folder("Mismatch and limits"):
            limits = ("payload", "mass_error", "force_limit", "rate", "noise")
            self.payload, self.mass_error, self.force_limit, self.rate, self.noise = add_sliders(
                self.view, CONTROL_SETTINGS, limits, self._show_gains, self.typed
            )
        self.reference = gui.add_dropdown("Reference", tuple(PAPER), initial_value="line (Fig. 4)")
        self.simulate = gui.add_button("Simulate", icon=viser.Icon.PLAYER_TRACK_NEXT)
        self.lesson = gui.add_button("Why computed torque? (run all three)", icon=viser.Icon.SCHOOL, color="teal")
        self.summary = gui.add_html(run_html(None, None))
        self.controls = gui.add_button_group("Playback", ("Play", "Pause", "To start"))
        self.time_typed = TypedSlider(self.view, "Time t (s)", time_quantity(0.2), 0.001, 0.0, self._typed_time)
        self.time = self.time_typed.slider
        self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.05×")
        self.magnify = gui.add_dropdown("Magnify the error", tuple(MAGNIFY), initial_value="×1 (true error)")
        self.error_chart = TimeChart(
            gui,
            "Tracking error e = p_ref − p",
            "error (µm)",
            (("e₁", hex_colour("tau1"), None), ("e₂", hex_colour("tau2"), None), ("|e|", "#0f172a", (4.0, 3.0))),
        )
        self.force_chart = TimeChart(
            gui,
            "Actuator forces: applied (solid) vs feedforward (dashed)",
            "force (N)",
            (
                ("τ₁", hex_colour("tau1"), None),
                ("τ₂", hex_colour("tau2"), None),
                ("τ₁ ff", "#93c5fd", (4.0, 3.0)),
                ("τ₂ ff", "#fca5a5", (4.0, 3.0)),
            ),
        )
        self.charts = (self.error_chart, self.force_chart)
        self.table_html = gui.add_html("")
        self.lesson_text = gui.add_html("")
        self._show_gains()
        for handle in (self.controller, self.wn, self.zeta, self.mass_error):
            handle.on_update(self._on_gains)
        self.simulate.on_click(self._on_simulate)
        self.lesson.on_click(self._on_lesson)
        self.controls.on_click(self._on_controls)
        self.time.on_update(self._on_time)
        self.magnify.on_update(self._on_magnify)

    # -- reading the widgets -------------------------------------------------------------------------------
    def _kind(self) -> ControllerKind:
        if self.controller.value not in CONTROLLERS:
            raise InputError(Phrase("unknown controller {name}", name=repr(self.controller.value)))
        return CONTROLLERS[self.controller.value]

    def _setup(self, kind: ControllerKind | None = None) -> ControlSetup:
        kind = self._kind() if kind is None else kind
        w = (self.wn, self.zeta, self.payload, self.mass_error, self.force_limit, self.rate, self.noise)
        return lab_setup(kind, *(h.value for h in w))

    def _user(self, event, fn, *args) -> None:
        """Run ``fn`` for a user event (not a server echo); a refusal is told to this tab only."""
        if getattr(event, "client", None) is None or self.view.closed:
            return
        bring(self.view, CONTROL, redraw=True)
        try:
            fn(*args)
        except TpmVizError as exc:
            with self.view.hub.locked():
                self.view.refuse(exc, resync=False)

    def _show_gains(self) -> None:
        try:
            setup = self._setup()
            masses = axis_masses(model_with_errors(self.view.session.state.params, *setup.mass_error))
        except (TpmVizError, AttributeError):
            return
        self.gains.content = gains_html(setup.controller, setup.gains, masses, self.view.lang)

    def attach(self) -> None:
        """The tab joined its session: show the gains for its mechanism."""
        with self.view.hub.locked():
            self._show_gains()

    # -- callbacks -----------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_gains(self, event) -> None:
        self._user(event, self._gains_changed)

    def _gains_changed(self) -> None:
        with self.view.hub.locked():
            self._show_gains()
            self.view.client.flush()

    @guarded(on_error=_internal_error)
    def _on_simulate(self, event) -> None:
        self._user(event, self._start, False)

    @guarded(on_error=_internal_error)
    def _on_lesson(self, event) -> None:
        self._user(event, self._start, True)

    def _start(self, lesson: bool) -> None:
        """Read the widgets and simulate in the worker (the lesson: all three controllers, with a payload)."""
        with self.view.hub.locked():
            if lesson and float(self.payload.value) == 0.0:
                self.payload.value = LESSON_PAYLOAD
            setup = self._setup()
            params = self.view.session.state.params
            reference = lab_reference(self.reference.value, self.runs.of(self.view.session).uploaded)
            self._request += 1
            request = self._request
            self.busy = (
                T("Simulating all three controllers…")
                if lesson
                else Phrase("Simulating {controller}…", controller=label_of(setup.controller))
            )
            self._refresh_status()
        if lesson:
            job = lambda: all_three(params, reference, setup)  # noqa: E731
        else:
            job = lambda: {setup.controller: timed(params, reference, setup)}  # noqa: E731
        self.worker.submit(
            "control",
            job,
            lambda result, error: self._done(request, params, setup, lesson, result, error),
            tab=self.view,  # the tab takes turns in the fair queue; its pending run is dropped when it closes
        )

    def _done(self, request: int, params: Params, setup: ControlSetup, lesson: bool, result, error) -> None:
        with self.view.hub.locked():
            if self.view.closed or request != self._request:
                return
            self.busy = ""
            if error is not None:
                self.status = Phrase("Simulation refused: {why}", why=_failure(error))
                self._refresh_status()
                self.view.refuse(_failure(error), resync=False)
                return
            self.status = ""
            key = (
                params,
                next(iter(result.values()))[0].name,
                dataclasses.replace(setup, controller=ControllerKind.PD),
            )
            if key != self._table_key:
                self._table_key, self.table = key, {}
            for kind, (run, _seconds) in result.items():
                self.table[kind] = run
            run, seconds = result.get(setup.controller, next(iter(result.values())))
            self._load(params, run, seconds)
            if lesson:
                self._lesson = (setup.payload, setup.mass_error[0])
            self._write_tables()
            try:
                self.player.seek(0.0)
            except TpmVizError as exc:
                self.view.refuse(exc, resync=False)
            self._refresh_status()

    def _write_tables(self) -> None:
        """The comparison table and the lesson's words, in the tab's language (under the lock)."""
        lang = self.view.lang
        if self.run is not None:
            self.table_html.content = comparison_html(self.table, setup_phrase(self.run), lang)
        if self._lesson is not None:
            self.lesson_text.content = lesson_html(self.table, *self._lesson, lang)

    def retell(self) -> None:
        """The tab's language changed: the gains, the run, the table and the lesson again, in it (under the lock)."""
        self._show_gains()
        self._write_tables()
        self._refresh_status()

    def _load(self, params: Params, run: ControlRun, seconds: float) -> None:
        """Make ``run`` the one played and charted (under the lock)."""
        self.run, self.seconds = run, seconds
        self.player.motion = ControlMotion(params, run, MAGNIFY.get(self.magnify.value, 1.0))
        e = run.error * 1e6
        self.error_chart.show(run.t, (e[:, 0], e[:, 1], run.error_norm * 1e6))
        self.force_chart.show(run.t, (run.tau[:, 0], run.tau[:, 1], run.tau_ff[:, 0], run.tau_ff[:, 1]))
        end = max(float(run.t[-1]), 1e-3)
        self.time_typed.limit(0.0, end, max(end / 400.0, 1e-4))
        bring(self.view, CONTROL)
        self._draw_paths()

    def _draw_paths(self) -> None:
        motion = self.player.motion
        if isinstance(motion, ControlMotion):
            self.nodes.draw(motion.params, motion.run.p_ref, motion.shown_path())

    @guarded(on_error=_internal_error)
    def _on_controls(self, event) -> None:
        self._user(event, self._control, self.controls.value)

    def _control(self, what: str) -> None:
        if what == "Play":
            self.player.play(SPEEDS.get(self.speed.value, 0.05))
        elif what == "Pause":
            self.player.pause()
        elif what == "To start":
            self.player.seek(0.0)
        with self.view.hub.locked():
            self._refresh_status()

    @guarded(on_error=_internal_error)
    def _on_time(self, event) -> None:
        self._user(event, self._seek)

    def _seek(self) -> None:
        with self.view.hub.locked():
            t = self.player.at(self.view.session.state)
            if t is not None and abs(t - float(self.time.value)) < 1e-9:
                return  # the echo of a value written by playback
            self.player.seek(float(self.time.value))

    def opened(self) -> None:
        """The page shows the Control tab (under the hub's lock): its run's paths and ghost in front."""
        bring(self.view, CONTROL, redraw=True)

    def _typed_time(self) -> None:
        """A typed time, settled and written into the slider (under the hub's lock): the run at that time."""
        bring(self.view, CONTROL)
        self.player.seek(float(self.time.value))

    @guarded(on_error=_internal_error)
    def _on_magnify(self, event) -> None:
        self._user(event, self._magnified)

    def _magnified(self) -> None:
        with self.view.hub.locked():
            motion = self.player.motion
            if not isinstance(motion, ControlMotion):
                return
            motion.magnify = MAGNIFY.get(self.magnify.value, 1.0)
            self._draw_paths()
            t = self.player.at(self.view.session.state)
            if t is not None and not self.player.playing:
                self.player.seek(t)
            self.view.client.flush()

    def _discard(self) -> None:
        """The mechanism's parameters changed: the run (computed for the old ones) is dropped, and the summary says
        so in one line (under the lock)."""
        self.run, self.seconds, self._lesson = None, None, None
        self.player.stop()
        self.status = T("The parameters changed: the control run was discarded; press Simulate again.")
        for chart in self.charts:
            chart.hide()
        self.nodes.hide()
        self.summary.content = run_html(None, None, self.busy, self.status, self.view.lang)

    # -- drawing -------------------------------------------------------------------------------------------
    def _refresh_status(self) -> None:
        if self.view.closed:
            return
        lang = self.view.lang
        self.summary.content = run_html(self.run, self.seconds, self.busy, self.status, lang) + (
            html("<div style='font-size:0.85em;color:#334155'>{text}</div>", text=say(lang, T("playing…")))
            if self.player.playing
            else Html("")
        )
        self.view.client.flush()

    def render(self, frame: Snapshot) -> None:
        """Draw the control tab's part of ``frame`` (under the hub's lock): ghost, chart markers, time slider."""
        session = self.view.session
        uploaded = self.runs.of(session).uploaded
        options = (*PAPER, upload_label(uploaded)) if uploaded is not None else tuple(PAPER)
        if tuple(self.reference.options) != options:
            self.reference.options = options
        if self.run is not None and frame.state.params != self.player.motion_params:
            self._discard()
        t = self.player.at(frame.state)
        motion = self.player.motion
        ghost_at = motion.reference_at(t) if t is not None and isinstance(motion, ControlMotion) else None
        self.nodes.place(self.run is not None and front(self.view) == CONTROL, ghost_at)
        now = time.monotonic()
        if frame.in_drag and now - self._last_push < 1.0 / CHART_HZ:
            return
        self._last_push = now
        self.error_chart.mark(t)
        self.force_chart.mark(t)
        if t is not None and abs(float(self.time.value) - t) > 1e-9:
            self.time_typed.follow(float(np.clip(round(t, 4), 0.0, self.time.max)))
