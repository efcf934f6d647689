"""The player's uPlot charts: actuator forces (paper solid, Pinocchio dotted, like Figs. 4-5) and the actuator
positions, velocities and accelerations vs time, each with a vertical marker at the current time.

uPlot takes one array per series on a shared x axis, and nothing but numbers and text (no JS callbacks) crosses
the wire, so:

- the time marker is a series of its own on a hidden scale ``c`` fixed to ``[0, 1]``: ``-1`` (off the chart)
  everywhere except ``+1`` at the current sample, a spike that draws as a vertical line across the chart;
- both axes are decided here, once per run (:func:`axes_for`, maths in :mod:`tpm_viz.ui.widgets.chart_axes`): fixed
  ranges, the tick positions and their labels (uPlot's static ``splits`` and ``values``), so the time axis always
  has its ticks whatever the duration, no label reads ``-0``, and the y axis is as wide as its widest label. The
  server does not know how wide the browser draws a chart, so the four charts share one time axis whose labels
  stay apart on the narrowest chart (:data:`NARROWEST_PX`, a small phone): fewer time ticks on a wide screen, never
  touching labels on a narrow one. A chart is tall enough for its rotated y label in every language
  (:func:`chart_height`). Drag-to-zoom is off (the ticks are fixed to the run's range).
- the axes are drawn in one of two :class:`AxisLook` s: :data:`NORMAL` (uPlot's 12 px in viser's grey) or
  :data:`LARGE` for presentation mode (:meth:`Charts.set_presentation`, from :mod:`tpm_viz.ui.look`: 18 px in
  near-black, thicker ticks); every size above (axis heights and widths, label room, padding, tick spacing)
  follows the font size, so the larger labels and titles are not cut either.

No NaN is ever sent. Charts are built once per tab; a new run replaces their axes and data; the marker moves by
re-sending the (decimated, <= :data:`CHART_POINTS` points) data, which the caller throttles during playback.
Titles and axis labels are :class:`~tpm_viz.core.words.Phrase` s rendered in ``lang`` (English by default: the tab's
connection shows the English texts in the tab's language, :mod:`tpm_viz.ui.language`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from tpm_viz.app.runs import Run
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.drawing.palette import hex_colour
from tpm_viz.ui.widgets.chart_axes import Ticks, text_width, time_ticks, value_ticks
from tpm_viz.ui.worded import TabGui

__all__ = ["CHART_POINTS", "LARGE", "NORMAL", "AxisLook", "Charts", "axes_for", "chart_height", "marker"]
__all__ += ["plot_room", "y_axis"]

CHART_POINTS = 151
FONT_PX = 12  # uPlot's axis font: 12 px (bold for the axis labels)
TICK_PX, GAP_PX = 10, 5  # uPlot's tick length and the gap between tick and label [px]
FONTS = '"Segoe UI", Roboto, "Helvetica Neue", Arial, "Noto Sans", "NanumGothic", sans-serif'
"""The font families of the large axes (uPlot's own default list, with a Korean font before the generic one)."""


@dataclass(frozen=True)
class AxisLook:
    """How the axes of a chart are drawn: the font size of tick labels and axis titles [CSS px] (titles bold) and
    the colour of text and ticks (None: uPlot's font and viser's theme grey, nothing sent). Every size of an axis
    follows the font size (:attr:`x_axis`, :attr:`label`, :attr:`padding`)."""

    px: int = FONT_PX
    colour: str | None = None
    tick_width: float = 1.0  # [px]

    @property
    def x_axis(self) -> int:
        """Height of the time axis [px]: tick, gap, one line of labels and their descenders (34 at 12 px)."""
        return TICK_PX + GAP_PX + math.ceil(self.px * 19 / 12)

    @property
    def label(self) -> int:
        """Room of an axis title [px]: one line of bold text and its gap (24 at 12 px)."""
        return 2 * self.px

    @property
    def padding(self) -> tuple[int, int, int, int]:
        """uPlot's padding [px]: top, half a y label above the top tick; right, half a time label past the end."""
        return (self.px, 2 * self.px, 0, 0)

    def style(self) -> dict[str, Any]:
        """The uPlot axis options of this look (none for the normal look: uPlot's and viser's defaults)."""
        if self.colour is None:
            return {}
        return {
            "font": f"{self.px}px {FONTS}",
            "labelFont": f"bold {self.px}px {FONTS}",
            "stroke": self.colour,
        }


NORMAL = AxisLook()
"""The charts' axes as uPlot and viser draw them: 12 px, grey."""
LARGE = AxisLook(18, "#0f172a", 2.0)
"""The charts' axes in presentation mode: 18 px (>= 16 px, read on a 1024 x 768 projector), near-black (the colour of
the presentation mode's labels), ticks 2 px wide."""
X_AXIS_PX = NORMAL.x_axis  # height of the time axis: tick, gap, one line of labels, descenders
LABEL_PX = NORMAL.label  # room of an axis label (one line of bold 12 px text and its gap)
PADDING = NORMAL.padding  # top: half a y label above the top tick; right: half a time label past the end
NARROWEST_PX = 303
"""[CSS px] The narrowest chart the time labels must fit: the full-width phone sheet (:mod:`tpm_viz.ui.look`) of a
320 px wide phone, measured in Chromium (390 px: 373; the docked panel: 365). A wider chart has room to spare."""
X_LABEL = T("time t (s)")
FORCE_COLOURS = (hex_colour("tau1"), hex_colour("tau2"))  # τ1, τ2 as in the PNG figures (blue, red)
LEG_COLOURS = (hex_colour("leg1"), hex_colour("leg2"))  # leg 1 teal, leg 2 indigo as in the 3D view
MARKER = hex_colour("inverse")
FORCES = (T("Actuator forces τ (paper solid, Pinocchio dotted)"), T("force (N)"), 240)
KINEMATICS = (  # attribute of Run, title, y-axis label, scale SI -> UI
    ("d", T("Actuator positions d₁, d₂ (eq. 4)"), T("d (mm)"), 1e3),
    ("dd", T("Actuator velocities (eq. 9)"), T("ḋ (mm/s)"), 1e3),
    ("ddd", T("Actuator accelerations (eq. 14)"), T("d̈ (mm/s²)"), 1e3),
)
KINEMATICS_HEIGHT = 170
RESOLUTION = 1e-9  # display units (N, mm, mm/s, mm/s²): a series flatter than this is drawn as a flat line


def marker(n: int, k: int | None) -> np.ndarray:
    """The time-marker series: ``-1`` everywhere (off the ``[0, 1]`` scale), ``+1`` at sample ``k``."""
    out = np.full(n, -1.0)
    if k is not None and 0 <= k < n:
        out[k] = 1.0
    return out


def chart_height(y_label: Phrase, least: int, look: AxisLook = NORMAL) -> int:
    """Height [px] of a chart whose plot area is at least as tall as ``y_label`` (bold, rotated along the y axis)
    in every language, and at least ``least``."""
    longest = max(text_width(say(lang, y_label), look.px, bold=True) for lang in Lang)
    return max(int(least), math.ceil(look.padding[0] + look.x_axis + look.label + longest + look.px))


def _axis(ticks: Ticks, label: str, size: float, look: AxisLook) -> dict[str, Any]:
    tick: dict[str, Any] = {"size": TICK_PX}
    if look.colour is not None:
        tick.update(stroke=look.colour, width=look.tick_width)
    return {
        "label": label,
        "size": math.ceil(size),
        "labelSize": look.label,
        "splits": ticks.values,
        "values": ticks.labels,
        "gap": GAP_PX,
        "ticks": tick,
        **look.style(),
    }


def y_axis(values, look: AxisLook = NORMAL) -> tuple[Ticks, int]:
    """The ticks of a value axis around ``values`` (display units, any shape) and its width [px]: tick, gap and
    the widest label (:func:`~tpm_viz.ui.widgets.chart_axes.text_width`, an upper bound) with a third of an em to
    spare."""
    y = value_ticks(values, most=5, resolution=RESOLUTION)
    widest = max(text_width(s, look.px) for s in y.labels)
    return y, math.ceil(TICK_PX + GAP_PX + widest + look.px / 3)


def plot_room(y_size: float, look: AxisLook = NORMAL) -> float:
    """Width [px] of the plot area of a chart whose y axis is ``y_size`` px wide, on the narrowest chart."""
    return NARROWEST_PX - look.padding[1] - look.label - y_size


def axes_for(
    t, values, y_label: str, x_label: str, room: float | None = None, look: AxisLook = NORMAL
) -> tuple[dict[str, Any], tuple[dict[str, Any], ...]]:
    """uPlot ``scales`` and ``axes`` for series ``values`` (display units, any shape) against ``t`` [s], drawn in
    ``look``: the time axis spans ``[t[0], t[-1]]``, the y axis the ticks around the values; every tick labelled,
    no label wider than its axis, time labels apart on a plot ``room`` px wide (default: this chart's on the
    narrowest chart, :func:`plot_room`)."""
    t = np.asarray(t, dtype=float)
    y, y_size = y_axis(values, look)
    room = plot_room(y_size, look) if room is None else room
    t0, t1 = (t[0], t[-1]) if len(t) else (0.0, 1.0)
    x = time_ticks(t0, t1, room=room, gap=look.px, px=look.px)
    scales = {"x": {"time": False, "range": (x.lo, x.hi)}, "y": {"range": (y.lo, y.hi)}, "c": {"range": (0.0, 1.0)}}
    return scales, (_axis(x, x_label, look.x_axis, look), _axis(y, y_label, y_size, look))


def _series(label: str, colour: str, width: float = 2.0, dash=None) -> Any:
    s = {"label": label, "stroke": colour, "width": width, "points": {"show": False}}
    if dash is not None:
        s["dash"] = dash
    return s


def _marker_series(lang: Lang) -> Any:
    return {"label": say(lang, T("now")), "stroke": MARKER, "width": 2.0, "scale": "c", "points": {"show": False}}


def _options(y_label: Phrase, least: int, lang: Lang) -> dict:
    x_label, y_text = say(lang, X_LABEL), say(lang, y_label)
    scales, axes = axes_for(np.array([0.0, 1.0]), np.zeros(2), y_text, x_label)
    return dict(
        scales=scales,
        axes=axes,
        legend={"live": False},
        cursor={"points": {"show": False}, "drag": {"x": False, "y": False}},
        height=chart_height(y_label, least),
        padding=PADDING,
    )


_PLACEHOLDER = (np.array([0.0, 1.0]), np.zeros(2))  # the axes of a chart before its first run


class Charts:
    """Four uPlot charts in the current GUI container (a tab): forces, ``d``, ``ḋ``, ``d̈``; words in ``lang``."""

    def __init__(self, gui: TabGui, lang: Lang = Lang.EN) -> None:
        n = 2
        x = np.linspace(0.0, 1.0, n)
        zero = np.zeros(n)
        self.lang = lang
        self.look = NORMAL
        self._run: Run | None = None
        self._idx = np.arange(n)
        self._base: list[tuple[np.ndarray, ...]] = []
        x_label = say(lang, X_LABEL)
        self._y_labels = [say(lang, FORCES[1]), *(say(lang, label) for _a, _t, label, _s in KINEMATICS)]
        self._heights = [(FORCES[1], FORCES[2]), *((label, KINEMATICS_HEIGHT) for _a, _t, label, _s in KINEMATICS)]
        self.forces = gui.add_uplot(
            (x, zero, zero, zero, zero, marker(n, None)),
            (
                {"label": x_label},
                _series(say(lang, T("τ₁ paper")), FORCE_COLOURS[0]),
                _series(say(lang, T("τ₂ paper")), FORCE_COLOURS[1]),
                _series(say(lang, T("τ₁ Pinocchio")), "#0f172a", 2.2, (2.0, 4.0)),
                _series(say(lang, T("τ₂ Pinocchio")), "#475569", 2.2, (2.0, 4.0)),
                _marker_series(lang),
            ),
            title=say(lang, FORCES[0]),
            **_options(FORCES[1], FORCES[2], lang),
        )
        self.kinematics = [
            gui.add_uplot(
                (x, zero, zero, marker(n, None)),
                (
                    {"label": x_label},
                    _series(say(lang, T("actuator 1")), LEG_COLOURS[0]),
                    _series(say(lang, T("actuator 2")), LEG_COLOURS[1]),
                    _marker_series(lang),
                ),
                title=say(lang, title),
                **_options(label, KINEMATICS_HEIGHT, lang),
            )
            for _attr, title, label, _scale in KINEMATICS
        ]

    @property
    def handles(self) -> list:
        """Every chart handle (forces first)."""
        return [self.forces, *self.kinematics]

    def show_run(self, run: Run | None, t: float | None) -> None:
        """Plot ``run`` (decimated to <= :data:`CHART_POINTS` samples) with the marker at ``t`` [s] (None: none)."""
        arrays = () if run is None else (run.t, run.tau, run.d, run.dd, run.ddd)
        if run is not None and not all(np.all(np.isfinite(a)) for a in arrays):
            run = None  # never a NaN on the wire (runs are checked, this is a guard)
        if run is not None and run.tau_ref is not None and not np.all(np.isfinite(run.tau_ref)):
            run = None
        self._run = run
        for handle in self.handles:
            handle.visible = run is not None
        if run is None:
            return
        self._plot(run)
        self.show_time(t)

    def set_presentation(self, on: bool) -> None:
        """Draw the axes large and dark (:data:`LARGE`, presentation mode) or as usual (:data:`NORMAL`): the
        ticks, their room, the charts' heights and padding follow; the run and its marker stay."""
        look = LARGE if on else NORMAL
        if look == self.look:
            return
        self.look = look
        for handle, (phrase, least) in zip(self.handles, self._heights, strict=True):
            handle.height = chart_height(phrase, least, look)
            handle.padding = look.padding
        if self._run is None:
            x_label = say(self.lang, X_LABEL)
            for handle, y_label in zip(self.handles, self._y_labels, strict=True):
                handle.scales, handle.axes = axes_for(*_PLACEHOLDER, y_label, x_label, look=look)
        else:
            self._plot(self._run, axes_only=True)

    def _plot(self, run: Run, axes_only: bool = False) -> None:
        """Decimate ``run`` into the charts' series (unless ``axes_only``) and set the axes for them."""
        if not axes_only:
            self._decimate(run)
        x_label = say(self.lang, X_LABEL)
        look = self.look
        shown = [
            base[1:3] if handle is not self.forces or run.tau_ref is None else base[1:]
            for handle, base in zip(self.handles, self._base, strict=True)
        ]
        room = min(plot_room(y_axis(np.concatenate(s), look)[1], look) for s in shown)  # one time axis for all four
        for handle, base, values, y_label in zip(self.handles, self._base, shown, self._y_labels, strict=True):
            handle.scales, handle.axes = axes_for(base[0], np.concatenate(values), y_label, x_label, room, look)
        if axes_only:
            return
        series = list(self.forces.series)
        for k in (3, 4):
            series[k] = {**series[k], "show": run.tau_ref is not None}
        self.forces.series = tuple(series)

    def _decimate(self, run: Run) -> None:
        n = len(run.t)
        step = max(1, int(np.ceil((n - 1) / (CHART_POINTS - 1))))
        self._idx = np.unique(np.r_[np.arange(0, n, step), n - 1])
        i = self._idx
        ref = run.tau_ref if run.tau_ref is not None else run.tau  # hidden when there is no reference
        self._base = [(run.t[i], run.tau[i, 0], run.tau[i, 1], ref[i, 0], ref[i, 1])]
        for attr, _title, _label, scale in KINEMATICS:
            arr = getattr(run, attr)
            self._base.append((run.t[i], arr[i, 0] * scale, arr[i, 1] * scale))

    def show_time(self, t: float | None, forces_only: bool = False) -> None:
        """Move the marker to the sample nearest ``t`` [s] (None hides it), in the force chart only if
        ``forces_only`` (playback alternates, to halve the bytes the three kinematic charts cost)."""
        run = self._run
        if run is None:
            return
        k = None
        if t is not None:
            k = int(np.argmin(np.abs(run.t[self._idx] - t)))
        m = marker(len(self._idx), k)
        for handle, base in zip(self.handles, self._base, strict=True):
            handle.data = (*base, m)
            if forces_only:
                break
