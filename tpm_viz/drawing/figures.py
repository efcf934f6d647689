"""PNG figures reproducing the paper's Figs. 4 (line) and 5 (circle): actuator forces vs time.

As in the paper, the closed-form equations are drawn solid and the independent simulation model
dotted (there ADAMS, here the Pinocchio closed-loop model); a second panel shows their difference.
Drawn with matplotlib's Agg canvas (no pyplot, no GUI backend). Takes arrays, computes nothing: the command line
(``tpm-viz figures``) and the app's player pass the forces of both models.
"""

from __future__ import annotations

import io
import pathlib
from typing import Protocol

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure

from tpm_viz.core.files import write_atomically
from tpm_viz.drawing.labels import name_props, quiet_glyphs

__all__ = ["FILE_NAMES", "PRINT_DPI", "TITLES", "ForceCurves", "force_plot_png", "force_plot_svg", "plot_forces"]

TITLES = {
    "line": "Fig. 4: line from (-100, -50) to (+100, +50) mm",
    "circle": "Fig. 5: circle about (0, 0), radius 100 mm",
}
FILE_NAMES = {"line": "fig4_line.png", "circle": "fig5_circle.png"}


class ForceCurves(Protocol):
    """Forces along one trajectory by both models, e.g. :class:`tpm_viz.multibody.crosscheck.ForceComparison`."""

    @property
    def kind(self) -> str: ...
    @property
    def duration(self) -> float: ...  # [s]
    @property
    def t(self) -> np.ndarray: ...  # (n,) [s]
    @property
    def tau_paper(self) -> np.ndarray: ...  # (n, 2) [N]
    @property
    def tau_pinocchio(self) -> np.ndarray: ...  # (n, 2) [N]


def _force_figure(t, tau_paper, tau_ref, title: str, dpi: int):
    """The figure of :func:`plot_forces`: forces (paper solid, reference dotted) over their difference; one
    panel when there is no reference."""
    fig = Figure(figsize=(7.0, 6.0 if tau_ref is not None else 4.2), dpi=dpi, layout="constrained")
    FigureCanvasAgg(fig)
    if tau_ref is not None:
        top, bottom = fig.subplots(2, 1, sharex=True, gridspec_kw={"height_ratios": [2.2, 1.0]})
    else:
        top, bottom = fig.subplots(1, 1), None
    colours = ("tab:blue", "tab:red")
    for i, colour in enumerate(colours):
        top.plot(t, tau_paper[:, i], "-", color=colour, lw=1.6, label=f"τ{i + 1} paper eqs. (29)-(31)")
        if tau_ref is not None:
            top.plot(t, tau_ref[:, i], ":", color="black", lw=2.2, label=f"τ{i + 1} Pinocchio model")
            bottom.plot(t, tau_ref[:, i] - tau_paper[:, i], "-", color=colour, lw=1.2, label=f"Δτ{i + 1}")
    top.axhline(0.0, color="0.6", lw=0.6)
    top.set_ylabel("actuator force [N]")
    top.legend(loc="lower center", bbox_to_anchor=(0.5, 1.0), fontsize=8, ncols=2, frameon=False)
    top.grid(alpha=0.3)
    fig.suptitle(title, fontsize=11, **name_props())  # a run's name is text: "$x$" is not maths
    last = top
    if bottom is not None:
        diff = np.asarray(tau_ref) - np.asarray(tau_paper)
        rel = float(np.max(np.abs(diff) / (1.0 + np.abs(tau_paper))))
        bottom.set_ylabel("Pinocchio − paper [N]")
        bottom.ticklabel_format(axis="y", style="sci", scilimits=(-2, 2))
        bottom.grid(alpha=0.3)
        bottom.legend(loc="upper right", fontsize=8, ncols=2)
        bottom.set_title(f"max |Δτ| = {np.max(np.abs(diff)):.1e} N, max |Δτ|/(1 N + |τ|) = {rel:.1e}", fontsize=9)
        last = bottom
    last.set_xlabel("time [s]")
    last.set_xlim(t[0], t[-1])
    return fig


def plot_forces(cmp: ForceCurves, path: str | pathlib.Path, dpi: int = 100) -> pathlib.Path:
    """Write one force figure (two panels, N vs s) for :class:`ForceCurves`; returns the path."""
    title = f"{TITLES.get(cmp.kind, cmp.kind)}, T = {cmp.duration:g} s"
    fig = _force_figure(cmp.t, cmp.tau_paper, cmp.tau_pinocchio, title, dpi)
    path = pathlib.Path(path)
    write_atomically(path, _save(fig, "png", dpi))  # never into a device or FIFO (tpm_viz.core.files)
    return path


PRINT_DPI = 240
"""Resolution of the downloadable figures: 7 in wide at 240 dpi = 1680 px (print size)."""


def force_plot_png(t, tau_paper, tau_ref=None, title: str = "actuator forces", dpi: int = PRINT_DPI) -> bytes:
    """PNG bytes of the force figure for any trajectory (e.g. the app's player): ``t`` (n,) [s], forces (n, 2)
    [N]; the reference model (Pinocchio) dotted with a difference panel when ``tau_ref`` is given."""
    return _save(_force_figure(t, tau_paper, tau_ref, title, dpi), "png", dpi)


def force_plot_svg(t, tau_paper, tau_ref=None, title: str = "actuator forces") -> bytes:
    """The same figure as :func:`force_plot_png`, as SVG (vector: any size, editable)."""
    return _save(_force_figure(t, tau_paper, tau_ref, title, PRINT_DPI), "svg", PRINT_DPI)


def _save(fig: Figure, fmt: str, dpi: int) -> bytes:
    out = io.BytesIO()
    with quiet_glyphs():  # a Hangul name on a machine without a Hangul font: boxes, not a warning per glyph
        fig.savefig(out, format=fmt, dpi=dpi)
    return out.getvalue()
