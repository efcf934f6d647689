"""The player's uPlot charts: actuator forces (paper solid, Pinocchio dotted, like Figs. 4-5) and the actuator
positions, velocities and accelerations vs time, each with a vertical marker at the current time.

uPlot takes one array per series on a shared x axis, and nothing but numbers (no JS callbacks) crosses the
wire, so the time marker is a series of its own on a hidden scale ``c`` fixed to ``[0, 1]``: ``-1`` (off the
chart) everywhere except ``+1`` at the current sample, a spike that draws as a vertical line across the chart.
No NaN is ever sent. Charts are built once per tab; a new run replaces their data; the marker moves by
re-sending the (decimated, <= :data:`CHART_POINTS` points) data, which the caller throttles during playback.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import viser

from tpm_viz.app.palette import hex_colour
from tpm_viz.app.runs import Run

__all__ = ["CHART_POINTS", "Charts", "marker"]

CHART_POINTS = 151
X_LABEL = "time t (s)"
FORCE_COLOURS = (hex_colour("tau1"), hex_colour("tau2"))  # τ1, τ2 as in the PNG figures (blue, red)
LEG_COLOURS = (hex_colour("leg1"), hex_colour("leg2"))  # leg 1 teal, leg 2 purple as in the 3D view
MARKER = hex_colour("inverse")
KINEMATICS = (  # attribute of Run, title, y-axis label, scale SI -> UI
    ("d", "Actuator positions d₁, d₂ (eq. 4)", "position (mm)", 1e3),
    ("dd", "Actuator velocities (eq. 9)", "velocity (mm/s)", 1e3),
    ("ddd", "Actuator accelerations (eq. 14)", "acceleration (mm/s²)", 1e3),
)


def marker(n: int, k: int | None) -> np.ndarray:
    """The time-marker series: ``-1`` everywhere (off the ``[0, 1]`` scale), ``+1`` at sample ``k``."""
    out = np.full(n, -1.0)
    if k is not None and 0 <= k < n:
        out[k] = 1.0
    return out


def _series(label: str, colour: str, width: float = 2.0, dash=None) -> Any:
    s = {"label": label, "stroke": colour, "width": width, "points": {"show": False}}
    if dash is not None:
        s["dash"] = dash
    return s


def _marker_series() -> Any:
    return {"label": "now", "stroke": MARKER, "width": 2.0, "scale": "c", "points": {"show": False}}


def _options(y_label: str, height: int) -> dict:
    return dict(
        scales={"x": {"time": False}, "c": {"range": (0.0, 1.0)}},
        axes=({"label": X_LABEL, "size": 40}, {"label": y_label, "size": 62}),
        legend={"live": False},
        cursor={"points": {"show": False}},
        height=height,
        padding=(12, 18, 0, 0),  # top: room for the highest tick label under the title
    )


class Charts:
    """Four uPlot charts in the current GUI container (a tab): forces, ``d``, ``ḋ``, ``d̈``."""

    def __init__(self, gui: viser.GuiApi) -> None:
        n = 2
        x = np.linspace(0.0, 1.0, n)
        zero = np.zeros(n)
        self._run: Run | None = None
        self._idx = np.arange(n)
        self._base: list[tuple[np.ndarray, ...]] = []
        self.forces = gui.add_uplot(
            (x, zero, zero, zero, zero, marker(n, None)),
            (
                {"label": X_LABEL},
                _series("τ₁ paper", FORCE_COLOURS[0]),
                _series("τ₂ paper", FORCE_COLOURS[1]),
                _series("τ₁ Pinocchio", "#0f172a", 2.2, (2.0, 4.0)),
                _series("τ₂ Pinocchio", "#475569", 2.2, (2.0, 4.0)),
                _marker_series(),
            ),
            title="Actuator forces τ (paper solid, Pinocchio dotted)",
            **_options("force (N)", 240),
        )
        self.kinematics = [
            gui.add_uplot(
                (x, zero, zero, marker(n, None)),
                (
                    {"label": X_LABEL},
                    _series("actuator 1", LEG_COLOURS[0]),
                    _series("actuator 2", LEG_COLOURS[1]),
                    _marker_series(),
                ),
                title=title,
                **_options(label, 170),
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
        self._run = run
        for handle in self.handles:
            handle.visible = run is not None
        if run is None:
            return
        n = len(run.t)
        step = max(1, int(np.ceil((n - 1) / (CHART_POINTS - 1))))
        self._idx = np.unique(np.r_[np.arange(0, n, step), n - 1])
        i = self._idx
        ref = run.tau_ref if run.tau_ref is not None else run.tau  # hidden when there is no reference
        self._base = [(run.t[i], run.tau[i, 0], run.tau[i, 1], ref[i, 0], ref[i, 1])]
        for attr, _title, _label, scale in KINEMATICS:
            arr = getattr(run, attr)
            self._base.append((run.t[i], arr[i, 0] * scale, arr[i, 1] * scale))
        series = list(self.forces.series)
        for k in (3, 4):
            series[k] = {**series[k], "show": run.tau_ref is not None}
        self.forces.series = tuple(series)
        self.show_time(t)

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
