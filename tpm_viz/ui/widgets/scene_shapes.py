"""The geometry of a mechanism's drawing (:mod:`.scene`), made once per parameter set and shared by every drawing
of it: the shared mechanism and every tab's own copy (a reconnect storm draws 100 copies of the same mechanism).

Every array returned is read-only (the drawings hand them to viser, which copies what it sends).
"""

from __future__ import annotations

import functools

import numpy as np

from tpm_viz.app.overlays import cached_map
from tpm_viz.core.params import Params
from tpm_viz.drawing import meshes
from tpm_viz.paper.workspace import direct_singularity_locus, inverse_singularity_loci

__all__ = ["LOCI_Z", "circle", "floor", "made", "part"]

LOCI_Z = 0.0008
"""[m] Height of the floor overlay (the workspace region at half of it, the leg circles 1 mm above)."""


@functools.lru_cache(maxsize=128)
def made(make, params: Params, *args):
    """``make(params, *args)`` of :mod:`tpm_viz.drawing.meshes`, made once per mechanism (a reconnect storm: 100 own
    copies)."""
    return make(params, *args)


@functools.cache
def part(make):
    """A part that is the same for every mechanism (:func:`tpm_viz.drawing.meshes.pin`, the tool marker), made once."""
    return make()


@functools.lru_cache(maxsize=32)
def floor(params: Params):
    """The floor overlay's geometry [m] (:meth:`.scene.MechanismScene._loci`), computed once per parameter set: the
    workspace region's mesh (None if the stroke holds no pose) and the segments of the inverse and direct loci."""
    ws = cached_map(params, 100)  # once per parameter set for all tabs
    region = meshes.region_mesh(ws.in_stroke, ws.xs, ws.ys, LOCI_Z / 2)
    lines = {
        "inverse": meshes.polyline_segments(inverse_singularity_loci(params), LOCI_Z),
        "direct": meshes.polyline_segments(direct_singularity_locus(params), LOCI_Z),
    }
    for segments in lines.values():
        segments.setflags(write=False)
    return region, lines


@functools.lru_cache(maxsize=32)
def circle(radius: float) -> np.ndarray:
    """The segments of a leg's constraint circle of ``radius`` [m] about the origin (read-only)."""
    segments = meshes.circle_segments(radius, LOCI_Z + 0.001)
    segments.setflags(write=False)
    return segments
