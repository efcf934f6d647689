"""Plan-view clearance of a 2-PPa over a task: the parts that must not cross (``docs/design.md``, *Clearance*).

The machine seen from above, each part as its centre lines (widths not included):

- rail ``i``: the segment the slider joint ``A_i`` sweeps over the stroke, ``d_i`` from 0 to ``Δd`` (fixed);
- leg ``i``: the parallelogram of its four pivots ``A_i``, ``A_i + o_i``, ``B_i + o_i``, ``B_i`` (both links and
  the space between them), ``o_i`` the pivot spacing across rail ``i`` (along ``e_j`` for the perpendicular
  arrangement, along ``+Y`` for the parallel one, as :func:`~tpm_viz.paper.arrangement.mechanism_pose` draws it).

The machine is built in layers: the rails on the base, each slider on its rail, both legs' links on the sliders,
the platform on the links. So a leg passes over its own rail (its slider carries it) and the platform over
everything, but at no pose of the task may

- a leg pass over the *other* rail anywhere along its stroke (the other slider, which lifts its leg's pivots to
  the links' layer, runs the whole stroke),
- the two legs cross (their links share a layer; this includes a leg over the other slider's pivots),
- the two rails cross or overlap (both lie on the base: ``Δd >= a`` in either arrangement).

Two convex shapes are apart by their *separation* ``σ``: the largest gap between their projections on the normals
of their edges (separating axes); ``σ > 0`` exactly when they are disjoint, and then ``σ`` is at most their
distance. :func:`collision` evaluates ``σ`` on the task's check grid and certifies every cell between grid points:
while the platform moves by ``δ`` a point of leg ``i`` moves by at most ``δ ‖J_i‖`` (``‖J_i‖ = 1/|cos θ_i|``, its
largest value on a cell is at a corner), so a cell is clear when its corners' smallest ``σ`` exceeds the two
parts' speeds times the cell's half diagonal. Cells that are not certified are split in four, at most
:data:`MAX_DEPTH` times; a cell still undecided there (parts within about 0.1 mm) counts as a collision.
"""

from __future__ import annotations

import numpy as np

from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["MAX_DEPTH", "PAIRS", "collision", "joints", "legs", "rail_problem", "rails", "separations"]

MAX_DEPTH = 8
"""Most times a grid cell is split in four before parts this close count as touching."""
COARSE = 4
"""The certificate starts from every ``COARSE``-th value of the check grid (cells split where parts come close)."""
MAX_CELLS = 4096
"""Most undecided cells carried from one split to the next (more: the parts run along each other, touching)."""
PAIRS = (("leg", 1, "rail", 2), ("leg", 2, "rail", 1), ("leg", 1, "leg", 2))
"""The checked pairs, in the order of the columns of :func:`separations`."""

_LEG_RAIL = (
    "leg {leg} runs over rail {rail} in plan view with the platform at ({x:.1f}, {y:.1f}) mm "
    "(slider {rail} travels the whole rail)"
)
_LEGS = "the two legs cross in plan view with the platform at ({x:.1f}, {y:.1f}) mm"
_RAILS_CROSS = "the rails cross in plan view: the stroke Δd = {stroke:.1f} mm must be shorter than a = {a:.1f} mm"
_RAILS_OVERLAP = "the rails overlap on the X axis: the stroke Δd = {stroke:.1f} mm must be shorter than a = {a:.1f} mm"


def joints(arrangement: Arrangement, params: Params, p: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Slider joints ``A_i`` and platform joints ``B_i`` ``(n, 2, 2)`` [m] (eq. 1 / ``docs/parallel.md`` P1)."""
    n = len(p)
    a_pts, b_pts = np.zeros((n, 2, 2)), np.repeat(p[:, None, :], 2, axis=1)
    if arrangement is Arrangement.PARALLEL:
        a_pts[:, 0, 0], a_pts[:, 1, 0] = d[:, 0] - params.a, params.a - d[:, 1]
        b_pts[:, 0, 0] -= params.b
        b_pts[:, 1, 0] += params.b
    else:
        a_pts[:, 0, 0], a_pts[:, 1, 1] = d[:, 0] - params.a, d[:, 1] - params.a
        b_pts[:, 0, 0] -= params.b
        b_pts[:, 1, 1] -= params.b
    return a_pts, b_pts


def _offsets(arrangement: Arrangement, params: Params) -> np.ndarray:
    """The second link's offset ``o_i`` (2, 2) [m] of each leg."""
    if arrangement is Arrangement.PARALLEL:
        return np.array([[0.0, 1.0], [0.0, 1.0]]) * params.pivot_spacing
    return np.array([[0.0, 1.0], [1.0, 0.0]]) * params.pivot_spacing


def rails(arrangement: Arrangement, params: Params) -> np.ndarray:
    """Both rails (2, 2, 2) [m]: rail ``i`` from ``A_i`` at ``d_i = 0`` to ``A_i`` at ``d_i = Δd``."""
    ends = np.array([[0.0, 0.0], [params.stroke, params.stroke]])
    a_pts, _ = joints(arrangement, params, np.zeros((2, 2)), ends)
    return np.swapaxes(a_pts, 0, 1)


def legs(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """Both legs' parallelograms ``(n, 2, 4, 2)`` [m] at poses ``p`` ``(n, 2)``: ``A, A + o, B + o, B``."""
    a_pts, b_pts = joints(arrangement, params, p, arr.inverse_kinematics(arrangement, params, p))
    o = _offsets(arrangement, params)[None]
    return np.stack([a_pts, a_pts + o, b_pts + o, b_pts], axis=2)


def _separation(one: np.ndarray, two: np.ndarray, edges_one: int, edges_two: int) -> np.ndarray:
    """``σ`` (n,) [m] of convex shapes ``one`` ``(n, k, 2)`` and ``two`` ``(n, m, 2)`` (vertices in order; a
    segment is two vertices): the largest projection gap over the normals of their first ``edges_one`` and
    ``edges_two`` edges (a parallelogram's first two edges give both its directions, a segment's one)."""
    edges = [one[:, e + 1] - one[:, e] for e in range(edges_one)] + [
        two[:, e + 1] - two[:, e] for e in range(edges_two)
    ]
    best = np.full(len(one), -np.inf)
    for edge in edges:
        length = np.hypot(edge[:, 0], edge[:, 1])
        nx, ny = -edge[:, 1] / np.where(length > 0, length, 1.0), edge[:, 0] / np.where(length > 0, length, 1.0)
        p1 = nx[:, None] * one[..., 0] + ny[:, None] * one[..., 1]
        p2 = nx[:, None] * two[..., 0] + ny[:, None] * two[..., 1]
        gap = np.maximum(p2.min(1) - p1.max(1), p1.min(1) - p2.max(1))
        best = np.maximum(best, np.where(length > 0, gap, -np.inf))
    return best


def separations(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """``σ`` ``(n, 3)`` [m] of :data:`PAIRS` at poses ``p`` ``(n, 2)`` (positive: apart)."""
    shapes = legs(arrangement, params, p)
    rail = np.broadcast_to(rails(arrangement, params)[:, None], (2, len(p), 2, 2))
    return np.stack(
        [
            _separation(shapes[:, 0], rail[1], 2, 1),
            _separation(shapes[:, 1], rail[0], 2, 1),
            _separation(shapes[:, 0], shapes[:, 1], 2, 2),
        ],
        axis=-1,
    )


def _measure(arrangement: Arrangement, params: Params, p: np.ndarray) -> np.ndarray:
    """``σ`` of :data:`PAIRS` and the pairs' largest part speed per unit platform speed, ``(n, 6)``: a point of
    leg ``i`` moves at most ``‖J_i‖`` (``1/|cos θ_i| >= 1``, so ``B_i``'s speed 1 too); a rail does not move."""
    speed = np.linalg.norm(arr.jacobians(arrangement, params, p).j, axis=-1)  # (n, 2): ‖J_1‖, ‖J_2‖
    pairs = np.stack([speed[:, 0], speed[:, 1], speed[:, 0] + speed[:, 1]], axis=-1)
    return np.concatenate([separations(arrangement, params, p), pairs], axis=-1)


def rail_problem(arrangement: Arrangement, params: Params) -> Phrase | None:
    """Why the two rails meet (None if they do not): both arrangements need ``Δd < a``."""
    if params.stroke < params.a:
        return None
    if arrangement is Arrangement.PARALLEL:
        return Phrase(_RAILS_OVERLAP, stroke=params.stroke * 1e3, a=params.a * 1e3)
    return Phrase(_RAILS_CROSS, stroke=params.stroke * 1e3, a=params.a * 1e3)


def _phrase(pair: int, pose: np.ndarray) -> Phrase:
    _, i, other, j = PAIRS[pair]
    x, y = float(pose[0]) * 1e3, float(pose[1]) * 1e3
    return Phrase(_LEG_RAIL, leg=i, rail=j, x=x, y=y) if other == "rail" else Phrase(_LEGS, x=x, y=y)


def collision(arrangement: Arrangement, params: Params, xs: np.ndarray, ys: np.ndarray) -> Phrase | None:
    """Why some pose of the task ``xs x ys`` (its check grid's sorted coordinates [m], the edges included) has
    parts crossing in plan view (None: every pose of the rectangle is certified clear; see the module docstring).
    The poses must be reachable (the task's singularity check passed)."""
    problem = rail_problem(arrangement, params)
    if problem is not None:
        return problem
    cells, corners, values = _first_cells(arrangement, params, np.asarray(xs), np.asarray(ys))
    for depth in range(MAX_DEPTH + 1):
        sigma = values[..., :3]
        hit = np.argwhere(sigma <= 0.0)
        if hit.size:
            k, corner, pair = (int(v) for v in hit[np.argmin(sigma[tuple(hit.T)])])
            return _phrase(pair, corners[k, corner])
        half = 0.5 * np.hypot(cells[:, 1] - cells[:, 0], cells[:, 3] - cells[:, 2])
        # ‖J_i‖ is largest where |p_j| is, at a corner of the cell (both arrangements)
        undecided = np.any(sigma.min(axis=1) <= values[..., 3:].max(axis=1) * half[:, None], axis=1)
        cells = cells[undecided]
        if not len(cells):
            return None
        if len(cells) > MAX_CELLS or depth == MAX_DEPTH:
            break
        cells = _split(cells)
        corners = _corners(cells)
        values = _measure(arrangement, params, corners.reshape(-1, 2)).reshape(len(cells), 4, 6)
    # parts within a fraction of a millimetre: touching, i.e. a collision at the closest corner found
    points = _corners(cells).reshape(-1, 2)
    closest = separations(arrangement, params, points)
    nearest, pair = (int(v) for v in np.unravel_index(int(np.argmin(closest)), closest.shape))
    return _phrase(pair, points[nearest])


def _first_cells(
    arrangement: Arrangement, params: Params, xs: np.ndarray, ys: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The cells ``(n, 4)`` of every :data:`COARSE`-th grid value (the last included), their corners ``(n, 4, 2)``
    and :func:`_measure` there ``(n, 4, 6)``, each lattice point evaluated once."""
    xs, ys = (np.unique(np.append(v[::COARSE], v[-1])) for v in (xs, ys))
    lattice = np.stack(np.meshgrid(xs, ys, indexing="ij"), -1)
    at = _measure(arrangement, params, lattice.reshape(-1, 2)).reshape(len(xs), len(ys), 6)
    quad = (np.s_[:-1, :-1], np.s_[1:, :-1], np.s_[:-1, 1:], np.s_[1:, 1:])
    corners = np.stack([lattice[q] for q in quad], axis=2).reshape(-1, 4, 2)
    values = np.stack([at[q] for q in quad], axis=2).reshape(-1, 4, 6)
    cells = np.stack([corners[:, 0, 0], corners[:, 3, 0], corners[:, 0, 1], corners[:, 3, 1]], -1)
    return cells, corners, values


def _split(cells: np.ndarray) -> np.ndarray:
    """Each cell ``(lo_x, hi_x, lo_y, hi_y)`` in four."""
    mx, my = (cells[:, 0] + cells[:, 1]) / 2, (cells[:, 2] + cells[:, 3]) / 2
    return np.concatenate(
        [
            np.stack([cells[:, 0], mx, cells[:, 2], my], -1),
            np.stack([mx, cells[:, 1], cells[:, 2], my], -1),
            np.stack([cells[:, 0], mx, my, cells[:, 3]], -1),
            np.stack([mx, cells[:, 1], my, cells[:, 3]], -1),
        ]
    )


def _corners(cells: np.ndarray) -> np.ndarray:
    """Corners ``(n, 4, 2)`` of cells ``(lo_x, hi_x, lo_y, hi_y)`` ``(n, 4)``."""
    return np.stack([cells[:, [0, 2]], cells[:, [1, 2]], cells[:, [0, 3]], cells[:, [1, 3]]], axis=1)
