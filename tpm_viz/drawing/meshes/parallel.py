"""Parts of the parallel 2-PPa (both rails on the X axis, facing each other, ``docs/parallel.md``), metres, Z up.

The same part vocabulary, heights and frames as :mod:`.perpendicular`, so that :func:`.base.posed_parts` places
them alike: sliders in a frame at ``A_i`` (eq. P1: ``A_1 = (d_1 - a, 0)``, ``A_2 = (a - d_2, 0)``), links along
their local +x from the slider-side pivot (:func:`.base.link`, :func:`.base.link_instances`), the platform in a
frame at ``P`` (``B_1 = P - (b, 0)``, ``B_2 = P + (b, 0)``). The second link of each parallelogram is offset by the
pivot spacing ``s`` along +Y on both legs.
"""

from __future__ import annotations

from typing import cast

import numpy as np
import trimesh

from tpm_viz.core.params import Params
from tpm_viz.drawing.meshes.base import PLATFORM_Z, RAIL_Z, SLIDER_LENGTH, SLIDER_MARGIN, SLIDER_Z, box

__all__ = [
    "base_extent",
    "base_plate",
    "end_stops",
    "platform",
    "platform_pin_offsets",
    "rail",
    "rail_span",
    "slider",
    "slider_pin_offsets",
]

_PLATFORM_MARGIN = 0.018  # m, beyond the platform-side pivots
_RAIL_OVERHANG = 0.02  # m, beyond the slider at either end of the stroke


def rail_span(params: Params, i: int) -> tuple[float, float]:
    """X range [m] of the joint ``A_i`` over the stroke: ``[-a, Δd - a]`` (rail 1), ``[a - Δd, a]`` (rail 2)."""
    a, s = params.a, params.stroke
    return (-a, s - a) if i == 0 else (a - s, a)


def rail(params: Params, i: int) -> trimesh.Trimesh:
    """Rail ``i`` on the X axis, long enough for the slider at both ends of its stroke."""
    lo, hi = rail_span(params, i)
    reach = SLIDER_LENGTH / 2 + _RAIL_OVERHANG
    return box((lo - reach, -0.011, RAIL_Z[0]), (hi + reach, 0.011, RAIL_Z[1]))


def end_stops(params: Params, i: int) -> trimesh.Trimesh:
    """The two end-stops of rail ``i``: the slider touches them at ``d_i = 0`` and ``d_i = Δd``."""
    lo, hi = rail_span(params, i)
    parts = []
    for face, sign in ((lo - SLIDER_LENGTH / 2, -1.0), (hi + SLIDER_LENGTH / 2, 1.0)):
        x0, x1 = sorted((face, face + sign * 0.012))
        parts.append(box((x0, -0.026, RAIL_Z[0]), (x1, 0.026, SLIDER_Z[1] + 0.004)))
    return cast(trimesh.Trimesh, trimesh.util.concatenate(parts))


def slider(params: Params, i: int) -> trimesh.Trimesh:
    """Slider ``i`` in its frame at ``A_i``: a carriage carrying both link pivots (``0`` and ``s e_2``)."""
    half = SLIDER_LENGTH / 2
    return box((-half, -SLIDER_MARGIN, SLIDER_Z[0]), (half, params.pivot_spacing + SLIDER_MARGIN, SLIDER_Z[1]))


def slider_pin_offsets(params: Params, i: int) -> np.ndarray:
    """Pivot positions on slider ``i`` relative to ``A_i`` [m], shape (2, 3): ``0`` and ``s e_2``."""
    return np.array([[0.0, 0.0, 0.0], [0.0, params.pivot_spacing, 0.0]])


def platform_pin_offsets(params: Params) -> np.ndarray:
    """Platform-side pivots relative to ``P`` [m], shape (4, 3): ``B_1 = P - b e_1``, ``B_1 + s e_2``,
    ``B_2 = P + b e_1``, ``B_2 + s e_2`` (leg-major, as :func:`link_instances` orders the links)."""
    b, s = params.b, params.pivot_spacing
    return np.array([[-b, 0.0, 0.0], [-b, s, 0.0], [b, 0.0, 0.0], [b, s, 0.0]])


def platform(params: Params) -> trimesh.Trimesh:
    """The platform in its frame at ``P``: a plate covering the four pivots (wide along X, the legs' axis)."""
    m, hx = _PLATFORM_MARGIN, params.b + _PLATFORM_MARGIN
    return box((-hx, -m, PLATFORM_Z[0]), (hx, params.pivot_spacing + m, PLATFORM_Z[1]))


def base_extent(params: Params) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper XY corners [m] of the base plate: both rails along X, the legs' reach along Y."""
    x = max(abs(v) for i in (0, 1) for v in rail_span(params, i)) + SLIDER_LENGTH + 0.03
    y_hi = params.l_a + params.pivot_spacing + _PLATFORM_MARGIN + 0.03
    return np.array([-x, -0.05]), np.array([x, y_hi])


def base_plate(params: Params) -> trimesh.Trimesh:
    """A rectangular base plate under the mechanism, top face at z = 0."""
    lo, hi = base_extent(params)
    return box((lo[0], lo[1], -0.012), (hi[0], hi[1], 0.0))
