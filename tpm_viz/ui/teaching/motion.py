"""What the *Control* and *Planner* tabs share: a per-tab player that plays a timed platform motion on the tab's
session, and a uPlot time chart with a time marker.

:class:`MotionPlayer` works like :class:`~tpm_viz.classroom.runhub.RunHub` but for one tab's own motion (a control run,
a plan): a thread steps ``t`` at ``speed`` x real time (~30 frames/s) and commits the sampled state through
``Hub.commit`` under the hub's lock (intermediate frames with ``dragging=True``, the last one in full). The state
carries ``TrajectorySample(kind, T, t)``, so a view knows which motion and time a frame shows (its ghost, its force
bars, its chart marker). Any other input to the session bumps ``session.play_token``, which stops it; so does a new
motion. Refusals (presenter mode, a pose that cannot be drawn) raise :class:`~tpm_viz.TpmVizError`.
"""

from __future__ import annotations

import math
import threading
import time
from collections.abc import Callable
from typing import Any, Protocol

import numpy as np

from tpm_viz.app.moves import place
from tpm_viz.app.readouts import Load
from tpm_viz.app.state import AppState, TrajectorySample, run_note
from tpm_viz.classroom.guard import report
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.ui.teaching.player.charts import LARGE, NORMAL, TICK_PX, AxisLook, marker
from tpm_viz.ui.worded import TabGui

__all__ = ["FPS", "Motion", "MotionPlayer", "TimeChart"]

FPS = 30.0
CHART_POINTS = 151
X_LABEL = "time t (s)"
MARKER = "#f59e0b"
RUN_NAMES = {"control": T("the control run"), "plan": T("the planned path")}
"""What the note under the banner calls a player's motion (:func:`~tpm_viz.app.state.run_note`)."""


class Motion(Protocol):
    """A timed platform motion on one mechanism."""

    params: Params
    duration: float

    def state_at(self, t: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """``(p, ṗ, p̈)`` [m, m/s, m/s²] of the platform as drawn at time ``t`` [s] in ``[0, duration]``."""
        ...


class MotionPlayer:
    """Plays one tab's motion on the tab's session; its frames are tagged ``kind#<player id>`` (``control#7f..``)."""

    def __init__(self, view, kind: str, on_stop: Callable[[], None] | None = None) -> None:
        self.view = view
        self.kind = f"{kind}#{id(self):x}"  # this tab's motion only (another tab's run of the same length is not ours)
        self.name = RUN_NAMES.get(kind, kind)
        self.motion: Motion | None = None
        self.playing = False
        self._token = -1
        self._on_stop = on_stop

    @property
    def motion_params(self) -> Params | None:
        """The mechanism the motion was computed for (None: no motion)."""
        return None if self.motion is None else self.motion.params

    def at(self, state: AppState) -> float | None:
        """The time [s] of this player's motion that ``state`` shows, or None (another motion, moved by hand)."""
        motion = self.motion
        sample = state.trajectory
        if motion is None or sample.kind != self.kind or state.params != motion.params:
            return None
        return sample.t if abs(sample.duration - motion.duration) < 1e-12 else None

    def sampled(self, state: AppState, t: float, settled: bool = False) -> AppState:
        """``state`` at time ``t`` of the motion (pose and dynamic load; unchanged with the reason if not valid).
        ``settled``: the platform stays there (paused, scrubbed, at the end): the note says whose load it shows."""
        motion = self.motion
        assert motion is not None
        t = float(np.clip(t, 0.0, motion.duration))
        p, dp, ddp = motion.state_at(t)
        move = place(state.params, state.pose, p)
        dynamic = Load("dynamic", dp=(float(dp[0]), float(dp[1])), ddp=(float(ddp[0]), float(ddp[1])))
        load = state.load if move.clamped else dynamic
        sample = TrajectorySample(self.kind, motion.duration, t)
        note = move.reason or (run_note(self.name, t) if settled else "")
        return state.replace(pose=move.pose, load=load, trajectory=sample, note=note)

    def _usable(self) -> Motion:
        motion = self.motion
        if motion is None:
            raise InputError(Phrase("nothing to play yet: compute it first"))
        if motion.params != self.view.session.state.params:
            raise InputError(Phrase("the mechanism changed since this was computed: compute it again"))
        return motion

    def seek(self, t: float) -> None:
        """Stop playing and show the motion at ``t`` [s] (under the hub's lock)."""
        with self.view.hub.locked():
            session = self.view.session
            self.view.hub.authorize(self.view, session)
            self._usable()
            session.play_token += 1
            self.playing = False
            self.view.hub.commit(session, self.sampled(session.state, t, settled=True), origin=self.view)

    def pause(self) -> None:
        """Stop playing (the last frame is committed again in full)."""
        with self.view.hub.locked():
            session = self.view.session
            t = self.at(session.state)
            self.view.hub.authorize(self.view, session)
            session.play_token += 1
            self.playing = False
            if t is not None:
                self.view.hub.commit(session, self.sampled(session.state, t, settled=True), origin=self.view)

    def stop(self) -> None:
        """Forget the motion (a playing thread ends at its next frame)."""
        self.motion = None
        self.playing = False

    def play(self, speed: float, loop: bool = False) -> None:
        """Play from the current sample (from the start if at the end or off the motion)."""
        with self.view.hub.locked():
            session = self.view.session
            self.view.hub.authorize(self.view, session)
            motion = self._usable()
            t = self.at(session.state)
            t0 = t if t is not None and t < motion.duration - 1e-9 else 0.0
            session.play_token += 1
            self._token = token = session.play_token
            self.playing = True
        args = (session, motion, t0, float(speed), bool(loop), token)
        threading.Thread(target=self._play, args=args, name=f"tpm-viz-{self.kind}", daemon=True).start()

    def _play(self, session, motion: Motion, t0: float, speed: float, loop: bool, token: int) -> None:
        try:
            self._frames(session, motion, t0, speed, loop, token)
        except Exception as exc:  # a bug: logged, the thread ends (not a guarded callback: it lasts a playback)
            report(exc, f"playing the {self.kind} motion")

    def _frames(self, session, motion: Motion, t0: float, speed: float, loop: bool, token: int) -> None:
        hub = self.view.hub
        tick0 = wall0 = time.monotonic()
        k = 0
        try:
            while True:
                t = t0 + speed * (time.monotonic() - wall0)
                with hub.locked():
                    if session.play_token != token or self.motion is not motion or self.view.closed:
                        return
                    if t >= motion.duration and loop:
                        t0, wall0, t = 0.0, time.monotonic(), 0.0
                    elif t >= motion.duration:
                        self.playing = False
                    state = self.sampled(session.state, min(t, motion.duration), settled=not self.playing)
                    if state.note:
                        self.playing = False
                    try:
                        hub.commit(session, state, dragging=self.playing)
                    except TpmVizError:
                        self.playing = False
                        return
                    if not self.playing:
                        return
                k += 1
                time.sleep(max(0.0, tick0 + k / FPS - time.monotonic()))
        finally:
            with hub.locked():
                if self._token == token:
                    self.playing = False
                    if self._on_stop is not None and not self.view.closed:
                        self._on_stop()


def _series(label: str, colour: str, dash: tuple[float, float] | None = None, scale: str | None = None) -> Any:
    s: dict[str, Any] = {"label": label, "stroke": colour, "width": 2.0, "points": {"show": False}}
    if dash is not None:
        s["dash"] = dash
    if scale is not None:
        s["scale"] = scale
    return s


def _axes(y_label: str, look: AxisLook) -> tuple[Any, ...]:
    """The time and value axes of a :class:`TimeChart` in ``look`` (the normal look: uPlot's own, sizes only)."""
    if look == NORMAL:
        return {"label": X_LABEL, "size": 40}, {"label": y_label, "size": 62}
    grow = look.px / NORMAL.px
    extra: dict[str, Any] = {"labelSize": look.label, **look.style()}
    if look.colour is not None:
        extra["ticks"] = {"size": TICK_PX, "stroke": look.colour, "width": look.tick_width}  # all of it, or none
    x = {"label": X_LABEL, "size": 40 + look.x_axis - NORMAL.x_axis, **extra}
    return x, {"label": y_label, "size": math.ceil(62 * grow), **extra}


def _padding(look: AxisLook) -> tuple[int, int, int, int]:
    """uPlot's padding of a :class:`TimeChart`: room above the top tick and past the last time label."""
    return (look.px, math.ceil(1.5 * look.px), 0, 0)


class TimeChart:
    """One uPlot chart of series against time, with a time marker; built once, hidden until it has data.

    ``lines``: ``(label, colour, dash or None)`` per series. Values never contain NaN or infinity (checked).
    """

    def __init__(self, gui: TabGui, title: str, y_label: str, lines, height: int = 200) -> None:
        self.lines = tuple(lines)
        self.y_label, self.height, self.look = y_label, height, NORMAL
        n = 2
        zero = np.zeros(n)
        series = [{"label": X_LABEL}, *(_series(*line) for line in self.lines), _series("now", MARKER, None, "c")]
        self.handle = gui.add_uplot(
            (np.linspace(0.0, 1.0, n), *(zero for _ in self.lines), marker(n, None)),
            tuple(series),
            title=title,
            scales={"x": {"time": False}, "c": {"range": (0.0, 1.0)}},
            axes=_axes(y_label, NORMAL),
            legend={"live": False},
            cursor={"points": {"show": False}},
            height=height,
            padding=_padding(NORMAL),
            visible=False,
        )
        self._base: tuple[np.ndarray, ...] | None = None

    def show(self, t: np.ndarray, columns) -> None:
        """Plot ``columns`` (each ``(n,)``, already in display units) against ``t`` [s], decimated; no marker."""
        t = np.asarray(t, dtype=float)
        cols = [np.asarray(c, dtype=float) for c in columns]
        if len(cols) != len(self.lines) or not all(np.all(np.isfinite(a)) for a in (t, *cols)):
            self.hide()
            return
        n = len(t)
        step = max(1, int(np.ceil((n - 1) / (CHART_POINTS - 1))))
        i = np.unique(np.r_[np.arange(0, n, step), n - 1])
        self._base = (t[i], *(c[i] for c in cols))
        self.mark(None)
        self.handle.visible = True

    def set_presentation(self, on: bool) -> None:
        """Axes large and dark in presentation mode (:data:`~.charts.LARGE`: 18 px, near-black, like the player's
        charts), as uPlot draws them otherwise; the chart grows by the room the larger axes take."""
        look = LARGE if on else NORMAL
        if look == self.look:
            return
        self.look = look
        self.handle.axes = _axes(self.y_label, look)
        self.handle.padding = _padding(look)
        self.handle.height = self.height + (look.x_axis - NORMAL.x_axis) + (look.label - NORMAL.label)

    def hide(self) -> None:
        self._base = None
        if self.handle.visible:
            self.handle.visible = False

    def mark(self, t: float | None) -> None:
        """Move the marker to the sample nearest ``t`` [s] (None: no marker)."""
        base = self._base
        if base is None:
            return
        k = None if t is None else int(np.argmin(np.abs(base[0] - t)))
        self.handle.data = (*base, marker(len(base[0]), k))
