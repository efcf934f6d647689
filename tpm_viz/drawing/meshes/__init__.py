"""Parametric trimesh parts of both 2-PPa arrangements, sized from a :class:`~tpm_viz.Params` (metres, Z up).

One module per arrangement over a shared base: :mod:`.base` (the heights, the link, pin and tool marker both
arrangements use, the scene's line and region helpers, the placing of parts at a pose), :mod:`.perpendicular` (the
paper's mechanism: rail 1 along X, rail 2 along Y) and :mod:`.parallel` (both rails on the X axis,
``docs/parallel.md``). The names of :mod:`.base` and :mod:`.perpendicular` are also this package's (``meshes.rail``
is the perpendicular rail, as the live mechanism draws it); :func:`posed_parts` places either arrangement's parts at a
platform position. Only trimesh and numpy here; the browser app turns these meshes into scene nodes once per
parameter set.
"""

from __future__ import annotations

import trimesh
from numpy.typing import ArrayLike

from tpm_viz.core.params import Params
from tpm_viz.drawing.meshes import base
from tpm_viz.drawing.meshes import parallel as parallel
from tpm_viz.drawing.meshes import perpendicular as perpendicular
from tpm_viz.drawing.meshes.base import (
    LINK_NAMES,
    LINK_Z,
    PIN_Z,
    PLATFORM_Z,
    RAIL_Z,
    SLIDER_LENGTH,
    SLIDER_MARGIN,
    SLIDER_Z,
    Parts,
    circle_segments,
    link,
    link_instances,
    pin,
    placed,
    polyline_segments,
    region_mesh,
    tool_marker,
)
from tpm_viz.drawing.meshes.perpendicular import (
    base_extent,
    base_plate,
    end_stops,
    platform,
    platform_half_size,
    platform_pin_offsets,
    rail,
    slider,
    slider_pin_offsets,
)
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

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
    "base_extent",
    "base_plate",
    "circle_segments",
    "end_stops",
    "link",
    "link_instances",
    "parallel",
    "parts_of",
    "perpendicular",
    "pin",
    "placed",
    "platform",
    "platform_half_size",
    "platform_pin_offsets",
    "polyline_segments",
    "posed_parts",
    "rail",
    "region_mesh",
    "slider",
    "slider_pin_offsets",
    "tool_marker",
]


def parts_of(arrangement: Arrangement) -> Parts:
    """The module of ``arrangement``'s own parts (:mod:`.perpendicular` or :mod:`.parallel`)."""
    return parallel if Arrangement.parse(arrangement) is Arrangement.PARALLEL else perpendicular


def posed_parts(
    arrangement: Arrangement, params: Params, p: ArrayLike, d: ArrayLike | None = None
) -> dict[str, trimesh.Trimesh]:
    """Every part of ``arrangement`` placed at platform position ``p`` [m] (working mode unless ``d``), world
    coordinates (:func:`.base.posed_parts`). Raises as the arrangement's inverse kinematics."""
    return base.posed_parts(parts_of(arrangement), params, arr.mechanism_pose(arrangement, params, p, d))
