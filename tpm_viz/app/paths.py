"""Geometric platform paths for the motion planner, parameterised by arc length ``s`` [m].

A path is a chain of straight segments and circular arcs, so that ``p(s)``, ``p'(s)`` (the unit
tangent) and ``p''(s)`` (curvature times the inward normal) are exact; the planner
(:mod:`tpm_viz.app.planner`) only chooses the timing ``s(t)``. Kinds (:class:`PathKind`):

- ``LINE``: the paper's Fig. 4 line, (-100, -50) mm to (+100, +50) mm;
- ``CIRCLE``: the paper's Fig. 5 circle, centre (0, 0), radius 100 mm, one counter-clockwise turn from (+100, 0) mm;
- ``PICK``: a pick-and-place stroke: up ``h`` (+Y), across ``w`` (+X), down ``h``, with the two corners rounded
  to a stated radius; the return stroke is the same path backwards (see :func:`pick_and_place`);
- ``WAYPOINTS``: a polyline through a user's points (CSV or clicked in the app), interior corners rounded.

Every path is checked against the valid region: reachable (eq. 4), in stroke (``0 <= d_i <= Δd``) and away from
both singularities (eqs. 11-12, :data:`~tpm_viz.paper.status.MOVE_LIMITS`); :func:`check_path` raises an
:class:`~tpm_viz.core.errors.InputError` naming the first offending point.
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Sequence
from dataclasses import dataclass
from enum import Enum

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.arrangement import Arrangement, classify
from tpm_viz.paper.status import MOVE_LIMITS, STATUS_WORDS, PoseStatus, SingularityThresholds

__all__ = [
    "CHECK_STEP",
    "DEFAULT_CORNER_RADIUS",
    "DEFAULT_PICK",
    "GeometricPath",
    "PathKind",
    "PickSize",
    "check_path",
    "circle_path",
    "default_pick",
    "line_path",
    "path_for",
    "pick_and_place",
    "waypoint_path",
]

CHECK_STEP = 0.5e-3
"""Spacing [m] of the points at which a path is checked against the valid region."""
DEFAULT_CORNER_RADIUS = 0.010
"""Corner radius [m] of the pick-and-place cycle and of waypoint polylines (10 mm)."""


class PathKind(Enum):
    """The kinds of geometric path the planner accepts."""

    LINE = "line"
    CIRCLE = "circle"
    PICK = "pick"
    WAYPOINTS = "waypoints"


@dataclass(frozen=True)
class PickSize:
    """Pick-and-place dimensions [m]: rise ``h``, span ``w`` and corner radius ``r`` (``r <= h``, ``2 r <= w``)."""

    h: float = 0.025
    w: float = 0.150
    r: float = DEFAULT_CORNER_RADIUS


DEFAULT_PICK = PickSize()
"""The default cycle, 25-150-25 mm with 10 mm corners; shrunk to fit when the parameters require it."""


@dataclass(frozen=True)
class GeometricPath:
    """A chain of lines and arcs parameterised by arc length ``s`` in ``[0, length]`` [m].

    Segment ``k`` starts at ``starts[k]`` [m]; ``radius[k] = 0`` marks a line from ``origin[k]`` along the unit
    vector ``direction[k]``; otherwise an arc about ``centre[k]`` [m] starting at polar angle ``phi0[k]`` [rad],
    turning with ``sense[k] = +1`` (counter-clockwise) or ``-1``.
    """

    kind: PathKind
    name: str
    starts: np.ndarray  # (k,) [m]
    length: float  # [m]
    origin: np.ndarray  # (k, 2) [m]
    direction: np.ndarray  # (k, 2)
    centre: np.ndarray  # (k, 2) [m]
    radius: np.ndarray  # (k,) [m], 0 for a line
    phi0: np.ndarray  # (k,) [rad]
    sense: np.ndarray  # (k,) ±1

    @property
    def junctions(self) -> np.ndarray:
        """Arc lengths [m] where one segment meets the next (the curvature jumps there)."""
        return self.starts[1:].copy()

    def evaluate(self, s: ArrayLike, order: int = 0, side: str = "right") -> np.ndarray:
        """``p(s)`` [m], ``p'(s)`` [-] or ``p''(s)`` [1/m] for ``order`` 0, 1, 2; shape ``s.shape + (2,)``.

        At a junction ``p''`` jumps: ``side="right"`` uses the segment that starts there, ``"left"`` the one
        that ends there.
        """
        s = np.clip(np.asarray(s, dtype=float), 0.0, self.length)
        k = np.clip(np.searchsorted(self.starts, s, side="left" if side == "left" else "right") - 1, 0, None)
        k = np.minimum(k, len(self.starts) - 1)
        sigma = (s - self.starts[k])[..., None]
        r = self.radius[k][..., None]
        arc = r > 0
        safe_r = np.where(arc, r, 1.0)
        phi = self.phi0[k][..., None] + self.sense[k][..., None] * sigma / safe_r
        radial = np.concatenate([np.cos(phi), np.sin(phi)], -1)
        tangent = self.sense[k][..., None] * np.concatenate([-np.sin(phi), np.cos(phi)], -1)
        if order == 0:
            return np.where(arc, self.centre[k] + r * radial, self.origin[k] + sigma * self.direction[k])
        if order == 1:
            return np.where(arc, tangent, self.direction[k])
        if order == 2:
            return np.where(arc, -radial / safe_r, 0.0)
        raise InputError(Phrase("path derivative order must be 0, 1 or 2, got {got}", got=repr(order)))

    def __call__(self, s: ArrayLike, order: int = 0) -> np.ndarray:
        """Same as :meth:`evaluate` (the call signature of toppra's geometric paths)."""
        return self.evaluate(s, order)

    def reversed(self) -> GeometricPath:
        """The same curve run backwards (``s -> length - s``)."""
        n = len(self.starts)
        seg_len = np.diff(np.append(self.starts, self.length))[::-1]
        starts = np.concatenate([[0.0], np.cumsum(seg_len)[:-1]])
        idx = np.arange(n)[::-1]
        ends = self.evaluate(np.append(self.starts[1:], self.length))  # end point of each segment
        phi_end = self.phi0 + self.sense * seg_len[::-1] / np.where(self.radius > 0, self.radius, 1.0)
        return GeometricPath(
            kind=self.kind,
            name=f"{self.name} (back)",
            starts=starts,
            length=self.length,
            origin=ends[idx],
            direction=-self.direction[idx],
            centre=self.centre[idx],
            radius=self.radius[idx],
            phi0=phi_end[idx],
            sense=-self.sense[idx],
        )


def _chain(kind: PathKind, name: str, pieces: list[tuple]) -> GeometricPath:
    """Build a path from pieces ``("line", start, end)`` or ``("arc", centre, radius, phi0, sweep)``."""
    rows: list[tuple] = []
    for piece in pieces:
        if piece[0] == "line":
            start, end = np.asarray(piece[1], float), np.asarray(piece[2], float)
            seg = float(np.hypot(*(end - start)))
            if seg > 1e-12:
                rows.append((seg, start, (end - start) / seg, (0.0, 0.0), 0.0, 0.0, 1.0))
        else:
            _, centre, radius, phi0, sweep = piece
            if abs(sweep) > 1e-12:
                rows.append(
                    (radius * abs(sweep), (0.0, 0.0), (1.0, 0.0), centre, radius, phi0, math.copysign(1, sweep))
                )
    if not rows:
        raise InputError(Phrase("the path has zero length: give two distinct points at least"))
    seg_len = np.array([r[0] for r in rows])
    return GeometricPath(
        kind=kind,
        name=name,
        starts=np.concatenate([[0.0], np.cumsum(seg_len)[:-1]]),
        length=float(seg_len.sum()),
        origin=np.array([r[1] for r in rows], float),
        direction=np.array([r[2] for r in rows], float),
        centre=np.array([r[3] for r in rows], float),
        radius=np.array([r[4] for r in rows], float),
        phi0=np.array([r[5] for r in rows], float),
        sense=np.array([r[6] for r in rows], float),
    )


def line_path(start: ArrayLike = (-0.100, -0.050), end: ArrayLike = (0.100, 0.050)) -> GeometricPath:
    """The straight line of the paper's Fig. 4 (defaults) [m]."""
    return _chain(PathKind.LINE, "line", [("line", start, end)])


def circle_path(centre: Iterable[float] = (0.0, 0.0), radius: float = 0.100) -> GeometricPath:
    """The circle of the paper's Fig. 5: one counter-clockwise turn from ``centre + (radius, 0)`` [m]."""
    if not (math.isfinite(radius) and radius > 0):
        raise InputError(Phrase("the circle radius must be a positive number of metres, got {got}", got=repr(radius)))
    return _chain(PathKind.CIRCLE, "circle", [("arc", tuple(centre), float(radius), 0.0, 2 * math.pi)])


def _polyline(kind: PathKind, name: str, points: ArrayLike, radius: float) -> GeometricPath:
    """Lines through ``points`` with every interior corner replaced by a tangent arc of ``radius`` [m].

    The radius is reduced where a corner is too sharp for it: the tangent length ``r tan(α/2)`` (``α`` the turn
    angle) may use at most half of each adjacent segment.
    """
    pts = np.asarray(points, dtype=float)
    if pts.ndim != 2 or pts.shape[1] != 2 or len(pts) < 2:
        raise InputError(
            Phrase("a path needs at least two points (x, y), got an array of shape {shape}", shape=str(pts.shape))
        )
    if not np.all(np.isfinite(pts)):
        raise InputError(Phrase("a waypoint is not finite (NaN or inf)"))
    if not (math.isfinite(radius) and radius >= 0):
        raise InputError(
            Phrase("the corner radius must be zero or a positive number of metres, got {got}", got=repr(radius))
        )
    seg = np.diff(pts, axis=0)
    lengths = np.hypot(seg[:, 0], seg[:, 1])
    if np.any(lengths < 1e-9):
        k = int(np.argmax(lengths < 1e-9))
        raise InputError(Phrase("waypoints {k} and {next} coincide: remove one of them", k=k + 1, next=k + 2))
    units = seg / lengths[:, None]
    pieces: list[tuple] = []
    cursor = pts[0]
    for k in range(1, len(pts) - 1):
        u_in, u_out = units[k - 1], units[k]
        cross = u_in[0] * u_out[1] - u_in[1] * u_out[0]
        turn = math.atan2(cross, float(u_in @ u_out))  # signed turn angle α [rad]
        if abs(turn) > math.pi - 1e-6:
            raise InputError(Phrase("the path reverses direction at waypoint {k}: split it into two moves", k=k + 1))
        if abs(turn) < 1e-9 or radius == 0:
            if radius == 0 and abs(turn) >= 1e-9:
                raise InputError(Phrase("a sharp corner at waypoint {k} needs a corner radius above zero", k=k + 1))
            continue
        half = math.tan(abs(turn) / 2)
        r = min(radius, 0.5 * min(lengths[k - 1], lengths[k]) / half)
        t_len = r * half
        enter, leave = pts[k] - t_len * u_in, pts[k] + t_len * u_out
        normal = np.array([-u_in[1], u_in[0]]) * math.copysign(1.0, turn)  # towards the centre
        centre = enter + r * normal
        phi0 = math.atan2(enter[1] - centre[1], enter[0] - centre[0])
        pieces += [("line", cursor, enter), ("arc", tuple(centre), r, phi0, turn)]
        cursor = leave
    pieces.append(("line", cursor, pts[-1]))
    return _chain(kind, name, pieces)


def waypoint_path(
    points: ArrayLike, corner_radius: float = DEFAULT_CORNER_RADIUS, name: str = "waypoints"
) -> GeometricPath:
    """A polyline through ``points`` [m] ``(n, 2)``, interior corners rounded to ``corner_radius`` [m].

    The rounded path passes within ``r (1/cos(α/2) - 1)`` of an interior waypoint (turn angle ``α``) and through
    the first and last points exactly.
    """
    return _polyline(PathKind.WAYPOINTS, name, points, float(corner_radius))


def pick_and_place(start: Sequence[float] | np.ndarray = (0.0, 0.0), size: PickSize = DEFAULT_PICK) -> GeometricPath:
    """The forward stroke of a pick-and-place cycle from ``start`` [m]: up ``h`` (+Y), across ``w``, down ``h``.

    The two corners are quarter circles of radius ``size.r``; the return stroke is :meth:`GeometricPath.reversed`.
    """
    h, w, r = float(size.h), float(size.w), float(size.r)
    if not all(math.isfinite(x) and x > 0 for x in (h, w)):
        raise InputError(
            Phrase("pick-and-place rise and span must be positive lengths, got h={h}, w={w}", h=repr(h), w=repr(w))
        )
    if not (math.isfinite(r) and 0 < r <= h and 2 * r <= w):
        raise InputError(
            Phrase("the corner radius {r} mm must be above 0, at most h and at most w/2", r=fixed(r, "g", 1e3))
        )
    x, y = float(start[0]), float(start[1])
    pts = [(x, y), (x, y + h), (x + w, y + h), (x + w, y)]
    return _polyline(PathKind.PICK, "pick", pts, r)


def check_path(
    params: Params,
    path: GeometricPath,
    thresholds: SingularityThresholds = MOVE_LIMITS,
    arrangement: Arrangement = Arrangement.PERPENDICULAR,
) -> None:
    """Raise :class:`InputError` at the first point (every :data:`CHECK_STEP`) outside the valid region.

    Valid: reachable (eq. 4), ``0 <= d_i <= Δd`` and ``min_i |cos θ_i|``, ``|cos(θ1 + θ2)|`` (eqs. 11-12) at least
    the ``thresholds`` (for ``arrangement``: :func:`tpm_viz.paper.arrangement.classify`).
    """
    n = max(math.ceil(path.length / CHECK_STEP) + 1, 2)
    s = np.unique(np.concatenate([np.linspace(0.0, path.length, n), path.junctions]))
    p = path.evaluate(s)
    status = classify(arrangement, params, p, thresholds)
    bad = np.flatnonzero(status != PoseStatus.REGULAR)
    if bad.size:
        k = int(bad[0])
        raise InputError(
            Phrase(
                "the {name} path leaves the valid region at ({x}, {y}) mm ({along} mm along it): {why}; move or "
                "shrink the path",
                name=path.name,
                x=fixed(p[k, 0], ".1f", 1e3),
                y=fixed(p[k, 1], ".1f", 1e3),
                along=fixed(s[k], ".1f", 1e3),
                why=STATUS_WORDS[PoseStatus(int(status[k]))],
            )
        )


def _valid_centre(params: Params, thresholds: SingularityThresholds) -> np.ndarray:
    """Centroid [m] of the valid region on a 81 x 81 grid over ``[-l_a, l_a]²`` (for placing default paths)."""
    xs = np.linspace(-params.l_a, params.l_a, 81)
    grid = np.stack(np.meshgrid(xs, xs), -1).reshape(-1, 2)
    ok = classify(Arrangement.PERPENDICULAR, params, grid, thresholds) == PoseStatus.REGULAR
    if not np.any(ok):
        raise InputError(Phrase("the parameters leave no valid workspace: change the stroke or the lengths"))
    return grid[ok].mean(axis=0)


def default_pick(
    params: Params, size: PickSize | None = None, thresholds: SingularityThresholds = MOVE_LIMITS
) -> GeometricPath:
    """A pick-and-place stroke centred on the valid region of ``params`` (centroid of its regular poses).

    Without ``size``: :data:`DEFAULT_PICK`, shrunk by steps of 10 % (all three dimensions together) until it fits.
    With ``size``: exactly that size, or an :class:`InputError` naming the first point outside the valid region.
    """
    centre = _valid_centre(params, thresholds)
    if size is not None:
        path = pick_and_place((centre[0] - size.w / 2, centre[1] - size.h / 2), size)
        check_path(params, path, thresholds)
        return path
    for k in range(30):
        scale = 0.9**k
        size = PickSize(DEFAULT_PICK.h * scale, DEFAULT_PICK.w * scale, DEFAULT_PICK.r * scale)
        path = pick_and_place((centre[0] - size.w / 2, centre[1] - size.h / 2), size)
        try:
            check_path(params, path, thresholds)
        except InputError:
            continue
        return path
    raise InputError(Phrase("no pick-and-place cycle fits in the valid workspace of these parameters"))


def path_for(
    params: Params,
    kind: PathKind | str,
    points: ArrayLike | None = None,
    corner_radius: float | None = None,
    pick: PickSize | None = None,
) -> GeometricPath:
    """The checked path of ``kind``: ``points`` [m] ``(n, 2)`` for ``WAYPOINTS`` (for ``PICK``: its start corner,
    default centred); ``corner_radius`` [m] for waypoints; ``pick`` the pick-and-place size (default: fitted)."""
    try:
        kind = PathKind(kind)
    except ValueError:
        raise InputError(
            Phrase(
                "path kind must be one of {kinds}, got {got}",
                kinds=", ".join(k.value for k in PathKind),
                got=repr(kind),
            )
        ) from None
    radius = DEFAULT_CORNER_RADIUS if corner_radius is None else float(corner_radius)
    if kind is PathKind.LINE:
        path = line_path()
    elif kind is PathKind.CIRCLE:
        path = circle_path()
    elif kind is PathKind.PICK:
        if points is None:
            return default_pick(params, pick)
        path = pick_and_place(np.asarray(points, float).reshape(-1, 2)[0], pick or DEFAULT_PICK)
    else:
        if points is None:
            raise InputError(Phrase("a waypoint path needs its points"))
        path = waypoint_path(points, radius)
    check_path(params, path)
    return path
