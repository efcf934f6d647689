"""Workspace and singularity maps on a grid, and the singularity loci as curves (for overlays).

In the working mode (eq. 4) ``sin θ_1 = p_2 / l_a`` and ``sin θ_2 = p_1 / l_a`` with
``cos θ_i > 0``, so:

- the inverse singularity ``cos θ_1 cos θ_2 = 0`` (eq. 11) is the square ``|p_j| = l_a``;
- the direct singularity ``cos(θ_1 + θ_2) = 0`` (eq. 12) is ``p_1² + p_2² = l_a²`` with
  ``p_1 p_2 > 0``: two quarter circles of radius ``l_a`` of different nature. In the third
  quadrant ``s_1 = -s_2``: the leg circles touch and the two assembly modes merge. In the first
  quadrant ``s_1 = s_2``: ``d_1 = d_2 = a - b``, the leg circles coincide and, with the actuators
  locked, the platform can still slide along the arc (outside the paper's stroke, since
  ``a - b = 390 mm > Δd = 300 mm``);
- the stroke limits ``d_i = 0`` and ``d_i = Δd`` are the curves
  ``p_i = d_i - (a - b) + sqrt(l_a² - p_j²)``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.paper.jacobians import condition_number, jacobians
from tpm_viz.paper.kinematics import in_stroke, inverse_kinematics, reachable

__all__ = [
    "WorkspaceMap",
    "direct_singularity_locus",
    "inverse_singularity_loci",
    "stroke_limit_loci",
    "workspace_area",
    "workspace_map",
]


@dataclass(frozen=True)
class WorkspaceMap:
    """Grid maps over the platform plane. ``xs`` ``(nx,)``, ``ys`` ``(ny,)`` [m]; maps ``(ny, nx)``.

    Singularity measures are NaN where the pose is unreachable (``|p_j| >= l_a``).
    """

    xs: np.ndarray
    ys: np.ndarray
    reachable: np.ndarray  # bool: eq. (4) has a real solution
    in_stroke: np.ndarray  # bool: reachable and 0 <= d_i <= Δd
    det_jx: np.ndarray  # cos(θ1 + θ2), eq. (12)
    det_jq: np.ndarray  # cos θ1 cos θ2, eq. (11)
    cond: np.ndarray  # condition number of J (eq. 10)


def workspace_map(params: Params, n: int = 200, extent: float | None = None) -> WorkspaceMap:
    """Maps on an ``n x n`` grid over ``[-extent, extent]²`` [m] (default ``extent = l_a``)."""
    if isinstance(n, bool) or int(n) != n or not 2 <= n <= 4000:
        raise InputError(f"grid size n must be a whole number from 2 to 4000, got {n!r}")
    extent = params.l_a if extent is None else float(extent)
    if not np.isfinite(extent) or extent <= 0:
        raise InputError(f"extent must be a positive number of metres, got {extent!r}")
    xs = np.linspace(-extent, extent, int(n))
    ys = xs.copy()
    grid = np.stack(np.meshgrid(xs, ys), axis=-1)  # (ny, nx, 2): [..., 0] = x = p1
    ok = reachable(params, grid)
    safe = np.where(ok[..., None], grid, 0.0)
    d = inverse_kinematics(params, safe)
    jac = jacobians(params, safe, d)
    with np.errstate(invalid="ignore", divide="ignore"):
        cond = condition_number(params, safe, d)
    nan = np.full(ok.shape, np.nan)
    return WorkspaceMap(
        xs=xs,
        ys=ys,
        reachable=ok,
        in_stroke=ok & in_stroke(params, d),
        det_jx=np.where(ok, jac.det_jx, nan),
        det_jq=np.where(ok, jac.det_jq, nan),
        cond=np.where(ok, cond, nan),
    )


def workspace_area(ws: WorkspaceMap, which: str = "in_stroke") -> float:
    """Area [m²] of the grid cells where ``which`` (``"in_stroke"`` or ``"reachable"``) holds; each grid point
    owns the cell of one grid spacing around it."""
    if which not in ("in_stroke", "reachable"):
        raise InputError(f"workspace area of 'in_stroke' or 'reachable', got {which!r}")
    cell = float(ws.xs[1] - ws.xs[0]) * float(ws.ys[1] - ws.ys[0])
    return float(np.count_nonzero(getattr(ws, which))) * cell


def direct_singularity_locus(params: Params, n: int = 90) -> list[np.ndarray]:
    """The direct-singularity curves ``cos(θ1+θ2) = 0`` in the working mode: two ``(n, 2)`` arcs [m].

    First the quadrant-I arc (coincident leg circles), then the quadrant-III arc (tangent circles).
    """
    phi = np.linspace(0.0, np.pi / 2, n)
    arc = params.l_a * np.stack([np.cos(phi), np.sin(phi)], -1)
    return [arc, -arc]


def inverse_singularity_loci(params: Params) -> list[np.ndarray]:
    """The inverse-singularity lines ``|p_j| = l_a`` (eq. 11): four ``(2, 2)`` segments [m]."""
    la = params.l_a
    return [np.array([[-la, y], [la, y]]) for y in (-la, la)] + [np.array([[x, -la], [x, la]]) for x in (-la, la)]


def stroke_limit_loci(params: Params, n: int = 90) -> list[np.ndarray]:
    """Curves ``d_i = 0`` and ``d_i = Δd`` in the platform plane, clipped to ``|p| <= l_a``: ``(m, 2)`` each."""
    k = params.offset
    pj = np.linspace(-params.l_a, params.l_a, n)
    curves = []
    for i in range(2):
        for d in (0.0, params.stroke):
            pi = d - k + np.sqrt(params.l_a**2 - pj**2)
            keep = np.abs(pi) <= params.l_a
            pts = np.stack([pi, pj], -1) if i == 0 else np.stack([pj, pi], -1)
            if np.count_nonzero(keep) >= 2:
                curves.append(pts[keep])
    return curves
