"""Special poses for the app: home, the pose kept after a parameter change, and demonstration poses near
each kind of singularity (eqs. 11-12) or at a stroke end.

All of them are valid poses in the sense of :mod:`tpm_viz.app.moves` (inside the stroke and clear of the
hard singularity margins), found on a grid of platform positions in the working mode (eq. 4), or, for a stroke
end, on the curves where an actuator is exactly at an end-stop. A preset or a home pose that changes the assembly
mode says so in its :class:`~tpm_viz.app.moves.Move` ``reason`` (a note: the move is not ``clamped``).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.app.moves import Move, Pose, check, ik_branch, pose_codes, why_not
from tpm_viz.core.errors import InputError, InvalidParametersError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.status import MOVE_LIMITS, WARN, PoseStatus, SingularityThresholds

__all__ = ["DEMO_KINDS", "go_home", "home_pose", "preset_pose", "settle"]

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
    params: Params, p: np.ndarray, d: np.ndarray, limits: SingularityThresholds, modes: tuple[int, ...] = (1, -1)
) -> list[np.ndarray]:
    """Masks of the valid grid points, one per assembly mode in ``modes`` (in that order)."""
    return [pose_codes(params, p, d, m, _WORKING, limits) == PoseStatus.REGULAR for m in modes]


def home_pose(
    params: Params, near: ArrayLike = (0.0, 0.0), limits: SingularityThresholds = MOVE_LIMITS, n: int = 101
) -> Pose:
    """The valid working-mode pose nearest ``near`` [m], preferring assembly mode +1 (the home pose's mode).

    Raises :class:`~tpm_viz.InvalidParametersError` if no pose is valid (e.g. a stroke so short that every
    reachable pose needs an actuator outside it, or the margins cannot be kept anywhere).
    """
    near = np.asarray(near, dtype=float).reshape(-1)
    if near.shape != (2,) or not np.all(np.isfinite(near)):
        raise InputError(Phrase("near must be two finite numbers, got {got}", got=repr(near)))
    d_near = ik_branch(params, near, _WORKING)
    if np.all(np.isfinite(d_near)) and pose_codes(params, near, d_near, 1, _WORKING, limits) == PoseStatus.REGULAR:
        return Pose(near, d_near)
    p, d = _grid(params, n)
    for mask in _valid(params, p, d, limits):
        if np.any(mask):
            k = np.flatnonzero(mask)[np.argmin(np.linalg.norm(p[mask] - near, axis=-1))]
            return Pose(p[k], d[k])
    raise InvalidParametersError(
        Phrase(
            "no valid pose for these parameters: every reachable pose needs an actuator outside the stroke or sits "
            "at a singularity; lengthen the stroke or the links"
        )
    )


def _mode_words(mode: int) -> str:
    return "det J_x > 0" if mode > 0 else "det J_x < 0"


def go_home(params: Params, pose: Pose, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """The *Home* button from ``pose``: :func:`home_pose`, with a note when it is not ``p = 0`` or when it changes
    the assembly mode."""
    home = home_pose(params, limits=limits)
    if np.any(np.abs(home.p) > 1e-12):
        return Move(
            home,
            False,
            Phrase("p = 0 is not a valid pose with these parameters: this is the nearest valid one"),
        )
    if home.mode(params) != pose.mode(params):
        return Move(home, False, Phrase("back in the working assembly mode ({sign})", sign=_mode_words(1)))
    return Move(home)


def settle(params: Params, pose: Pose, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """The pose to show after a parameter change: the same ``p`` in the same branch and mode if still valid,
    otherwise the valid pose nearest to it (:func:`home_pose`), saying why and whether the mode changed. Raises like
    :func:`home_pose`."""
    branch = pose.branch(params)
    d = ik_branch(params, pose.p, branch)
    if np.all(np.isfinite(d)):
        kept = Pose(pose.p, d)
        code = check(params, kept, limits)
        if kept.mode(params) == pose.mode(params) and code == PoseStatus.REGULAR:
            return Move(kept)
        why = (
            why_not(params, code, kept.p, kept.d)
            if code != PoseStatus.REGULAR
            else Phrase("it would be in the other assembly mode")
        )
    else:
        why = why_not(params, PoseStatus.UNREACHABLE, pose.p, d)
    home = home_pose(params, near=pose.p, limits=limits)
    if home.mode(params) != pose.mode(params):
        return Move(
            home,
            True,
            Phrase(
                "the previous pose does not fit these parameters ({why}): moved to the nearest valid pose, in the "
                "other assembly mode ({sign})",
                why=why,
                sign=_mode_words(home.mode(params)),
            ),
        )
    return Move(
        home,
        True,
        Phrase("the previous pose does not fit these parameters ({why}): moved to the nearest valid pose", why=why),
    )


def _measure(params: Params, kind: str, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Distance to the demonstrated condition: ``min |cos θ_i|``, ``|cos(θ1+θ2)|`` or to a stroke end [m]."""
    cos = (p - d + params.offset) / params.l_a
    if kind == "inverse":
        return np.min(np.abs(cos), axis=-1)
    if kind == "direct":
        sin = p[..., ::-1] / params.l_a
        return np.abs(cos[..., 0] * cos[..., 1] - sin[..., 0] * sin[..., 1])
    return np.min(np.minimum(d, params.stroke - d), axis=-1)


def _stroke_ends(params: Params, n: int) -> tuple[np.ndarray, np.ndarray]:
    """Working-mode poses with an actuator exactly at an end-stop, ``d_i = 0`` or ``Δd``: for each, the curve
    ``p_i = d_i - (a - b) + sqrt(l_a² - p_j²)`` of eq. (4), sampled uniformly in ``θ_i``. Shapes ``(4n, 2)`` [m]."""
    s = params.l_a * np.sin(np.linspace(-np.pi / 2, np.pi / 2, n + 2)[1:-1])
    ps, ds = [], []
    for i in range(2):
        for end in (0.0, params.stroke):
            p = np.zeros((n, 2))
            p[:, 1 - i] = s
            p[:, i] = end - params.offset + np.sqrt(params.l_a**2 - s**2)
            d = ik_branch(params, p, _WORKING)
            d[:, i] = end
            ps.append(p)
            ds.append(d)
    return np.concatenate(ps), np.concatenate(ds)


_WHAT = {
    "inverse": Phrase("this close to an inverse singularity"),
    "direct": Phrase("this close to the direct singularity"),
    "stroke": Phrase("at a stroke end"),
}


def preset_pose(
    params: Params,
    kind: str,
    near: ArrayLike | Pose = (0.0, 0.0),
    limits: SingularityThresholds = MOVE_LIMITS,
    thresholds: SingularityThresholds = WARN,
    n: int = 161,
) -> Move:
    """A valid pose that demonstrates ``kind`` (see :data:`DEMO_KINDS`), the one nearest ``near``.

    - ``"inverse"``: ``min_i |cos θ_i|`` inside the warning band, between the hard margin and the threshold
      of :class:`~tpm_viz.SingularityThresholds` (eq. 11);
    - ``"direct"``: ``|cos(θ1 + θ2)|`` inside the same kind of band (eq. 12);
    - ``"stroke"``: an actuator exactly at an end-stop.

    ``near`` is a position [m] or the current :class:`~tpm_viz.app.moves.Pose`: then a pose in its assembly mode
    is preferred, and one in the other mode comes with a note that says so. If the stroke keeps the mechanism
    away from the condition, returns the closest valid pose with ``clamped=True`` and a one-line explanation.
    """
    if kind not in DEMO_KINDS:
        raise InputError(
            Phrase("demo pose kind must be one of {kinds}, got {got}", kinds=", ".join(DEMO_KINDS), got=repr(kind))
        )
    current = near.mode(params) if isinstance(near, Pose) else None
    near = np.asarray(near.p if isinstance(near, Pose) else near, dtype=float).reshape(-1)
    modes = (1, -1) if current is None else (current, -current)
    p, d = _stroke_ends(params, 4 * n) if kind == "stroke" else _grid(params, n)
    valid = _valid(params, p, d, limits, modes)
    if not np.any(valid[0] | valid[1]):
        if kind != "stroke":
            raise InvalidParametersError(Phrase("no valid pose for these parameters"))
        p, d = _grid(params, n)  # no end-stop can be reached: the closest pose of the grid
        valid = _valid(params, p, d, limits, modes)
        if not np.any(valid[0] | valid[1]):
            raise InvalidParametersError(Phrase("no valid pose for these parameters"))
    m = _measure(params, kind, p, d)
    if kind == "stroke":
        band = m <= 1e-12
    else:
        lo = limits.inverse if kind == "inverse" else limits.direct
        hi = thresholds.inverse if kind == "inverse" else thresholds.direct
        band = (m >= lo + 0.25 * (hi - lo)) & (m <= lo + 0.6 * (hi - lo))
    for mode, mask in zip(modes, valid, strict=True):
        idx = np.flatnonzero(mask & band)
        if idx.size == 0:
            continue
        k = int(idx[np.argmin(np.linalg.norm(p[idx] - near, axis=-1))])
        pose = Pose(p[k], d[k])
        if current is None or mode == current:
            return Move(pose)
        note = Phrase(
            "now in the other assembly mode ({sign}): no pose of the previous mode inside the stroke is {what}",
            sign=_mode_words(mode),
            what=_WHAT[kind],
        )
        return Move(pose, False, note)
    either = valid[0] | valid[1]
    k = int(np.flatnonzero(either)[np.argmin(np.where(either, m, np.inf)[either])])
    value = f"{fixed(m[k] * 1e3, '.1f')} mm" if kind == "stroke" else fixed(m[k], ".2f")
    what = {"inverse": "min |cos θi|", "direct": "|cos(θ1+θ2)|", "stroke": "min(d_i, Δd − d_i)"}[kind]
    return Move(
        Pose(p[k], d[k]),
        True,
        Phrase(
            "no pose inside the stroke is {what}: this is the closest one ({formula} = {value})",
            what=_WHAT[kind],
            formula=what,
            value=value,
        ),
    )
