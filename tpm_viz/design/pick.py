"""The design studio's standard pick (``docs/design.md``): its path over a task, either way, and its peak force
under the paper's cubic law.

- :func:`pick_path`: from ``(x0, y_c - h/2)`` up ``h``, across the task's width, down ``h`` (``along="x"``), or the
  same mirrored in the line ``x = y`` (``along="y"``);
- :func:`peak_cubic`: the peak ``|τ_i|`` [N] along a path run by ``s = L (3u² - 2u³)`` in a given time.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from tpm_viz.app.paths import GeometricPath, PickSize, pick_and_place, waypoint_path
from tpm_viz.core.params import Params
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["PICK_CORNER", "PICK_RISE", "Rectangle", "cubic_inverse", "peak_cubic", "pick_path"]

PICK_RISE = 0.025
"""Rise and fall of the standard pick [m] (25 mm)."""
PICK_CORNER = 0.010
"""Corner radius of the standard pick [m] (the planner's default)."""


class Rectangle(Protocol):
    """A task rectangle (:class:`tpm_viz.design.indices.Task`): ``x0 < x1``, ``y0 < y1`` [m]."""

    @property
    def x0(self) -> float: ...
    @property
    def x1(self) -> float: ...
    @property
    def y0(self) -> float: ...
    @property
    def y1(self) -> float: ...


def pick_path(task: Rectangle, along: str = "x") -> GeometricPath:
    """The standard pick: from ``(x0, y_c - h/2)`` up ``h``, across the task's width, down ``h`` (``h`` =
    :data:`PICK_RISE`, or the task's height if smaller; corners :data:`PICK_CORNER` or less), centred in height.
    ``along="y"``: the same pick mirrored in the line ``x = y`` (``+h`` along X, the task's height along Y,
    ``-h`` along X, centred in width)."""
    width, height = task.x1 - task.x0, task.y1 - task.y0
    if along == "y":
        h = min(PICK_RISE, width)
        r = min(PICK_CORNER, h, height / 2)
        x = (task.x0 + task.x1) / 2 - h / 2
        return waypoint_path([(x, task.y0), (x + h, task.y0), (x + h, task.y1), (x, task.y1)], r)
    h = min(PICK_RISE, height)
    r = min(PICK_CORNER, h, width / 2)
    return pick_and_place((task.x0, (task.y0 + task.y1) / 2 - h / 2), PickSize(h, width, r))


def cubic_inverse(fraction: np.ndarray) -> np.ndarray:
    """``u`` in ``[0, 1]`` with ``3u² - 2u³ = fraction`` (bisection to 1e-15: the law is increasing)."""
    lo, hi = np.zeros_like(fraction), np.ones_like(fraction)
    for _ in range(52):
        mid = (lo + hi) / 2
        below = 3 * mid**2 - 2 * mid**3 < fraction
        lo, hi = np.where(below, mid, lo), np.where(below, hi, mid)
    return (lo + hi) / 2


def peak_cubic(arrangement: Arrangement, params: Params, path: GeometricPath, duration: float, n: int = 1001) -> float:
    """Peak ``|τ_i|`` [N] along ``path`` under the cubic law ``s = L (3u² - 2u³)``, ``u = t / duration``, at ``n``
    even instants and at the junctions, both sides (the return stroke has the same peak: ``τ`` is even in ``ṗ``)."""
    big = path.length
    u = np.concatenate([np.linspace(0.0, 1.0, n), cubic_inverse(path.junctions / big)])
    s = np.concatenate([big * (3 * u[:n] ** 2 - 2 * u[:n] ** 3), path.junctions])  # junctions exactly
    ds, dds = big * (6 * u - 6 * u**2) / duration, big * (6 - 12 * u) / duration**2
    peak = 0.0
    for side in ("left", "right"):
        ps, pss = path.evaluate(s, 1), path.evaluate(s, 2, side)
        dp, ddp = ps * ds[:, None], ps * dds[:, None] + pss * (ds**2)[:, None]
        tau = arr.inverse_dynamics(arrangement, params, path.evaluate(s), dp, ddp)
        peak = max(peak, float(np.max(np.abs(tau))))
    return peak
