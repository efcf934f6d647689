"""Camera framing: where to put a pinhole camera so that a set of points fills the free part of a canvas.

A browser tab shows the 3D scene in a canvas of aspect ``width / height``; part of the canvas may be covered (a
floating box of live numbers, say). :func:`frame_points` keeps the viewing *direction* (the camera looks along
``-view_from``, the world ``up`` is up on the screen) and returns the camera position and look-at point [m] that
put every point inside the free rectangle, less a margin, with the camera as close as it can be: the points touch
the free rectangle (less its margin) on one axis and are centred on the other.

The maths. With the camera's right, image-up and forward unit vectors ``r, u, f`` and ``C = a r + b u + c f``, a
point ``X`` is seen at the normalised device coordinates ``x = r·(X - C) / (f·(X - C) tan(fov_x / 2))`` and
``y = u·(X - C) / (f·(X - C) tan(fov_y / 2))`` (``tan(fov_x / 2) = aspect tan(fov_y / 2)``). Keeping ``x`` in
``[x0, x1]`` for every point is two linear inequalities in ``(a, c)``; their sum bounds ``c`` alone. The same holds
for ``y`` and ``(b, c)``. The closest camera takes the smallest of the two bounds on ``c`` and of the one that keeps
every point at least ``near`` in front of it; ``a`` and ``b`` are then the middles of their feasible intervals. Closed
form, no iteration.

Where the panel is (:mod:`tpm_viz.ui.look`): on a wide screen it is docked beside the canvas (viser's dock shrinks
the canvas), on a phone the canvas is the part of the screen above the panel's sheet; either way the panel covers
none of the canvas, and the camera frames the mechanism in the whole canvas (:func:`free_region`). In presentation
mode a box of banner and forces may float over the bottom of the canvas (when the panel is collapsed): its band is
kept free. The server knows a tab's canvas only by its aspect ratio (its size is in device pixels, whose ratio to
CSS pixels is the browser's business), which is all the framing needs.

Pure numpy; SI units (metres, radians); canvas positions in fractions of the canvas.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import ArrayLike

__all__ = [
    "FULL",
    "LIVE_BAND",
    "MARGIN",
    "VIEW_FROM",
    "Framing",
    "Region",
    "box_corners",
    "frame_box",
    "frame_points",
    "free_region",
]


@dataclass(frozen=True)
class Region:
    """A rectangle of the canvas, in fractions of its width and height, from the top-left corner (y down)."""

    left: float = 0.0
    top: float = 0.0
    right: float = 1.0
    bottom: float = 1.0

    def __post_init__(self) -> None:
        values = (self.left, self.top, self.right, self.bottom)
        if not all(math.isfinite(v) for v in values):
            raise ValueError("region bounds must be finite")
        if not (0.0 <= self.left < self.right <= 1.0 and 0.0 <= self.top < self.bottom <= 1.0):
            raise ValueError(f"not a region of the canvas: {values}")


FULL = Region()
"""The whole canvas."""


@dataclass(frozen=True)
class Framing:
    """A camera pose: ``position`` and ``look_at`` [m] (world frame), for a vertical ``fov`` [rad] and ``aspect``."""

    position: np.ndarray
    look_at: np.ndarray
    fov: float
    aspect: float

    @property
    def distance(self) -> float:
        """Distance [m] from the camera to its look-at point."""
        return float(np.linalg.norm(self.look_at - self.position))


def box_corners(lo: ArrayLike, hi: ArrayLike) -> np.ndarray:
    """The 8 corners (8 x 3) [m] of the axis-aligned box with opposite corners ``lo`` and ``hi`` (3-vectors)."""
    lo, hi = np.asarray(lo, dtype=float), np.asarray(hi, dtype=float)
    pick = np.array([[(k >> axis) & 1 for axis in range(3)] for k in range(8)], dtype=bool)
    return np.where(pick, hi, lo)


def _unit(v: np.ndarray, what: str) -> np.ndarray:
    norm = float(np.linalg.norm(v))
    if not math.isfinite(norm) or norm < 1e-12:
        raise ValueError(f"{what} must be a finite, non-zero vector")
    return v / norm


def frame_points(
    points: ArrayLike,
    view_from: ArrayLike,
    fov: float,
    aspect: float,
    free: Region = FULL,
    margin: float = 0.05,
    up: ArrayLike = (0.0, 0.0, 1.0),
    near: float = 0.01,
) -> Framing:
    """The closest camera, looking along ``-view_from``, that shows every point inside ``free`` less ``margin``.

    ``points``: (N, 3) [m]; ``view_from``: a direction [-] from the scene towards the camera (not parallel to
    ``up``); ``fov``: vertical field of view [rad], in (0, π); ``aspect``: canvas width / height; ``free``: the part
    of the canvas the points must stay in; ``margin``: the fraction of the free rectangle's width and height kept
    empty on each side, in [0, 0.45]; ``near`` [m]: the least depth of a point in front of the camera (a point
    cloud whose nearest point hides the others behind it would draw the camera onto it). The look-at point lies
    on the optical axis at the depth of the centre of the points' bounding box (the point the camera orbits about).
    Raises ``ValueError`` for non-finite or out-of-range input.
    """
    pts = np.asarray(points, dtype=float).reshape(-1, 3)
    if len(pts) == 0 or not np.all(np.isfinite(pts)):
        raise ValueError("frame_points needs at least one finite point")
    if not (math.isfinite(fov) and 0.0 < fov < math.pi):
        raise ValueError(f"vertical field of view out of range: {fov}")
    if not (math.isfinite(aspect) and aspect > 0.0):
        raise ValueError(f"aspect ratio out of range: {aspect}")
    if not (math.isfinite(margin) and 0.0 <= margin <= 0.45):
        raise ValueError(f"margin out of range: {margin}")
    if not (math.isfinite(near) and near > 0.0):
        raise ValueError(f"near distance out of range: {near}")
    forward = -_unit(np.asarray(view_from, dtype=float), "view_from")
    right = _unit(np.cross(forward, np.asarray(up, dtype=float)), "view_from x up")
    image_up = np.cross(right, forward)
    ty = math.tan(fov / 2.0)
    tx = aspect * ty
    # The free rectangle, less its margin, in normalised device coordinates (x right, y up, both in [-1, 1]).
    w, h = free.right - free.left, free.bottom - free.top
    x0 = 2.0 * (free.left + margin * w) - 1.0
    x1 = 2.0 * (free.right - margin * w) - 1.0
    y0 = 1.0 - 2.0 * (free.bottom - margin * h)
    y1 = 1.0 - 2.0 * (free.top + margin * h)
    pr, pu, pf = pts @ right, pts @ image_up, pts @ forward
    c_best = float(np.min(pf)) - near
    bounds = []
    for coord, lo_slope, hi_slope in ((pr, x0 * tx, x1 * tx), (pu, y0 * ty, y1 * ty)):
        m_lo = float(np.min(coord - lo_slope * pf))  # lateral - lo_slope c <= m_lo
        m_hi = float(np.min(hi_slope * pf - coord))  # -lateral + hi_slope c <= m_hi
        c_best = min(c_best, (m_lo + m_hi) / (hi_slope - lo_slope))
        bounds.append((lo_slope, hi_slope, m_lo, m_hi))
    lateral = []
    for lo_slope, hi_slope, m_lo, m_hi in bounds:
        lowest, highest = hi_slope * c_best - m_hi, m_lo + lo_slope * c_best
        lateral.append((lowest + highest) / 2.0)
    position = lateral[0] * right + lateral[1] * image_up + c_best * forward
    centre = (pts.min(axis=0) + pts.max(axis=0)) / 2.0
    depth = max(float(forward @ (centre - position)), 1e-6)
    return Framing(position=position, look_at=position + depth * forward, fov=float(fov), aspect=float(aspect))


# -- what the tab's canvas leaves free ------------------------------------------------------------------------------
VIEW_FROM = (0.0, -0.36, 0.7)
"""The default viewing direction [-], from the scene towards the camera: from the front (-y), about 63 degrees
above the floor (the direction of :func:`tpm_viz.ui.scene.camera_pose`)."""
MARGIN = 0.04
"""Fraction of the free rectangle's width and height kept empty on each side of the framed mechanism."""
LIVE_BAND = 0.3
"""Presentation mode: the bottom band of the canvas [fraction of its height] kept for the box of banner and forces
that shows when the panel is collapsed (its style sheet caps its height at :data:`LIVE_BAND` less a gap, in
fractions of the window height, which is the canvas height)."""


def free_region(presentation: bool = False) -> Region:
    """The part of a tab's canvas the mechanism is framed in: all of it (the panel is docked beside the canvas on a
    wide screen and sits under it on a phone, so it covers none of it), less the bottom :data:`LIVE_BAND` in
    presentation mode."""
    return Region(bottom=1.0 - LIVE_BAND) if presentation else FULL


def frame_box(
    lo: ArrayLike,
    hi: ArrayLike,
    fov: float,
    aspect: float,
    presentation: bool = False,
    view_from: ArrayLike = VIEW_FROM,
) -> Framing:
    """The closest camera, looking along ``-view_from``, that shows the whole axis-aligned box ``lo``-``hi`` [m]
    (the mechanism's extreme points) inside :func:`free_region` less :data:`MARGIN`, on a canvas of ``aspect``
    (width / height) with a vertical field of view ``fov`` [rad]."""
    return frame_points(box_corners(lo, hi), view_from, fov, aspect, free=free_region(presentation), margin=MARGIN)
