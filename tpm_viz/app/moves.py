"""Interactive moves of the 2-PPa TPM: drags and drives that stop at the nearest valid pose.

Pure numpy, no browser: the app calls these functions and only draws what they return.

A :class:`Pose` is a platform position ``p`` with actuator positions ``d`` [m]. ``d`` fixes the branch of each
leg, the sign of ``c_i = p_i - d_i + a - b = l_a cos θ_i`` (eq. 23; ``+1`` is the working mode of eq. 4), and
the pair fixes the assembly mode, the sign of ``det J_x = cos(θ1 + θ2)`` (eq. 12). A pose is *valid* when

- both actuators are inside the stroke, ``0 <= d_i <= Δd``;
- both legs keep clear of the inverse singularity, ``|cos θ_i| >= min_cos`` (eq. 11);
- the mechanism keeps clear of the direct singularity, ``|cos(θ1 + θ2)| >= min_det`` (eq. 12).

Continuous moves (:func:`drag_to` moves the platform by inverse kinematics, :func:`drive_to` moves the
actuators by forward kinematics) keep each leg's branch and the assembly mode. When the request leaves the
valid set, the pose stops at the last valid point of the straight segment from the current pose towards the
request (a drag also slides along the boundary when that gets nearer to the request) and the reason comes
back as one line of text. Deliberate jumps are separate: :func:`switch_mode` (the other assembly mode),
:func:`place` (a trajectory sample). Special poses (home, after a parameter change, near each kind of
singularity) are in :mod:`tpm_viz.app.poses`.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Literal, NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.kinematics import forward_kinematics_both, inverse_kinematics
from tpm_viz.paper.status import MOVE_LIMITS, PoseStatus, SingularityThresholds

__all__ = [
    "Move",
    "Pose",
    "check",
    "drag_to",
    "drive_to",
    "ik_branch",
    "margins",
    "place",
    "pose_codes",
    "switch_mode",
    "why_not",
]


_STROKE_TOL = 1e-9  # m
_SAMPLES = 48  # samples per refinement round of a segment
_ROUNDS = 3  # resolution 1 / 48**3 of the segment

ArrayMap = Callable[[np.ndarray], np.ndarray]
"""A function of points ``(..., 2)`` [m]: validity codes ``(...)`` or margins ``(..., 5)`` (see :func:`margins`)."""


@dataclass(frozen=True)
class Pose:
    """One assembled configuration: platform position ``p`` [m] and actuator positions ``d`` [m], shape (2,)."""

    p: np.ndarray
    d: np.ndarray

    def __post_init__(self) -> None:
        for name in ("p", "d"):
            arr = np.array(getattr(self, name), dtype=float).reshape(-1)
            if arr.shape != (2,) or not np.all(np.isfinite(arr)):
                raise InputError(
                    Phrase(
                        "pose {name} must be two finite numbers, got {got}", name=name, got=repr(getattr(self, name))
                    )
                )
            arr.setflags(write=False)
            object.__setattr__(self, name, arr)

    def branch(self, params: Params) -> np.ndarray:
        """Sign of ``c_i = l_a cos θ_i`` per leg (``+1`` is the working mode of eq. 4), shape (2,)."""
        return np.where(self.p - self.d + params.offset >= 0.0, 1.0, -1.0)

    def mode(self, params: Params) -> int:
        """Assembly mode: the sign of ``det J_x = cos(θ1 + θ2)`` (eq. 12), ``+1`` or ``-1``."""
        c = self.p - self.d + params.offset
        return 1 if c[0] * c[1] - self.p[0] * self.p[1] >= 0.0 else -1

    @classmethod
    def working(cls, params: Params, p: ArrayLike) -> Pose:
        """The working-mode pose at ``p`` (eq. 4); raises :class:`~tpm_viz.UnreachablePoseError`."""
        return cls(np.asarray(p, dtype=float), inverse_kinematics(params, p))


class Move(NamedTuple):
    """Result of a move: the new pose, whether it stopped short of the request, and why (one line: a
    :class:`~tpm_viz.core.words.Phrase`, rendered in the tab's language; ``""`` when there is nothing to say)."""

    pose: Pose
    clamped: bool = False
    reason: str | Phrase = ""


def ik_branch(params: Params, p: ArrayLike, branch: ArrayLike) -> np.ndarray:
    """Inverse kinematics on a given branch: ``d_i = p_i + a - b - σ_i sqrt(l_a² - p_j²)`` [m] (eq. 3).

    ``σ_i = +1`` is eq. (4). NaN where ``|p_j| > l_a``. Shapes ``(..., 2)``.
    """
    p = np.asarray(p, dtype=float)
    with np.errstate(invalid="ignore"):
        root = np.sqrt(params.l_a**2 - p[..., ::-1] ** 2)
    return p + params.offset - np.asarray(branch, dtype=float) * root


def margins(
    params: Params, p: ArrayLike, d: ArrayLike, mode: int, limits: SingularityThresholds = MOVE_LIMITS
) -> np.ndarray:
    """Signed distances to the edges of the valid set, shape ``(..., 5)``; the pose is valid iff all are >= 0.

    Columns: the stroke of each actuator ``min(d_i, Δd - d_i)`` [m] (2 columns), ``|cos θ_i| - min_cos``
    (2 columns, eq. 11) and ``mode cos(θ1 + θ2) - min_det`` (eq. 12). NaN where ``p`` or ``d`` is not finite.
    """
    p = np.asarray(p, dtype=float)
    d = np.asarray(d, dtype=float)
    cos = (p - d + params.offset) / params.l_a
    sin = p[..., ::-1] / params.l_a
    det = cos[..., 0] * cos[..., 1] - sin[..., 0] * sin[..., 1]
    stroke = np.minimum(d, params.stroke - d)
    return np.concatenate([stroke, np.abs(cos) - limits.inverse, (mode * det - limits.direct)[..., None]], axis=-1)


_CODE_OF_COLUMN = np.array([PoseStatus.OUT_OF_STROKE] * 2 + [PoseStatus.NEAR_INVERSE] * 2 + [PoseStatus.NEAR_DIRECT])


def pose_codes(
    params: Params,
    p: ArrayLike,
    d: ArrayLike,
    mode: int,
    branch: ArrayLike | None = None,
    limits: SingularityThresholds = MOVE_LIMITS,
) -> np.ndarray:
    """Validity per pose, shape ``(...)``: ``PoseStatus.REGULAR`` or the first failing rule (stroke, inverse, direct).

    ``mode`` is the required sign of ``det J_x``; ``branch`` (optional) the required sign of each ``c_i``.
    Non-finite ``p`` or ``d`` count as ``PoseStatus.UNREACHABLE``.
    """
    m = margins(params, p, d, mode, limits)
    m[..., :2] += _STROKE_TOL
    finite = np.all(np.isfinite(m), axis=-1)
    bad = m < 0.0
    if branch is not None:
        cos_sign = np.sign(np.asarray(p, dtype=float) - np.asarray(d, dtype=float) + params.offset)
        bad[..., 2:4] |= cos_sign != np.asarray(branch)
    first = np.argmax(bad, axis=-1)
    code = np.where(np.any(bad, axis=-1), _CODE_OF_COLUMN[first], PoseStatus.REGULAR)
    return np.where(finite, code, PoseStatus.UNREACHABLE)


def check(params: Params, pose: Pose, limits: SingularityThresholds = MOVE_LIMITS) -> int:
    """Validity code of one pose in its own branch and mode (``PoseStatus.REGULAR`` = 0 when valid)."""
    return int(pose_codes(params, pose.p, pose.d, pose.mode(params), pose.branch(params), limits))


Cause = Literal["drag", "drive", "path"]
"""What led to a pose: a drag of the platform, a drive of the actuators, or a sample of a given path."""


def why_not(params: Params, status: int, p: ArrayLike, d: ArrayLike, cause: Cause = "path") -> Phrase:
    """One line saying why the pose ``(p, d)`` [m] is not valid, for a status of :class:`PoseStatus` other than
    ``REGULAR``: the one describer of refusals (moves, trajectories, presets, lessons). What happens physically
    first (which actuator and which end, which leg, what the platform does), then the number and the equation.
    For a drag or a drive ``(p, d)`` is the first blocked pose of the move; for a path, the offending sample."""
    p, d, mm = np.asarray(p, dtype=float), np.asarray(d, dtype=float), 1e3
    cos = (p - d + params.offset) / params.l_a
    if status == PoseStatus.OUT_OF_STROKE:
        i = int(np.argmax(np.maximum(-d, d - params.stroke)))
        if cause != "path":
            if d[i] < 0.5 * params.stroke:
                return Phrase(
                    "slider {i} is against its end-stop at the start of its rail (d{i} = 0 mm): actuator {i} cannot "
                    "pull it further back",
                    i=i + 1,
                )
            return Phrase(
                "slider {i} is against its end-stop at the end of its rail (d{i} = Δd = {end} mm): actuator {i} "
                "cannot push it further",
                i=i + 1,
                end=fixed(params.stroke * mm, ".1f"),
            )
        return Phrase(
            "actuator {i} would leave its stroke: slider {i} would have to be at d{i} = {d} mm, beyond its "
            "end-stops at 0 and {stroke} mm",
            i=i + 1,
            d=fixed(d[i] * mm, ".1f"),
            stroke=fixed(params.stroke * mm, ".0f"),
        )
    if status == PoseStatus.NEAR_INVERSE:
        i = int(np.nanargmin(np.abs(cos))) if np.any(np.isfinite(cos)) else 0
        value = f"cos θ{i + 1} = {fixed(cos[i], '.3f')}, " if np.isfinite(cos[i]) else ""
        return Phrase(
            "leg {i} would come too close to an inverse singularity: its links would stand almost perpendicular to "
            "rail {i}, where actuator {i} loses its authority along them ({value}eq. 11)",
            i=i + 1,
            value=value,
        )
    if status == PoseStatus.NEAR_DIRECT:
        det = cos[0] * cos[1] - p[1] * p[0] / params.l_a**2
        dot = cos[0] * p[1] + p[0] * cos[1]  # l_a s_1 · s_2 / l_a
        kind = Phrase("the leg circles coincide") if dot > 0 else Phrase("the two assembly modes merge")
        value = f"cos(θ1+θ2) = {fixed(det, '.3f')}, " if np.isfinite(det) else ""
        return Phrase(
            "the platform would come too close to the direct singularity, where it gains a degree of freedom: it "
            "loses its stiffness in one direction and the actuator forces grow without bound for a load along it; "
            "{kind} ({value}eq. 12)",
            kind=kind,
            value=value,
        )
    if cause == "drive":
        return Phrase(
            "the two legs cannot both reach the platform there: their circles no longer meet, so the mechanism "
            "cannot be assembled"
        )
    return Phrase(
        "out of reach: a leg of length l_a = {l_a} mm cannot reach the platform there (|p1| and |p2| must stay "
        "below l_a)",
        l_a=fixed(params.l_a * mm, ".1f"),
    )


def _clamp(codes_of: ArrayMap, x0: np.ndarray, x1: np.ndarray) -> tuple[np.ndarray, int]:
    """Last valid point of the segment ``x0 -> x1`` and the code that stopped it (``PoseStatus.REGULAR`` if none)."""
    t_ok, t_end = 0.0, 1.0
    stop: int = PoseStatus.REGULAR
    for _ in range(_ROUNDS):
        ts = np.linspace(t_ok, t_end, _SAMPLES + 1)[1:]
        codes = codes_of(x0 + ts[:, None] * (x1 - x0))
        bad = np.flatnonzero(codes != PoseStatus.REGULAR)
        if bad.size == 0:
            return (x1, stop) if stop == PoseStatus.REGULAR else (x0 + t_ok * (x1 - x0), stop)
        k = int(bad[0])
        stop = int(codes[k])
        t_ok, t_end = (ts[k - 1] if k > 0 else t_ok), ts[k]
    return x0 + t_ok * (x1 - x0), stop


def _drag_codes(params: Params, branch: np.ndarray, mode: int, limits: SingularityThresholds) -> ArrayMap:
    def codes_of(p: np.ndarray) -> np.ndarray:
        d = ik_branch(params, p, branch)
        return pose_codes(params, p, d, mode, branch, limits)

    return codes_of


def drag_to(params: Params, pose: Pose, p_req: ArrayLike, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """Move the platform towards ``p_req`` [m] by inverse kinematics, in the pose's branch and mode.

    Stops at the last valid pose on the way (see the module docstring). When stopped, it then slides along
    the edge that stopped it, towards the point of that edge nearest ``p_req``, if that ends nearer.
    """
    p_req = np.asarray(p_req, dtype=float).reshape(-1)
    if p_req.shape != (2,) or not np.all(np.isfinite(p_req)):
        raise InputError(Phrase("requested platform position must be two finite numbers, got {got}", got=repr(p_req)))
    branch, mode = pose.branch(params), pose.mode(params)
    codes_of = _drag_codes(params, branch, mode, limits)
    p0 = pose.p.astype(float)
    best, stop = _clamp(codes_of, p0, p_req)
    if stop == PoseStatus.REGULAR:
        return Move(Pose(best, ik_branch(params, best, branch)))
    blocked = _first_bad(codes_of, p0, p_req)

    def margins_of(p: np.ndarray) -> np.ndarray:
        return margins(params, p, ik_branch(params, p, branch), mode, limits)

    edge = _project_on_edge(margins_of, np.clip(p_req, -0.999 * params.l_a, 0.999 * params.l_a), blocked)
    if edge is not None:
        slid, _ = _clamp(codes_of, best, edge)
        if np.linalg.norm(slid - p_req) < np.linalg.norm(best - p_req) - 1e-12:
            best = slid
    new = Pose(best, ik_branch(params, best, branch))
    why = why_not(params, stop, blocked, ik_branch(params, blocked, branch), "drag")
    return Move(new, True, Phrase("stopped: {why}", why=why))


def _project_on_edge(margins_of: ArrayMap, start: np.ndarray, blocked: np.ndarray) -> np.ndarray | None:
    """The point of the edge that stopped a drag (the margin most violated just past the stop, at ``blocked``)
    nearest ``start`` (the request), by Gauss-Newton projection; slightly inside the valid set. None if it fails."""
    m_blocked = margins_of(blocked[None])[0]
    if not np.all(np.isfinite(m_blocked)):
        return None
    k = int(np.argmin(m_blocked))
    target = start.astype(float)
    x = target.copy()
    h = 1e-7
    for _ in range(10):
        g = margins_of(x + np.array([[0.0, 0.0], [h, 0.0], [0.0, h]]))[:, k]
        if not np.all(np.isfinite(g)):
            return None
        grad = (g[1:] - g[0]) / h
        norm2 = float(grad @ grad)
        if norm2 == 0.0:
            return None
        # Nearest point to the target on the linearised edge g(x) + grad.(y - x) = 1e-9 (just inside).
        x_new = target - (g[0] - 1e-9 + grad @ (target - x)) / norm2 * grad
        if np.linalg.norm(x_new - x) < 1e-12:
            break
        x = x_new
    return x


def _first_bad(codes_of: ArrayMap, x0: np.ndarray, x1: np.ndarray) -> np.ndarray:
    """A point just past the last valid one on ``x0 -> x1`` (for the wording of the reason)."""
    ts = np.linspace(0.0, 1.0, 4 * _SAMPLES + 1)[1:]
    pts = x0 + ts[:, None] * (x1 - x0)
    bad = np.flatnonzero(codes_of(pts) != PoseStatus.REGULAR)
    return pts[int(bad[0])] if bad.size else x1


def _fk(params: Params, d: np.ndarray, mode: int) -> np.ndarray:
    with np.errstate(invalid="ignore", divide="ignore"):
        sol = forward_kinematics_both(params, d)
    p = sol.plus if mode > 0 else sol.minus
    return np.where(sol.exists[..., None], p, np.nan)


def drive_to(params: Params, pose: Pose, d_req: ArrayLike, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """Move the actuators towards ``d_req`` [m]; the platform follows by forward kinematics in the pose's mode.

    Stops at the last valid pose on the way: at a stroke end, before an inverse singularity, or before the
    direct singularity where the two leg circles become tangent and the assembly modes merge.
    """
    d_req = np.asarray(d_req, dtype=float).reshape(-1)
    if d_req.shape != (2,) or not np.all(np.isfinite(d_req)):
        raise InputError(Phrase("requested actuator positions must be two finite numbers, got {got}", got=repr(d_req)))
    branch, mode = pose.branch(params), pose.mode(params)

    def codes_of(d: np.ndarray) -> np.ndarray:
        return pose_codes(params, _fk(params, d, mode), d, mode, branch, limits)

    d0 = pose.d.astype(float)
    d_box = np.clip(d_req, 0.0, params.stroke)  # the stroke is a box in d: clipping the request is exact
    d_new, stop = _clamp(codes_of, d0, d_box)
    if stop == PoseStatus.REGULAR and not np.array_equal(d_box, d_req):
        stop = PoseStatus.OUT_OF_STROKE
    p_new = _fk(params, d_new, mode)
    new = Pose(p_new, d_new) if np.all(np.isfinite(p_new)) else pose
    if stop == PoseStatus.REGULAR:
        return Move(new)
    d_bad = _first_bad(codes_of, d0, d_req)
    p_bad = _fk(params, d_bad, mode)
    return Move(new, True, Phrase("stopped: {why}", why=why_not(params, stop, p_bad, d_bad, "drive")))


def switch_mode(params: Params, pose: Pose, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """Jump to the other assembly mode at the same actuator positions (the other circle intersection)."""
    other = _fk(params, pose.d, -pose.mode(params))
    if not np.all(np.isfinite(other)):
        why = why_not(params, PoseStatus.UNREACHABLE, pose.p, pose.d, "drive")
        return Move(pose, True, Phrase("no other assembly mode here: {why}", why=why))
    code = int(pose_codes(params, other, pose.d, -pose.mode(params), None, limits))
    if code != PoseStatus.REGULAR:
        why = why_not(params, code, other, pose.d, "drive")
        return Move(pose, True, Phrase("the other assembly mode is not usable here: {why}", why=why))
    return Move(Pose(other, pose.d))


def place(params: Params, pose: Pose, p: ArrayLike, limits: SingularityThresholds = MOVE_LIMITS) -> Move:
    """Jump to ``p`` [m] in the working mode (eq. 4), e.g. a trajectory sample; refused if not valid there."""
    p = np.asarray(p, dtype=float).reshape(-1)
    if p.shape != (2,) or not np.all(np.isfinite(p)):
        raise InputError(Phrase("platform position must be two finite numbers, got {got}", got=repr(p)))
    d = ik_branch(params, p, (1.0, 1.0))
    if not np.all(np.isfinite(d)):
        return Move(pose, True, Phrase("refused: {why}", why=why_not(params, PoseStatus.UNREACHABLE, p, d)))
    new = Pose(p, d)
    code = check(params, new, limits)
    if code != PoseStatus.REGULAR:
        return Move(pose, True, Phrase("refused: {why}", why=why_not(params, code, p, d)))
    return Move(new)
