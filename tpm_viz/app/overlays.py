"""What the singularity explorer draws on the floor and at the platform, as plain arrays (no viser).

- :func:`map_rgba`: a :class:`~tpm_viz.paper.workspace.WorkspaceMap` as an RGBA image (pixel ``[k, i]`` is the grid
  point ``(xs[i], ys[k])``, the orientation in which viser lays an image on the XY plane: row 0 at ``-y``), one
  of :data:`MAP_KINDS`: the workspace (reachable, inside the stroke), ``det J_x = cos(θ1+θ2)`` (eq. 12) on a
  diverging scale, or the condition number of ``J`` (eq. 10) on a log scale. Cells where the quantity does not
  exist (unreachable: NaN in the map) are fully transparent, so no NaN ever leaves this module; reachable cells
  outside the stroke are drawn faint.
- :func:`colour_scale`: the legend of each kind (colour stops with their values and units; its words are
  :class:`~tpm_viz.core.words.Phrase` s, rendered in a tab's language where the legend is shown).
- :func:`ellipse_polylines`: the velocity and force manipulability ellipses (:mod:`tpm_viz.paper.ellipses`) at a
  platform position, scaled for drawing, or None at a singular pose.
- :func:`arrow_length`, :func:`arrow_vector`: how long the force arrows of the 3D view are drawn. Near a
  singularity the actuator forces grow without bound (eq. 12), so the length is proportional to the force for
  small forces and grows only logarithmically beyond :data:`ARROW_FORCE`, never past :func:`arrow_reach` (a fixed
  fraction of the mechanism's size): every arrow stays in view, a larger force always has a longer arrow, and the
  number itself is in the panel.
"""

from __future__ import annotations

import functools
from collections.abc import Sequence
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.ellipses import ellipse_outline, manipulability_ellipses
from tpm_viz.paper.workspace import WorkspaceMap, workspace_map

__all__ = [
    "ARROW_FORCE",
    "ARROW_REACH",
    "MAP_KINDS",
    "ColourScale",
    "EllipseDrawing",
    "arrow_length",
    "arrow_reach",
    "arrow_vector",
    "cached_map",
    "colour_scale",
    "ellipse_polylines",
    "map_rgba",
]

MAP_KINDS = {
    "off": "off (outline only)",
    "workspace": "workspace: reachable / in stroke",
    "det_jx": "det J_x = cos(θ1+θ2), eq. 12",
    "cond": "condition number of J, eq. 10",
}
"""Map kinds of the explorer and their labels."""

COND_MAX = 100.0
"""The condition-number scale saturates here (log scale from 1)."""
FAINT = 0.35  # opacity factor of reachable cells outside the stroke
ALPHA = 215  # opacity of the map (0-255)

_DIVERGING = (  # det J_x from -1 to +1: brown, white at 0, blue
    (-1.0, (140, 81, 10)),
    (-0.5, (216, 179, 101)),
    (0.0, (250, 250, 250)),
    (0.5, (103, 169, 207)),
    (1.0, (33, 102, 172)),
)
_SEQUENTIAL = (  # log10(cond) from 0 to 2: good (light green) to bad (dark purple)
    (0.0, (237, 248, 177)),
    (0.5, (127, 205, 187)),
    (1.0, (44, 127, 184)),
    (1.5, (83, 39, 140)),
    (2.0, (45, 0, 75)),
)
_IN_STROKE = (34, 197, 94)
_OUT_OF_STROKE = (148, 163, 184)


class ColourScale(NamedTuple):
    """Legend of a map: title (with its unit), colour stops ``(label, "#rrggbb")`` from low to high (a label is a
    number as text, or words), and a note (None: none)."""

    title: Phrase
    stops: tuple[tuple[str | Phrase, str], ...]
    note: Phrase | None


def _hex(rgb: tuple[int, int, int]) -> str:
    return "#{:02x}{:02x}{:02x}".format(*rgb)


def colour_scale(kind: str) -> ColourScale:
    """The legend of map ``kind`` (see :data:`MAP_KINDS`)."""
    if kind == "det_jx":
        diverging: tuple[tuple[str | Phrase, str], ...] = tuple(
            (f"{v:+.1f}" if v else "0", _hex(c)) for v, c in _DIVERGING
        )
        return ColourScale(T("det J_x = cos(θ1+θ2) (dimensionless)"), diverging, T("white band: direct singularity"))
    if kind == "cond":
        sequential: tuple[tuple[str | Phrase, str], ...] = tuple((f"{10**v:.3g}", _hex(c)) for v, c in _SEQUENTIAL)
        return ColourScale(
            T("condition number of J (log scale)"),
            sequential,
            Phrase("1 = isotropic; ≥ {most:g} saturates", most=COND_MAX),
        )
    if kind == "workspace":
        return ColourScale(
            T("workspace (working mode, eq. 4)"),
            ((T("in stroke"), _hex(_IN_STROKE)), (T("reachable, out of stroke"), _hex(_OUT_OF_STROKE))),
            T("transparent: unreachable (|p_j| ≥ l_a)"),
        )
    if kind == "off":
        return ColourScale(T("no map"), (), None)
    raise InputError(f"map kind must be one of {', '.join(MAP_KINDS)}, got {kind!r}")


def _interpolate(values: np.ndarray, stops: Sequence[tuple[float, tuple[int, int, int]]]) -> np.ndarray:
    xs = np.array([s[0] for s in stops], dtype=float)
    cs = np.array([s[1] for s in stops], dtype=float)
    v = np.clip(np.nan_to_num(values, nan=xs[0]), xs[0], xs[-1])
    return np.stack([np.interp(v, xs, cs[:, k]) for k in range(3)], -1)


def map_rgba(ws: WorkspaceMap, kind: str) -> np.ndarray:
    """``(ny, nx, 4)`` uint8 image of the map ``kind``; pixel ``[k, i]`` is the grid point ``(xs[i], ys[k])``."""
    colour_scale(kind)  # validates kind
    ny, nx = ws.reachable.shape
    rgb = np.zeros((ny, nx, 3))
    alpha = np.where(ws.reachable, float(ALPHA), 0.0)
    if kind == "workspace":
        rgb[:] = np.where(ws.in_stroke[..., None], _IN_STROKE, _OUT_OF_STROKE)
        alpha = np.where(ws.in_stroke, alpha, alpha * 0.6)
    elif kind == "det_jx":
        rgb = _interpolate(ws.det_jx, _DIVERGING)
        alpha = np.where(ws.in_stroke, alpha, alpha * FAINT)
    elif kind == "cond":
        with np.errstate(divide="ignore", invalid="ignore"):
            rgb = _interpolate(np.log10(ws.cond), _SEQUENTIAL)
        alpha = np.where(ws.in_stroke, alpha, alpha * FAINT)
    else:
        alpha[:] = 0.0
    alpha = np.where(ws.reachable & ~np.isnan(ws.det_jx), alpha, 0.0)  # no value, no colour
    image = np.concatenate([rgb, alpha[..., None]], -1)
    return np.ascontiguousarray(np.clip(np.rint(image), 0, 255).astype(np.uint8))


@functools.lru_cache(maxsize=8)
def cached_map(params: Params, n: int = 200) -> WorkspaceMap:
    """:func:`~tpm_viz.workspace_map` over ``[-l_a, l_a]²``, computed once per parameter set (arrays read-only)."""
    ws = workspace_map(params, n=n)
    for name in ("xs", "ys", "reachable", "in_stroke", "det_jx", "det_jq", "cond"):
        getattr(ws, name).setflags(write=False)
    return ws


class EllipseDrawing(NamedTuple):
    """Closed outlines ``(n, 2)`` [m] about the platform and the true semi-axes (dimensionless)."""

    velocity: np.ndarray
    force: np.ndarray
    velocity_radii: np.ndarray  # (m/s) per (m/s) of actuator speed
    force_radii: np.ndarray  # N per N of actuator force
    clipped: bool  # some radius was longer than the drawing cap


def ellipse_polylines(
    params: Params, p: ArrayLike, scale: float, cap: float = 3.0, n: int = 49
) -> EllipseDrawing | None:
    """Both manipulability ellipses at ``p`` [m], centred on the origin (the platform frame), each radius
    ``min(r, cap) * scale`` [m]; None where ``J`` is singular or ill-conditioned (``cond > 1e6``)."""
    try:
        ell = manipulability_ellipses(params, p)
    except TpmVizError:
        return None
    outlines, clipped = [], False
    for e in (ell.velocity, ell.force):
        radii = np.minimum(e.radii, cap)
        clipped |= bool(np.any(e.radii > cap))
        outlines.append(ellipse_outline(e._replace(radii=radii), scale=scale, n=n))
    if not all(np.all(np.isfinite(o)) for o in outlines):
        return None
    return EllipseDrawing(outlines[0], outlines[1], ell.velocity.radii, ell.force.radii, clipped)


ARROW_REACH = 0.15
"""The longest force arrow, as a fraction of the mechanism's size ``a + l_a`` (0.111 m for the paper's)."""
ARROW_FORCE = 50.0
"""[N] The force scale of the arrows: linear well below it (``reach / ARROW_FORCE`` per newton, 2.2 mm/N for
the paper's mechanism), logarithmic above; half the reach at ``(e - 1) ARROW_FORCE`` = 86 N."""


def arrow_reach(params: Params) -> float:
    """Length [m] that no force arrow reaches: :data:`ARROW_REACH` ``(a + l_a)``."""
    return ARROW_REACH * (params.a + params.l_a)


def arrow_length(force: ArrayLike, params: Params) -> float | NDArray[np.float64]:
    """Length [m] of the arrow of a force of magnitude ``|force|`` [N] (scalar or array): ``L u / (1 + u)`` with
    ``u = ln(1 + |force| / ARROW_FORCE)`` and ``L`` = :func:`arrow_reach`. Strictly increasing in ``|force|``, below
    ``L`` for every finite force; 0 for NaN, ``L`` for an infinite force."""
    f = np.abs(np.asarray(force, dtype=float))
    with np.errstate(invalid="ignore"):
        u = np.log1p(np.where(np.isfinite(f), f, 0.0) / ARROW_FORCE)
        out = np.where(np.isinf(f), 1.0, u / (1.0 + u)) * arrow_reach(params)
    out = np.where(np.isnan(f), 0.0, out)
    return float(out) if out.ndim == 0 else out


def arrow_vector(force: ArrayLike, params: Params) -> np.ndarray:
    """The arrow [m] of a planar force ``force`` (2,) [N]: along the force, :func:`arrow_length` of its norm.
    Zero for a zero force or one with a NaN component; an infinite component gives the longest arrow along it."""
    f = np.asarray(force, dtype=float).reshape(2)
    if np.any(np.isnan(f)):
        return np.zeros(2)
    if np.any(np.isinf(f)):
        f = np.where(np.isinf(f), np.sign(f), 0.0)
        return f / float(np.hypot(f[0], f[1])) * arrow_reach(params)
    norm = float(np.hypot(f[0], f[1]))
    if norm == 0.0:
        return np.zeros(2)
    return f / norm * arrow_length(norm, params)
