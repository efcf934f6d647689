"""Special poses for the app: home, the pose kept after a parameter change, and demonstration poses near
each kind of singularity (eqs. 11-12) or at a stroke end.

All of them are valid poses in the sense of :mod:`tpm_viz.app.moves` (inside the stroke and clear of the
hard singularity margins), found on a grid of platform positions in the working mode (eq. 4).
"""

from __future__ import annotations

import numpy as np

from tpm_viz.app.moves import Move, Pose, check, drag_to, ik_branch, pose_codes
from tpm_viz.errors import InputError, InvalidParametersError
from tpm_viz.paper.status import MOVE_LIMITS, WARN, PoseStatus, SingularityThresholds
from tpm_viz.params import Params

__all__ = ["DEMO_KINDS", "home_pose", "preset_pose", "settle"]

DEMO_KINDS = ("inverse", "direct", "stroke")
"""Kinds of :func:`preset_pose`: near an inverse singularity, near the direct singularity, at a stroke end."""

_WORKING = np.ones(2)


def _grid(params: Params, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Working-mode grid over ``|p_j| < l_a``: positions and actuator positions, shape ``(n*n, 2)`` [m].

    Uniform in the leg angles (``p_1 = l_a sin θ_2``, ``p_2 = l_a sin θ_1``), so that it resolves
    ``cos θ_i`` evenly near the inverse singularity, where ``|p_j| -> l_a``.
    """
    xs = params.l_a * np.sin(np.linspace(-np.pi / 2, np.pi / 2, n + 2)[1:-1])
    p = np.stack(np.meshgrid(xs, xs), axis=-1).reshape(-1, 2)
    return p, ik_branch(params, p, _WORKING)


def _valid(
    params: Params, p: np.ndarray, d: np.ndarray, limits: SingularityThresholds, modes=(1, -1)
) -> list[np.ndarray]:
    """Masks of the valid grid points, one per assembly mode in ``modes`` (in that order)."""
    return [pose_codes(params, p, d, m, _WORKING, limits) == PoseStatus.REGULAR for m in modes]


def home_pose(params: Params, near=(0.0, 0.0), limits: SingularityThresholds = MOVE_LIMITS, n: int = 101) -> Pose:
    """The valid working-mode pose nearest ``near`` [m], preferring assembly mode +1 (the home pose's mode).

    Raises :class:`~tpm_viz.InvalidParametersError` if no pose is valid (e.g. a stroke so short that every
    reachable pose needs an actuator outside it, or the margins cannot be kept anywhere).
    """
    near = np.asarray(near, dtype=float).reshape(-1)
    if near.shape != (2,) or not np.all(np.isfinite(near)):
        raise InputError(f"near must be two finite numbers, got {near!r}")
    d_near = ik_branch(params, near, _WORKING)
    if np.all(np.isfinite(d_near)) and pose_codes(params, near, d_near, 1, _WORKING, limits) == PoseStatus.REGULAR:
        return Pose(near, d_near)
    p, d = _grid(params, n)
    for mask in _valid(params, p, d, limits):
        if np.any(mask):
            k = np.flatnonzero(mask)[np.argmin(np.linalg.norm(p[mask] - near, axis=-1))]
            return Pose(p[k], d[k])
    raise InvalidParametersError(
        "no valid pose for these parameters: every reachable pose needs an actuator outside the stroke "
        "or sits at a singularity"
    )


def settle(params: Params, pose: Pose, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """The pose to show after a parameter change: the same ``p`` in the same branch and mode if still valid,
    otherwise the valid pose nearest to it (:func:`home_pose`). Raises like :func:`home_pose`."""
    branch = pose.branch(params)
    d = ik_branch(params, pose.p, branch)
    if np.all(np.isfinite(d)):
        kept = Pose(pose.p, d)
        if kept.mode(params) == pose.mode(params) and check(params, kept, limits) == PoseStatus.REGULAR:
            return Move(kept)
    home = home_pose(params, near=pose.p, limits=limits)
    return Move(home, True, "the previous pose is not valid with these parameters: moved to the nearest valid pose")


def _measure(params: Params, kind: str, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance to the demonstrated condition: ``min |cos θ_i|``, ``|cos(θ1+θ2)|`` or to a stroke end [m]."""
    cos = (p - d + params.offset) / params.l_a
    if kind == "inverse":
        return np.min(np.abs(cos), axis=-1)
    if kind == "direct":
        sin = p[..., ::-1] / params.l_a
        return np.abs(cos[..., 0] * cos[..., 1] - sin[..., 0] * sin[..., 1])
    return np.min(np.minimum(d, params.stroke - d), axis=-1)


def preset_pose(
    params: Params,
    kind: str,
    near=(0.0, 0.0),
    limits: SingularityThresholds = MOVE_LIMITS,
    thresholds: SingularityThresholds = WARN,
    n: int = 161,
) -> Move:
    """A valid pose that demonstrates ``kind`` (see :data:`DEMO_KINDS`), the one nearest ``near`` [m].

    - ``"inverse"``: ``min_i |cos θ_i|`` inside the warning band, between the hard margin and the threshold
      of :class:`~tpm_viz.SingularityThresholds` (eq. 11);
    - ``"direct"``: ``|cos(θ1 + θ2)|`` inside the same kind of band (eq. 12);
    - ``"stroke"``: an actuator exactly at a stroke end (reached by a clamped drag towards it).

    If the stroke keeps the mechanism away from the condition, returns the closest valid pose with
    ``clamped=True`` and a one-line explanation.
    """
    if kind not in DEMO_KINDS:
        raise InputError(f"demo pose kind must be one of {', '.join(DEMO_KINDS)}, got {kind!r}")
    near = np.asarray(near, dtype=float).reshape(-1)
    p, d = _grid(params, n)
    valid = np.any(np.stack(_valid(params, p, d, limits)), axis=0)
    if not np.any(valid):
        raise InvalidParametersError("no valid pose for these parameters")
    p, d = p[valid], d[valid]
    m = _measure(params, kind, p, d)
    if kind == "stroke":
        band = m <= 0.02 * params.stroke
    else:
        lo = limits.inverse if kind == "inverse" else limits.direct
        hi = thresholds.inverse if kind == "inverse" else thresholds.direct
        band = (m >= lo + 0.25 * (hi - lo)) & (m <= lo + 0.6 * (hi - lo))
    if not np.any(band):
        k = int(np.argmin(m))
        what = {"inverse": "min |cos θi|", "direct": "|cos(θ1+θ2)|", "stroke": "distance to a stroke end"}[kind]
        value = f"{m[k] * 1e3:.1f} mm" if kind == "stroke" else f"{m[k]:.2f}"
        return Move(
            Pose(p[k], d[k]), True, f"the stroke keeps the mechanism away: the closest pose has {what} = {value}"
        )
    idx = np.flatnonzero(band)
    k = int(idx[np.argmin(np.linalg.norm(p[idx] - near, axis=-1))])
    pose = Pose(p[k], d[k])
    if kind != "stroke":
        return Move(pose)
    i = int(np.argmin(np.minimum(d[k], params.stroke - d[k])))
    towards = np.zeros(2)
    towards[i] = 1.0 if params.stroke - d[k, i] < d[k, i] else -1.0  # ∂d_i/∂p_i = 1 on every branch
    pushed = drag_to(params, pose, pose.p + 0.05 * params.l_a * towards, limits)
    at_end = np.min(np.minimum(pushed.pose.d, params.stroke - pushed.pose.d)) < 1e-6  # m
    return Move(pushed.pose) if at_end else Move(pose)
