"""The *Planner* tab of one browser tab: the time-optimal cycle of a path within the motors' limits.

Widgets: path (pick-and-place, the paper's line or circle, waypoints typed as ``x,y; x,y`` in mm or added by
Shift+clicking the floor, viser's scene click events), force limit and
speed limit sliders. Every change re-plans in the planner's own background worker (off the hub's lock; a newer
request replaces a queued one: latest value wins) and the cycle time and cycles per minute update live. The plan
plays on the tab's session (:class:`~.motion.MotionPlayer`) with force bars over the sliders scaled to the limit
(red at the limit), a chart of τ against ±F_max, the sizing table beside the paper's cubic law scaled to the same
peak force, and other robots' catalogue figures for orientation.
"""

from __future__ import annotations

import time

import numpy as np
import viser

from tpm_viz.app.planning import PATH_KINDS, PlanResult, solve
from tpm_viz.app.readouts import reason
from tpm_viz.classroom.guard import guarded
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.classroom.worker import Worker
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.markup import Markdown
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.drawing import meshes
from tpm_viz.drawing.palette import hex_colour
from tpm_viz.ui.teaching.motion import MotionPlayer, TimeChart
from tpm_viz.ui.teaching.planner.text import industry_html, result_html, sizing_html
from tpm_viz.ui.teaching.player.tab import SPEEDS
from tpm_viz.ui.teaching.player.trace import TRACE_Z, segments
from tpm_viz.ui.teaching.settings import PLANNER_SETTINGS
from tpm_viz.ui.teaching.stage import PLAN, bring, front, show
from tpm_viz.ui.widgets.typed_sliders import TypedSlider, add_sliders
from tpm_viz.ui.worded import TabGui

__all__ = ["BAR_HEIGHT", "PlanMotion", "PlannerView", "bar_segments", "floor_point"]

BAR_HEIGHT = 0.12  # m, a force bar at the limit
BAR_Z = meshes.SLIDER_Z[1] + 0.01
PATH_COLOUR = (124, 58, 237)
BAR_COLOURS = {"push": (37, 99, 235), "pull": (234, 88, 12), "limit": (220, 38, 38)}
DEFAULT_WAYPOINTS = "-60,-40; 0,40; 60,-40"
CHART_HZ = 4.0


def _internal_error(owner, exc: Exception) -> None:
    owner.view.refuse(Phrase("internal error ({kind}), logged on the server", kind=type(exc).__name__), resync=False)


def bar_segments(params: Params, d, tau, limit: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Force bars over the two sliders at ``d`` [m]: ``(bars, colours, limit ticks)`` as ``(2, 2, 3)`` segments,
    a bar ``BAR_HEIGHT |τ_i| / limit`` tall (blue pushing, orange pulling, red at the limit)."""
    bars = np.zeros((2, 2, 3), dtype=np.float32)
    ticks = np.zeros((2, 2, 3), dtype=np.float32)
    colours = np.zeros((2, 2, 3), dtype=np.uint8)
    for i in range(2):
        base = np.zeros(3)
        base[i] = -params.a + float(d[i])
        base[2] = BAR_Z
        ratio = min(abs(float(tau[i])) / limit, 1.0) if limit > 0 else 0.0
        bars[i, 0], bars[i, 1] = base, base + np.array([0.0, 0.0, BAR_HEIGHT * max(ratio, 0.01)])
        across = np.zeros(3)
        across[1 - i] = 0.02
        top = base + np.array([0.0, 0.0, BAR_HEIGHT])
        ticks[i, 0], ticks[i, 1] = top - across, top + across
        key = "limit" if ratio >= 0.99 else ("push" if float(tau[i]) >= 0 else "pull")
        colours[i] = BAR_COLOURS[key]
    return bars, colours, ticks


def floor_point(origin, direction) -> tuple[float, float] | None:
    """Where the ray ``origin + s direction`` (``s > 0``) meets the floor ``z = 0`` [m], or None."""
    try:
        o, d = np.asarray(origin, dtype=float), np.asarray(direction, dtype=float)
    except (TypeError, ValueError):
        return None
    if o.shape != (3,) or d.shape != (3,) or not (np.all(np.isfinite(o)) and np.all(np.isfinite(d))) or d[2] >= 0:
        return None
    s = -o[2] / d[2]
    if s <= 0:
        return None
    return float(o[0] + s * d[0]), float(o[1] + s * d[1])


class PlanMotion:
    """A plan as a playable motion."""

    def __init__(self, params: Params, result: PlanResult) -> None:
        self.params = params
        self.result = result
        self.duration = result.plan.duration

    def state_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        s = self.result.plan.sample([t])
        return s.p[0], s.dp[0], s.ddp[0]

    def forces_at(self, t: float) -> np.ndarray:
        return self.result.plan.sample([t]).tau[0]


class PlannerView:
    """Planner widgets, scene nodes and plans of one tab."""

    def __init__(self, view, worker: Worker) -> None:
        self.view = view
        self.worker = worker
        self.player = MotionPlayer(view, "plan", on_stop=self._flush)
        self.result: PlanResult | None = None
        self.error: str | Phrase = ""
        self._request = 0
        self._shown = 0
        self._planned_for: Params | None = None
        self._path: viser.LineSegmentsHandle | None = None
        self._bars: viser.LineSegmentsHandle | None = None
        self._ticks: viser.LineSegmentsHandle | None = None
        self._last_push = 0.0
        self.charts: tuple[TimeChart, ...] = ()  # built with the tab

    def build(self, gui: TabGui) -> None:
        """The *Planner* tab's widgets (inside the tab's context)."""
        gui.add_markdown(
            Markdown(
                "The fastest cycle the motors allow: the platform runs the path there and back (the circle: one turn), "
                "one actuator at its force limit almost all the time (toppra). Move a limit: the cycle time follows."
            )
        )
        self.path = gui.add_dropdown("Path", tuple(PATH_KINDS), initial_value="pick-and-place")
        self.waypoints = gui.add_text(
            "Waypoints x,y; x,y (mm)",
            DEFAULT_WAYPOINTS,
            visible=False,
            hint="Or Shift+click points on the floor; Clear starts a new list",
        )
        self.clear = gui.add_button("Clear waypoints", color="gray", visible=False)
        self.typed: dict[
            str, TypedSlider
        ] = {}  # each slider with a typed number beside it (ui/widgets/typed_sliders.py)
        self.force, self.speed = add_sliders(self.view, PLANNER_SETTINGS, ("force", "speed"), self.request, self.typed)
        self.result_html = gui.add_html(result_html(None, 200.0, None, False, lang=self.view.lang))
        self.controls = gui.add_button_group("Playback", ("Play", "Pause", "To start"))
        self.play_speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="0.1×")
        self.loop = gui.add_checkbox("Loop", True)
        self.chart = TimeChart(
            gui,
            "Actuator forces τ against ±F_max",
            "force (N)",
            (
                ("τ₁", hex_colour("tau1"), None),
                ("τ₂", hex_colour("tau2"), None),
                ("+F_max", "#64748b", (6.0, 4.0)),
                ("−F_max", "#64748b", (6.0, 4.0)),
            ),
        )
        self.charts = (self.chart,)
        self.sizing = gui.add_html("")
        self.industry = gui.add_html(industry_html())
        for handle in (self.path, self.waypoints, self.force, self.speed):
            handle.on_update(self._on_limits)
        self.controls.on_click(self._on_controls)
        self.clear.on_click(self._on_clear)
        self.view.client.scene.on_click(modifier="shift")(self._on_floor_click)

    # -- planning ------------------------------------------------------------------------------------------
    def _user(self, event, fn, *args) -> None:
        if getattr(event, "client", None) is None or self.view.closed:
            return
        bring(self.view, PLAN, redraw=True)
        try:
            fn(*args)
        except TpmVizError as exc:
            with self.view.hub.locked():
                self.view.refuse(exc, resync=False)

    @guarded(on_error=_internal_error)
    def _on_limits(self, event) -> None:
        self._user(event, self.request)

    def request(self) -> None:
        """Re-plan for the widgets' current values in the worker (latest value wins)."""
        kind = PATH_KINDS.get(self.path.value, "pick")
        self.waypoints.visible = self.clear.visible = kind == "waypoints"
        force, speed = float(self.force.value), float(self.speed.value)
        text = str(self.waypoints.value)
        with self.view.hub.locked():
            params = self._planned_for = self.view.session.state.params
            self._request += 1
            request = self._request
        self.worker.submit(
            "plan",
            lambda: solve(params, kind, force, speed if speed > 0 else None, text),
            lambda result, error: self._done(request, params, result, error),
            tab=self.view,  # the tab takes turns in the fair queue (latest wins per tab)
        )

    def _done(self, request: int, params: Params, result, error) -> None:
        with self.view.hub.locked():
            if self.view.closed or request < self._shown:
                return
            self._shown = request
            latest = request == self._request
            if error is not None:
                self.error = (
                    Phrase("No plan: {why}", why=reason(error))
                    if isinstance(error, TpmVizError)
                    else T("No plan: internal error")
                )
                self.result_html.content = result_html(None, 0.0, None, not latest, self.error, self.view.lang)
                self.view.client.flush()
                return
            self.error = ""
            self.result = result
            self.result_html.content = result_html(result, 0.0, None, not latest, lang=self.view.lang)
            if latest:
                self._load(params, result)
            self.view.client.flush()

    def _load(self, params: Params, result: PlanResult) -> None:
        """Make ``result`` the plan charted, tabled and played (under the lock)."""
        was_playing = self.player.playing
        self.player.motion = PlanMotion(params, result)
        s, limit = result.samples, result.plan.limits.force
        ones = np.ones_like(s.t)
        self.chart.show(s.t, (s.tau[:, 0], s.tau[:, 1], limit * ones, -limit * ones))
        self.sizing.content = sizing_html(result, self.view.lang)
        self._path = self.view.client.scene.add_line_segments(
            "/planner/path", segments(s.p, TRACE_Z, 400), PATH_COLOUR, thickness=2.5, thickness_units="screen"
        )
        show(self._path, front(self.view, PLAN) == PLAN)
        if not was_playing and "planner" in getattr(self.view.teaching, "open_tabs", ()):
            try:  # the Planner is open: its plan, not another run, on the mechanism
                self._replace_other_run()
            except TpmVizError:
                pass  # a student on the shared mechanism: the path is shown, the mechanism is the lecturer's
        if was_playing:
            try:
                self.player.play(SPEEDS.get(self.play_speed.value, 0.1), bool(self.loop.value))
            except TpmVizError:
                pass  # e.g. presenter mode: the new plan is shown, not played

    @guarded(on_error=_internal_error)
    def _on_clear(self, event) -> None:
        self._user(event, self._set_waypoints, "")

    @guarded(on_error=_internal_error)
    def _on_floor_click(self, event) -> None:
        """Shift+click: the ray hits the floor (z = 0) at a new waypoint (rounded to 1 mm)."""
        point = floor_point(event.ray_origin, event.ray_direction)
        if point is None:
            self._user(event, self._refuse_click)
            return
        self._user(event, self._add_waypoint, f"{point[0] * 1e3:.0f},{point[1] * 1e3:.0f}")

    def _add_waypoint(self, item: str) -> None:
        """Append ``item`` (``x,y`` in mm) to the list, read and written in one locked step: clicks that arrive
        together each add their point."""
        with self.view.hub.locked():
            text = str(self.waypoints.value).strip() if self.path.value == "waypoints" else ""
            self._set_waypoints(f"{text}; {item}" if text else item)

    def _refuse_click(self) -> None:
        raise InputError(Phrase("Shift+click on the floor to add a waypoint"))

    def _set_waypoints(self, text: str) -> None:
        with self.view.hub.locked():
            self.path.value = "waypoints"
            self.waypoints.value = text
        self.request()

    def opened(self) -> None:
        """The page shows the Planner tab (under the hub's lock): its path in front, and, when the mechanism shows
        another run (the Control lab's, the Player's: their dynamic load), the plan's start and its forces instead
        (a pose placed by hand stays). Raises the refusal when this tab may not move the mechanism (a student on the
        shared one): the path is shown all the same."""
        bring(self.view, PLAN, redraw=True)
        self._replace_other_run()

    def _replace_other_run(self) -> None:
        """The plan's start in place of another run's sample on the mechanism (see :meth:`opened`)."""
        motion, state = self.player.motion, self.view.session.state
        if not isinstance(motion, PlanMotion) or motion.params != state.params:
            return
        if state.trajectory.kind != "none" and self.player.at(state) is None:
            self.player.seek(0.0)

    # -- playback ------------------------------------------------------------------------------------------
    @guarded(on_error=_internal_error)
    def _on_controls(self, event) -> None:
        self._user(event, self._control, self.controls.value)

    def _control(self, what: str) -> None:
        if what == "Play":
            self.player.play(SPEEDS.get(self.play_speed.value, 0.1), bool(self.loop.value))
        elif what == "Pause":
            self.player.pause()
        elif what == "To start":
            self.player.seek(0.0)

    def _flush(self) -> None:
        self.view.client.flush()

    # -- drawing -------------------------------------------------------------------------------------------
    def retell(self) -> None:
        """The tab's language changed: the result line and the sizing table again, in it (under the hub's lock)."""
        busy, lang = self._shown < self._request, self.view.lang
        if self.error:
            self.result_html.content = result_html(None, 0.0, None, busy, self.error, lang)
        else:
            self.result_html.content = result_html(self.result, 0.0, None, busy, lang=lang)
        if self.result is not None:
            self.sizing.content = sizing_html(self.result, lang)

    def attach(self) -> None:
        """The tab joined its session: plan the default path for its mechanism."""
        self.request()

    def render(self, frame: Snapshot) -> None:
        """Draw the planner's part of ``frame`` (under the hub's lock): force bars and the chart marker."""
        if self._planned_for is not None and frame.state.params != self._planned_for:
            self.request()  # the mechanism changed: plan again for the new one
        motion = self.player.motion
        t = self.player.at(frame.state)
        show(self._path, front(self.view, PLAN) == PLAN)
        if t is None or not isinstance(motion, PlanMotion):
            for handle in (self._bars, self._ticks):
                if handle is not None and handle.visible:
                    handle.visible = False
            if self.chart.handle.visible and not frame.in_drag:
                self.chart.mark(None)
            return
        limit = motion.result.plan.limits.force
        bars, colours, ticks = bar_segments(frame.state.params, frame.state.pose.d, motion.forces_at(t), limit)
        scene = self.view.client.scene
        if self._bars is None or self._ticks is None:
            self._bars = scene.add_line_segments(
                "/planner/bars", bars, colours, thickness=14.0, thickness_units="screen"
            )
            self._ticks = scene.add_line_segments(
                "/planner/limits", ticks, BAR_COLOURS["limit"], thickness=3.0, thickness_units="screen"
            )
        else:
            self._bars.points, self._bars.colors, self._ticks.points = bars, colours, ticks
            for handle in (self._bars, self._ticks):
                if not handle.visible:
                    handle.visible = True
        now = time.monotonic()
        if not frame.in_drag or now - self._last_push >= 1.0 / CHART_HZ:
            self._last_push = now
            self.chart.mark(t)
