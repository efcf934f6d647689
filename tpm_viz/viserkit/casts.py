"""viser's two per-property checks, without numpy's per-call overhead (the ``casts`` patch, ``PATCHES.md`` entry 12).

Every scene node viser makes sets its orientation and position (:func:`set_pose_vector`: "unchanged?" asked of
``np.allclose`` on 3-4 numbers), and every property write casts its value by its type hint
(:func:`cast_value`: viser builds four ``npt.NDArray[...]`` aliases per call to compare the hint with). Both are the
same arithmetic as viser's, done on plain floats and on aliases built once: a returning tab's own copy makes ~40
nodes and its panel ~400 property writes (``benchmarks/bench_reconnect.py``).

The replacements in :mod:`.patches` call these for a handle of a registered server only; any other handle gets
viser's own functions (kept in :data:`VISER`).
"""

from __future__ import annotations

from collections.abc import Callable
from math import isfinite
from typing import Any

import numpy as np
import numpy.typing as npt
from viser import _assignable_props_api, _scene_api, _scene_handles

__all__ = ["VISER", "cast_value", "cast_vector", "close", "missing", "set_pose_vector"]

VISER: dict[str, Any] = {
    "pose": getattr(_scene_handles, "_set_pose_vector", None),
    "cast": getattr(_assignable_props_api.AssignablePropsBase, "_cast_value_recursive", None),
}
"""viser 1.1.1's own functions, as they were before any patch (None if gone: :func:`~.core.check_viser` says so)."""


def missing() -> list[str]:
    """The viser internals this module needs that the installed viser lacks."""
    found = {
        "viser._scene_handles._set_pose_vector": VISER["pose"],
        "AssignablePropsBase._cast_value_recursive": VISER["cast"],
        "viser._scene_api.cast_vector": getattr(_scene_api, "cast_vector", None),
        "viser._assignable_props_api.colors_to_uint8": getattr(_assignable_props_api, "colors_to_uint8", None),
    }
    return [name for name, value in found.items() if value is None]


_F16: Any = npt.NDArray[np.float16]
_F32: Any = npt.NDArray[np.float32]
_F64: Any = npt.NDArray[np.float64]
_U8: Any = npt.NDArray[np.uint8]
_RTOL, _ATOL = 1e-5, 1e-8  # np.allclose's defaults, as viser calls it


def close(new: tuple[float, ...], current: list[float]) -> bool:
    """``np.allclose(new, current)`` for a few plain floats: each pair equal, or both finite with
    ``|a - b| <= atol + rtol * |b|`` (so an infinity is close only to itself, NaN to nothing)."""
    return all(
        a == b or (isfinite(a) and isfinite(b) and abs(a - b) <= _ATOL + _RTOL * abs(b))
        for a, b in zip(new, current, strict=True)
    )


def cast_vector(value: Any, length: int) -> tuple[float, ...]:
    """viser's ``cast_vector``: ``value`` as a tuple of ``length`` floats (ValueError for another length)."""
    return tuple(_scene_api.cast_vector(value, length))


def set_pose_vector(
    current: np.ndarray, value: Any, length: int, queue: Callable[[Any], None], make_message: Callable[[Any], Any]
) -> None:
    """viser's ``_set_pose_vector``: cast ``value`` (raises ValueError for the wrong length), do nothing if it is
    numerically unchanged from ``current``, else write it into ``current`` in place and queue its message."""
    value_cast = cast_vector(value, length)
    if close(value_cast, current.tolist()):
        return
    current[:] = value_cast
    queue(make_message(value_cast))


def cast_value(hint: Any, value: Any, prop_name: str) -> Any:
    """viser's ``AssignablePropsBase._cast_value_recursive``: arrays to the hinted dtype (colours to uint8), each
    element of a ``tuple[T, ...]`` by ``T``, anything else as it is."""
    if hint == _F16:
        return np.asarray(value).astype(np.float16)
    if hint == _F32:
        return np.asarray(value).astype(np.float32)
    if hint == _F64:
        return np.asarray(value).astype(np.float64)
    if hint == _U8 and "color" in prop_name:
        return _assignable_props_api.colors_to_uint8(value)
    if isinstance(value, np.ndarray):
        return value
    args = getattr(hint, "__args__", None)
    if isinstance(value, tuple) and getattr(hint, "__origin__", None) is tuple and args is not None:
        if len(args) == 2 and args[1] is ...:
            return tuple(cast_value(args[0], item, prop_name) for item in value)
    return value
