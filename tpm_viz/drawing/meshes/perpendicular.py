"""Parts of the paper's perpendicular 2-PPa (rail 1 along X, rail 2 along Y), sized from a :class:`~tpm_viz.Params`.

Each part in its frame (:mod:`.base`): slider ``i`` at ``A_i = (d_i - a) e_i`` (eq. 1) carrying its pivots ``0`` and
``s e_j``, the square platform at ``P`` with the pivots ``B_i = P - b e_i`` and ``B_i + s e_j``. The rails and the
end-stops are fixed; :func:`tpm_viz.drawing.meshes.posed_parts` places everything at a pose.
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
    "platform_half_size",
    "platform_pin_offsets",
    "rail",
    "slider",
    "slider_pin_offsets",
]


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
    return box((lo, lo, -0.012), (hi, hi, 0.0))


def rail(params: Params, i: int) -> trimesh.Trimesh:
    """Rail ``i`` along ``e_i`` at the line of the joints ``A_i``, long enough for the slider at both ends."""
    along, across = _axes(i)
    lo, hi = np.zeros(3), np.zeros(3)
    lo[along], hi[along] = -params.a - SLIDER_LENGTH / 2 - 0.02, -params.a + params.stroke + SLIDER_LENGTH / 2 + 0.02
    lo[across], hi[across] = -0.011, 0.011
    lo[2], hi[2] = RAIL_Z
    return box(lo, hi)


def end_stops(params: Params, i: int) -> trimesh.Trimesh:
    """The two end-stops of rail ``i``: the slider touches them at ``d_i = 0`` and ``d_i = Δd``."""
    along, across = _axes(i)
    parts = []
    for face, sign in ((-params.a - SLIDER_LENGTH / 2, -1.0), (-params.a + params.stroke + SLIDER_LENGTH / 2, 1.0)):
        lo, hi = np.zeros(3), np.zeros(3)
        lo[along], hi[along] = sorted((face, face + sign * 0.012))
        lo[across], hi[across] = -0.026, 0.026
        lo[2], hi[2] = RAIL_Z[0], SLIDER_Z[1] + 0.004
        parts.append(box(lo, hi))
    return cast(trimesh.Trimesh, trimesh.util.concatenate(parts))


def slider(params: Params, i: int) -> trimesh.Trimesh:
    """Slider ``i`` in its frame at ``A_i``: a carriage on the rail carrying both link pivots (0 and ``s e_j``)."""
    along, across = _axes(i)
    lo, hi = np.zeros(3), np.zeros(3)
    lo[along], hi[along] = -SLIDER_LENGTH / 2, SLIDER_LENGTH / 2
    lo[across], hi[across] = -SLIDER_MARGIN, params.pivot_spacing + SLIDER_MARGIN
    lo[2], hi[2] = SLIDER_Z
    return box(lo, hi)


def slider_pin_offsets(params: Params, i: int) -> np.ndarray:
    """Pivot positions on slider ``i`` relative to ``A_i`` [m], shape (2, 3): ``0`` and ``s e_j``."""
    out = np.zeros((2, 3))
    out[1, 1 - i] = params.pivot_spacing
    return out


def platform_half_size(params: Params) -> float:
    """Half the side of the square platform [m]: it covers all four platform-side pivots."""
    return max(params.b, params.pivot_spacing) + 0.018


def platform(params: Params) -> trimesh.Trimesh:
    """The square platform in its frame at ``P``."""
    h = platform_half_size(params)
    return box((-h, -h, PLATFORM_Z[0]), (h, h, PLATFORM_Z[1]))


def platform_pin_offsets(params: Params) -> np.ndarray:
    """Platform-side pivots relative to ``P`` [m], shape (4, 3): ``B_i = P - b e_i`` and ``B_i + s e_j``."""
    b, s = params.b, params.pivot_spacing
    return np.array([[-b, 0.0, 0.0], [-b, s, 0.0], [0.0, -b, 0.0], [s, -b, 0.0]])
