"""Frames of an animated clip of a trajectory run: a top view of the mechanism and a force strip.

One frame per sample of the run (frame ``k`` shows the run at its time ``t[k]``: the frames are the run's times,
never the wall clock, so the same run gives the same frames). Left, the mechanism seen from above as in the
paper's Figs. 1 and 3: rails with the stroke ``0 <= d_i <= Δd``, sliders, both links of each parallelogram, the
platform, the whole path (yellow) and the trace so far (dark), force arrows on the sliders along ``e_i`` (green
``τ_i > 0``, red ``< 0``). Right, the time and both forces as text, two force bars (zero in the middle, a fixed
scale) and the forces over the whole run (eq. 31, closed form) with a marker at the current time.

The frame's pixel geometry of the bars is :class:`BarGeometry` (written to a clip's sidecar), so that a reader of
the decoded frames can measure the drawn forces. Drawn with matplotlib's Agg canvas (no pyplot): the static parts
once, the moving artists over a copy of them (blitting). Takes arrays, computes nothing of the paper's maths.
"""

from __future__ import annotations

import math
from collections.abc import Iterator
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from matplotlib.patches import FancyArrowPatch, Rectangle

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.drawing.labels import name_props, quiet_glyphs
from tpm_viz.drawing.meshes import SLIDER_LENGTH, SLIDER_MARGIN, platform_half_size
from tpm_viz.media.clipopts import (
    DEFAULT_FPS,
    DEFAULT_SIZE,
    MAX_FPS,
    MAX_SIZE,
    MIN_SIZE,
    SIZE_PRESETS,
    check_fps,
    parse_size,
)
from tpm_viz.paper.kinematics import mechanism_pose

__all__ = [
    "BAR_COLOURS",
    "DEFAULT_FPS",
    "DEFAULT_SIZE",
    "MAX_FPS",
    "MAX_FRAMES",
    "MAX_SIZE",
    "MIN_SIZE",
    "SIZE_PRESETS",
    "BarGeometry",
    "ClipRenderer",
    "ClipRun",
    "check_fps",
    "parse_size",
]

MAX_FRAMES = 2001
"""Most frames of a clip (one per run sample)."""
BAR_COLOURS = ((31, 119, 180), (214, 39, 40))
"""Colours (RGB) of the force bars and curves of τ1 and τ2."""
_ARROW = {True: "#16a34a", False: "#dc2626"}
_PATH, _TRACE = "#eab308", "#0f172a"


class ClipRun(Protocol):
    """What a clip needs of a run, e.g. :class:`tpm_viz.app.runs.Run` (SI units)."""

    @property
    def params(self) -> Params: ...
    @property
    def t(self) -> np.ndarray: ...  # (n,) [s]
    @property
    def p(self) -> np.ndarray: ...  # (n, 2) [m]
    @property
    def d(self) -> np.ndarray: ...  # (n, 2) [m], eq. (4)
    @property
    def tau(self) -> np.ndarray: ...  # (n, 2) [N], eq. (31)


@dataclass(frozen=True)
class BarGeometry:
    """Where the force bars are in a frame [px, rows counted from the top]: a bar of force ``τ_i`` [N] covers the
    columns from ``zero_x`` to ``zero_x + τ_i * px_per_newton`` on row ``rows[i]`` (the bar is ``height`` px)."""

    zero_x: float
    px_per_newton: float
    rows: tuple[int, int]
    height: int


def _force_scale(tau: np.ndarray) -> float:
    """Half-width of the bars' scale [N]: the run's peak with 10 % room, rounded up to 1, 2 or 5 x 10^k."""
    peak = max(float(np.max(np.abs(tau))) * 1.1, 1e-3)
    exp = 10.0 ** math.floor(math.log10(peak))
    return next(m * exp for m in (1.0, 2.0, 5.0, 10.0) if m * exp >= peak)


def _signed(value: float) -> str:
    text = fixed(value, ".2f")
    return text if text.startswith("-") else "+" + text


class ClipRenderer:
    """Draws the frames of one run at ``size`` = ``(width, height)`` [px]; ``title`` names the run."""

    def __init__(self, run: ClipRun, title: str, size: tuple[int, int] = DEFAULT_SIZE) -> None:
        n = len(run.t)
        if not 2 <= n <= MAX_FRAMES:
            raise InputError(Phrase("a clip has 2 to {hi} frames (one per run sample), got {n}", hi=MAX_FRAMES, n=n))
        width, height = parse_size(f"{size[0]}x{size[1]}")
        self.run, self.size = run, (width, height)
        self.fig = Figure(figsize=(width / 100.0, height / 100.0), dpi=100)
        self.canvas = FigureCanvasAgg(self.fig)
        self._font = max(6.5, 9.0 * min(width / 800.0, height / 450.0))  # pt
        self.scale = _force_scale(run.tau)
        step = float(np.min(np.diff(run.t))) if n > 1 else 1.0
        self._digits = int(np.clip(math.ceil(-math.log10(max(step, 1e-9))) + 1, 3, 7))  # every frame's time differs
        self._moving: list = []
        self._mechanism(title)
        self._panel()
        with quiet_glyphs():
            self.canvas.draw()  # the static parts (moving artists are animated: not drawn here)
        self._background = self.canvas.copy_from_bbox(self.fig.bbox)

    def __len__(self) -> int:
        return len(self.run.t)

    def _add(self, artist):
        artist.set_animated(True)
        self._moving.append(artist)
        return artist

    # -- the static figure and its moving artists -----------------------------------------------------------
    def _mechanism(self, title: str) -> None:
        params, mm, fs = self.run.params, 1e3, self._font
        ax = self.fig.add_axes((0.07, 0.1, 0.44, 0.8))
        self.top = ax
        half = platform_half_size(params)
        lo, hi = -params.a - SLIDER_LENGTH - 0.03, params.l_a + half + 0.03
        ax.set_xlim(lo * mm, hi * mm)
        ax.set_ylim(lo * mm, hi * mm)
        ax.set_aspect("equal", adjustable="box")
        ax.tick_params(labelsize=fs * 0.8)
        ax.set_xlabel("x [mm]", fontsize=fs * 0.85, labelpad=1)
        ax.set_ylabel("y [mm]", fontsize=fs * 0.85, labelpad=1)
        ax.grid(alpha=0.25)
        self.fig.text(0.01, 0.97, title, fontsize=fs * 1.1, va="top", ha="left", **name_props())  # a name is text
        for i in range(2):
            ends = np.zeros((2, 2))
            ends[:, i] = (-params.a - SLIDER_LENGTH / 2, -params.a + params.stroke + SLIDER_LENGTH / 2)
            ax.plot(*(ends.T * mm), color="0.55", lw=fs * 0.7, solid_capstyle="butt", zorder=1)
            for d in (0.0, params.stroke):  # the stroke ends d_i = 0 and Δd
                stop = np.zeros((2, 2))
                stop[:, i] = -params.a + d
                stop[:, 1 - i] = (-0.026, 0.026)
                ax.plot(*(stop.T * mm), color="0.3", lw=1.2, zorder=1)
        ax.plot(*(self.run.p.T * mm), color=_PATH, lw=2.0, zorder=2)
        ax.plot([0], [0], "+", color="0.3", ms=fs)
        ax.text(4, -14, "O", fontsize=fs * 0.8, color="0.3")
        self.trace = self._add(ax.plot([], [], color=_TRACE, lw=1.4, zorder=3)[0])
        self.sliders = [
            self._add(Rectangle((0, 0), 1, 1, fc="#94a3b8", ec="#334155", lw=0.8, zorder=4)) for _ in range(2)
        ]
        self.links = [self._add(ax.plot([], [], color="#475569", lw=fs * 0.45, zorder=5)[0]) for _ in range(4)]
        side = 2 * half * mm
        self.platform = self._add(
            Rectangle((0, 0), side, side, fc="#cbd5e1", ec="#1e293b", lw=1.0, alpha=0.6, zorder=6)
        )
        self.point = self._add(ax.plot([], [], "o", color=_PATH, mec="#1e293b", ms=fs * 0.6, zorder=7)[0])
        self.arrows = [
            self._add(FancyArrowPatch((0, 0), (1, 0), arrowstyle="-|>", mutation_scale=fs * 1.6, lw=2.0, zorder=8))
            for _ in range(2)
        ]
        for artist in (*self.sliders, self.platform, *self.arrows):
            ax.add_patch(artist)

    def _panel(self) -> None:
        run, fs = self.run, self._font
        self.clock = self._add(self.fig.text(0.54, 0.86, "", fontsize=fs * 1.25, va="top", family="monospace"))
        self.values = [
            self._add(
                self.fig.text(
                    0.54,
                    0.78 - 0.065 * i,
                    "",
                    fontsize=fs * 1.1,
                    va="top",
                    family="monospace",
                    color=np.array(BAR_COLOURS[i]) / 255,
                )
            )
            for i in range(2)
        ]
        bars = self.fig.add_axes((0.6, 0.52, 0.37, 0.11))
        bars.set_xlim(-self.scale, self.scale)
        bars.set_ylim(-0.5, 1.5)
        bars.set_yticks([])
        bars.axvline(0.0, color="0.2", lw=0.8)
        bars.tick_params(labelsize=fs * 0.75)
        bars.set_xlabel("N", fontsize=fs * 0.8, labelpad=0)
        self.bars = []
        for i in range(2):
            colour = np.array(BAR_COLOURS[i]) / 255
            bar = self._add(Rectangle((0.0, 1 - i - 0.3), 0.0, 0.6, fc=colour, ec="none", antialiased=False))
            bars.add_patch(bar)
            self.bars.append(bar)
        self.bar_axes = bars
        strip = self.fig.add_axes((0.6, 0.1, 0.37, 0.31))
        for i in range(2):
            strip.plot(run.t, run.tau[:, i], color=np.array(BAR_COLOURS[i]) / 255, lw=1.4, label=f"τ{i + 1}")
        strip.axhline(0.0, color="0.6", lw=0.6)
        strip.set_xlim(run.t[0], run.t[-1])
        strip.set_ylim(-self.scale, self.scale)
        strip.tick_params(labelsize=fs * 0.75)
        strip.set_xlabel("t [s]", fontsize=fs * 0.8, labelpad=1)
        strip.set_ylabel("τ [N], eq. (31)", fontsize=fs * 0.8)
        strip.legend(fontsize=fs * 0.75, loc="upper right", ncols=2, frameon=False)
        strip.grid(alpha=0.3)
        self.marker = self._add(strip.axvline(run.t[0], color="0.15", lw=1.2))
        self.dots = self._add(strip.plot([], [], "o", color="0.15", ms=fs * 0.45)[0])

    # -- frames -------------------------------------------------------------------------------------------
    def geometry(self) -> BarGeometry:
        """The bars' pixel geometry (identical in every frame)."""
        height = self.size[1]
        to_px = self.bar_axes.transData.transform
        (x0, y1), (x1, y2) = to_px([(0.0, 1.0), (self.scale, 0.0)])
        (_, top), (_, bottom) = to_px([(0.0, 1.3), (0.0, 0.7)])
        return BarGeometry(
            zero_x=float(x0),
            px_per_newton=float((x1 - x0) / self.scale),
            rows=(round(height - y1), round(height - y2)),
            height=round(top - bottom),
        )

    def texts(self, k: int) -> tuple[str, str, str]:
        """The time and the two forces as frame ``k`` shows them."""
        t, tau = float(self.run.t[k]), self.run.tau[k]
        return (f"t = {t:.{self._digits}f} s", f"τ1 = {_signed(tau[0])} N", f"τ2 = {_signed(tau[1])} N")

    def frame(self, k: int) -> np.ndarray:
        """Frame ``k`` (the run at ``t[k]``) as an RGB array ``(height, width, 3)`` of uint8."""
        run, mm = self.run, 1e3
        params = run.params
        pose = mechanism_pose(params, run.p[k], run.d[k])
        self.trace.set_data(run.p[: k + 1, 0] * mm, run.p[: k + 1, 1] * mm)
        for i in range(2):
            lo = np.array(pose.A[i]) - np.array([SLIDER_LENGTH / 2, SLIDER_MARGIN])[[i, 1 - i]]
            size = np.array([SLIDER_LENGTH, params.pivot_spacing + 2 * SLIDER_MARGIN])[[i, 1 - i]]
            self.sliders[i].set_xy(tuple(lo * mm))
            self.sliders[i].set_width(size[0] * mm)
            self.sliders[i].set_height(size[1] * mm)
            for j in range(2):
                self.links[2 * i + j].set_data(*(pose.links[i, j].T * mm))
            tau = float(run.tau[k, i])
            length = 0.3 * params.a * tau / self.scale  # m, full scale = 30 % of a
            tip = np.array(pose.A[i]) + np.eye(2)[i] * length
            self.arrows[i].set_positions(tuple(pose.A[i] * mm), tuple(tip * mm))
            self.arrows[i].set_color(_ARROW[tau >= 0])
            self.bars[i].set_width(tau)
        half = platform_half_size(params)
        self.platform.set_xy(tuple((run.p[k] - half) * mm))
        self.point.set_data([run.p[k, 0] * mm], [run.p[k, 1] * mm])
        clock, *values = self.texts(k)
        self.clock.set_text(clock)
        for text, value in zip(self.values, values, strict=True):
            text.set_text(value)
        self.marker.set_xdata([run.t[k], run.t[k]])
        self.dots.set_data([run.t[k], run.t[k]], run.tau[k])
        self.canvas.restore_region(self._background)
        for artist in self._moving:
            self.fig.draw_artist(artist)
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()

    def frames(self) -> Iterator[np.ndarray]:
        """Every frame in order."""
        for k in range(len(self)):
            yield self.frame(k)
