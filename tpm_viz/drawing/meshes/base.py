"""The parts both arrangements of the 2-PPa share, and how a mechanism's parts are placed at a pose (metres, Z up).

The mechanism is planar (the XY plane of the paper's frame OXY); parts are stacked in Z only so that they never
intersect visually (the heights below). Each moving part is built in its own frame so that a drawing needs only its
pose: sliders in a frame at the slider joint ``A_i`` (they translate), links along their local +x from the
slider-side pivot (they rotate about Z, :func:`link_instances`), the platform (and its pins) in a frame at ``P`` (it
translates). Here: the link, the pin and the tool marker of both arrangements, the scene's line and region helpers,
and :func:`posed_parts`, which places an arrangement's :class:`Parts` (:mod:`.perpendicular`, :mod:`.parallel`) at a
:class:`~tpm_viz.paper.legs.MechanismPose`.
"""

from __future__ import annotations

from typing import Protocol, cast

import numpy as np
import trimesh
from numpy.typing import ArrayLike

from tpm_viz.core.params import Params
from tpm_viz.paper.legs import MechanismPose

__all__ = [
    "LINK_NAMES",
    "LINK_Z",
    "PIN_Z",
    "PLATFORM_Z",
    "RAIL_Z",
    "SLIDER_LENGTH",
    "SLIDER_MARGIN",
    "SLIDER_Z",
    "Parts",
    "box",
    "circle_segments",
    "link",
    "link_instances",
    "pin",
    "placed",
    "polyline_segments",
    "posed_parts",
    "region_mesh",
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
LINK_NAMES = ("link1_0", "link1_1", "link2_0", "link2_1")
"""The four links of :func:`posed_parts`, leg-major (as :func:`link_instances` orders them)."""


class Parts(Protocol):
    """An arrangement's own parts, each in its frame (a module: :mod:`.perpendicular`, :mod:`.parallel`)."""

    def base_plate(self, params: Params) -> trimesh.Trimesh: ...
    def rail(self, params: Params, i: int) -> trimesh.Trimesh: ...
    def end_stops(self, params: Params, i: int) -> trimesh.Trimesh: ...
    def slider(self, params: Params, i: int) -> trimesh.Trimesh: ...
    def slider_pin_offsets(self, params: Params, i: int) -> np.ndarray: ...
    def platform(self, params: Params) -> trimesh.Trimesh: ...
    def platform_pin_offsets(self, params: Params) -> np.ndarray: ...


def box(lo: ArrayLike, hi: ArrayLike) -> trimesh.Trimesh:
    """Axis-aligned box between corners ``lo`` and ``hi`` (3,) [m]."""
    lo, hi = np.asarray(lo, float), np.asarray(hi, float)
    return trimesh.creation.box(extents=hi - lo, transform=trimesh.transformations.translation_matrix((lo + hi) / 2))


def link(params: Params) -> trimesh.Trimesh:
    """One parallelogram link along local +x from 0 to ``l_a``, rounded ends, centred on z = 0."""
    bar = box((0.0, -LINK_WIDTH / 2, -LINK_THICKNESS / 2), (params.l_a, LINK_WIDTH / 2, LINK_THICKNESS / 2))
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


def tool_marker() -> trimesh.Trimesh:
    """A small disc on top of the platform marking the point ``P``."""
    return trimesh.creation.cylinder(
        radius=0.012,
        height=0.008,
        sections=32,
        transform=trimesh.transformations.translation_matrix((0.0, 0.0, PLATFORM_Z[1] + 0.004)),
    )


def placed(mesh: trimesh.Trimesh, position: ArrayLike, wxyz: ArrayLike = (1.0, 0.0, 0.0, 0.0)) -> trimesh.Trimesh:
    """A copy of ``mesh`` turned by the quaternion ``wxyz`` and moved to ``position`` (3,) [m]."""
    matrix = trimesh.transformations.quaternion_matrix(list(np.asarray(wxyz, dtype=float)))
    matrix[:3, 3] = position
    out = mesh.copy()
    out.apply_transform(matrix)
    return out


def posed_parts(parts: Parts, params: Params, pose: MechanismPose) -> dict[str, trimesh.Trimesh]:
    """Every part of an arrangement placed at ``pose`` (world coordinates, metres): ``base, rail1, rail2, stops1,
    stops2, slider1, slider2, link1_0, link1_1, link2_0, link2_1, platform, pins, tool``; the sliders and their pins
    at ``A_i``, the links by :func:`link_instances`, the platform, its pins and the tool at ``P``."""
    out: dict[str, trimesh.Trimesh] = {"base": parts.base_plate(params)}
    pins = []
    for i in (0, 1):
        a_i = np.array([*pose.A[i], 0.0])
        out[f"rail{i + 1}"] = parts.rail(params, i)
        out[f"stops{i + 1}"] = parts.end_stops(params, i)
        out[f"slider{i + 1}"] = placed(parts.slider(params, i), a_i)
        pins += [placed(pin(), a_i + offset) for offset in parts.slider_pin_offsets(params, i)]
    positions, quats = link_instances(pose)
    for k, name in enumerate(LINK_NAMES):
        out[name] = placed(link(params), positions[k], quats[k])
    centre = np.array([*pose.p, 0.0])
    out["platform"] = placed(parts.platform(params), centre)
    pins += [placed(pin(), centre + offset) for offset in parts.platform_pin_offsets(params)]
    out["pins"] = cast(trimesh.Trimesh, trimesh.util.concatenate(pins))
    out["tool"] = placed(tool_marker(), centre)
    return out


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
