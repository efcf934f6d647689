"""Parametric trimesh parts of the 2-PPa TPM, sized from a :class:`~tpm_viz.Params` (metres, Z up).

The mechanism is planar (the XY plane of the paper's frame OXY); parts are stacked in Z only so that they never
intersect visually. Each moving part is built in its own frame so that a drawing needs only its pose:

- sliders in a frame at the slider joint ``A_i = (d_i - a) e_i`` (they translate);
- links along their local +x from the slider-side pivot (they rotate about Z, see :func:`link_instances`);
- the platform (and its pins) in a frame at ``P`` (it translates).

Only trimesh and numpy here; the browser app turns these meshes into scene nodes once per parameter set.
"""

from __future__ import annotations

from typing import cast

import numpy as np
import trimesh

from tpm_viz.core.params import Params
from tpm_viz.paper.kinematics import MechanismPose

__all__ = [
    "LINK_Z",
    "base_plate",
    "circle_segments",
    "end_stops",
    "link",
    "link_instances",
    "pin",
    "platform",
    "platform_pin_offsets",
    "polyline_segments",
    "rail",
    "region_mesh",
    "slider",
    "slider_pin_offsets",
    "tool_marker",
]

RAIL_Z = (0.0, 0.012)  # m, bottom and top of the rails
SLIDER_Z = (0.012, 0.032)  # m
LINK_Z = (0.042, 0.056)  # m, centre height of the links of leg 1 and leg 2 (they cross without touching)
LINK_THICKNESS = 0.008  # m
LINK_WIDTH = 0.016  # m
PLATFORM_Z = (0.066, 0.076)  # m
PIN_Z = (0.012, 0.082)  # m
PIN_RADIUS = 0.005  # m
SLIDER_LENGTH = 0.05  # m, along the rail
SLIDER_MARGIN = 0.022  # m, beyond the outer pivots across the rail


def _box(lo, hi) -> trimesh.Trimesh:
    """Axis-aligned box between corners ``lo`` and ``hi`` (3,) [m]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2))


def _axes(i: int) -> tuple[int, int]:
    """World axis index along rail ``i`` (0 or 1) and across it."""
    return i, 1 - i


def base_extent(params: Params) -> tuple[float, float]:
    """Lower and upper corner coordinate of the square base plate [m] (same in x and y)."""
    half = platform_half_size(params)
    return -params.a - SLIDER_LENGTH - 0.03, params.l_a + half + 0.03


def base_plate(params: Params) -> trimesh.Trimesh:
    """A square base plate under the whole mechanism, top face at z = 0."""
    lo, hi = base_extent(params)
    return _box((lo, lo, -0.012), (hi, hi, 0.0))


def rail(params: Params, i: int) -> trimesh.Trimesh:
    """Rail ``i`` along ``e_i`` at the line of the joints ``A_i``, long enough for the slider at both ends."""
    along, across = _axes(i)
    lo, hi = np.zeros(3), np.zeros(3)
    lo[along], hi[along] = -params.a - SLIDER_LENGTH / 2 - 0.02, -params.a + params.stroke + SLIDER_LENGTH / 2 + 0.02
    lo[across], hi[across] = -0.011, 0.011
    lo[2], hi[2] = RAIL_Z
    return _box(lo, hi)


def end_stops(params: Params, i: int) -> trimesh.Trimesh:
    """The two end-stops of rail ``i``: the slider touches them at ``d_i = 0`` and ``d_i = Δd``."""
    along, across = _axes(i)
    parts = []
    for face, sign in ((-params.a - SLIDER_LENGTH / 2, -1.0), (-params.a + params.stroke + SLIDER_LENGTH / 2, 1.0)):
        lo, hi = np.zeros(3), np.zeros(3)
        lo[along], hi[along] = sorted((face, face + sign * 0.012))
        lo[across], hi[across] = -0.026, 0.026
        lo[2], hi[2] = RAIL_Z[0], SLIDER_Z[1] + 0.004
        parts.append(_box(lo, hi))
    return cast(trimesh.Trimesh, trimesh.util.concatenate(parts))


def slider(params: Params, i: int) -> trimesh.Trimesh:
    """Slider ``i`` in its frame at ``A_i``: a carriage on the rail carrying both link pivots (0 and ``s e_j``)."""
    along, across = _axes(i)
    lo, hi = np.zeros(3), np.zeros(3)
    lo[along], hi[along] = -SLIDER_LENGTH / 2, SLIDER_LENGTH / 2
    lo[across], hi[across] = -SLIDER_MARGIN, params.pivot_spacing + SLIDER_MARGIN
    lo[2], hi[2] = SLIDER_Z
    return _box(lo, hi)


def slider_pin_offsets(params: Params, i: int) -> np.ndarray:
    """Pivot positions on slider ``i`` relative to ``A_i`` [m], shape (2, 3): ``0`` and ``s e_j``."""
    out = np.zeros((2, 3))
    out[1, 1 - i] = params.pivot_spacing
    return out


def link(params: Params) -> trimesh.Trimesh:
    """One parallelogram link along local +x from 0 to ``l_a``, rounded ends, centred on z = 0."""
    bar = _box((0.0, -LINK_WIDTH / 2, -LINK_THICKNESS / 2), (params.l_a, LINK_WIDTH / 2, LINK_THICKNESS / 2))
    ends = [
        trimesh.creation.cylinder(
            radius=LINK_WIDTH / 2,
            height=LINK_THICKNESS,
            sections=24,
            transform=trimesh.transformations.translation_matrix((x, 0.0, 0.0)),
        )
        for x in (0.0, params.l_a)
    ]
    return cast(trimesh.Trimesh, trimesh.util.concatenate([bar, *ends]))


def link_instances(pose: MechanismPose) -> tuple[np.ndarray, np.ndarray]:
    """World positions (4, 3) and orientations ``wxyz`` (4, 4) of the four links (leg-major order).

    A link's frame sits at its slider-side pivot with +x towards its platform-side pivot.
    """
    ends = pose.links.reshape(4, 2, 2)  # (link, end, xy)
    delta = ends[:, 1] - ends[:, 0]
    half = np.arctan2(delta[:, 1], delta[:, 0]) / 2.0
    wxyz = np.zeros((4, 4))
    wxyz[:, 0], wxyz[:, 3] = np.cos(half), np.sin(half)
    z = np.repeat(np.asarray(LINK_Z), 2)
    return np.column_stack([ends[:, 0], z]), wxyz


def pin() -> trimesh.Trimesh:
    """A vertical pivot pin (world z from ``PIN_Z[0]`` to ``PIN_Z[1]``), its axis through the local origin."""
    height = PIN_Z[1] - PIN_Z[0]
    return trimesh.creation.cylinder(
        radius=PIN_RADIUS,
        height=height,
        sections=16,
        transform=trimesh.transformations.translation_matrix((0.0, 0.0, PIN_Z[0] + height / 2)),
    )


def platform_half_size(params: Params) -> float:
    """Half the side of the square platform [m]: it covers all four platform-side pivots."""
    return max(params.b, params.pivot_spacing) + 0.018


def platform(params: Params) -> trimesh.Trimesh:
    """The square platform in its frame at ``P``."""
    h = platform_half_size(params)
    return _box((-h, -h, PLATFORM_Z[0]), (h, h, PLATFORM_Z[1]))


def platform_pin_offsets(params: Params) -> np.ndarray:
    """Platform-side pivots relative to ``P`` [m], shape (4, 3): ``B_i = P - b e_i`` and ``B_i + s e_j``."""
    b, s = params.b, params.pivot_spacing
    return np.array([[-b, 0.0, 0.0], [-b, s, 0.0], [0.0, -b, 0.0], [s, -b, 0.0]])


def tool_marker() -> trimesh.Trimesh:
    """A small disc on top of the platform marking the point ``P``."""
    return trimesh.creation.cylinder(
        radius=0.012,
        height=0.008,
        sections=32,
        transform=trimesh.transformations.translation_matrix((0.0, 0.0, PLATFORM_Z[1] + 0.004)),
    )


def circle_segments(radius: float, z: float, n: int = 96) -> np.ndarray:
    """A circle of ``radius`` [m] about the local origin at height ``z``, as ``(n, 2, 3)`` line segments."""
    phi = np.linspace(0.0, 2.0 * np.pi, n + 1)
    pts = np.column_stack([radius * np.cos(phi), radius * np.sin(phi), np.full(n + 1, z)])
    return np.stack([pts[:-1], pts[1:]], axis=1)


def polyline_segments(curves, z: float) -> np.ndarray:
    """Planar polylines (each ``(m, 2)`` [m]) as one ``(k, 2, 3)`` array of segments at height ``z``."""
    segs = [np.stack([c[:-1], c[1:]], axis=1) for c in curves if len(c) >= 2]
    if not segs:
        return np.zeros((0, 2, 3))
    xy = np.concatenate(segs)
    return np.concatenate([xy, np.full((*xy.shape[:2], 1), z)], axis=-1)


def region_mesh(mask: np.ndarray, xs: np.ndarray, ys: np.ndarray, z: float) -> trimesh.Trimesh | None:
    """A flat mesh at height ``z`` covering the grid cells where ``mask`` is true (e.g. the workspace).

    ``mask`` has shape ``(ny, nx)`` on the grid points ``xs`` (nx,), ``ys`` (ny,) [m]; each point owns the
    cell around it (half a spacing each way). Returns None if the mask is empty.
    """
    mask = np.asarray(mask, dtype=bool)
    if not mask.any():
        return None
    hx, hy = (xs[1] - xs[0]) / 2, (ys[1] - ys[0]) / 2
    gx = np.concatenate([xs - hx, [xs[-1] + hx]])
    gy = np.concatenate([ys - hy, [ys[-1] + hy]])
    vx, vy = np.meshgrid(gx, gy)  # (ny + 1, nx + 1) cell corners
    vertices = np.column_stack([vx.ravel(), vy.ravel(), np.full(vx.size, z)])
    j, i = np.nonzero(mask)  # row (y) and column (x) of each cell
    stride = len(gx)
    v00 = j * stride + i
    v10, v01, v11 = v00 + 1, v00 + stride, v00 + stride + 1
    faces = np.concatenate([np.column_stack([v00, v10, v11]), np.column_stack([v00, v11, v01])])
    mesh = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    mesh.remove_unreferenced_vertices()
    return mesh
