"""The parallel 2-PPa (both rails on the X axis, facing each other): kinematics, Jacobians, statics, status.

Shapes and units as :mod:`tpm_viz.paper.kinematics`: ``p`` and ``d`` have shape ``(..., 2)`` [m]; matrices
``(..., 2, 2)``; every function broadcasts over the leading axes. Derivations: ``docs/parallel.md``.

Geometry (``docs/parallel.md``, eq. P1): ``A_1 = (d_1 - a, 0)``, ``A_2 = (a - d_2, 0)``, ``B_1 = P - (b, 0)``,
``B_2 = P + (b, 0)``, ``|B_i - A_i| = l_a``. Writing ``c_1 = p_1 - d_1 + a - b`` and ``c_2 = -p_1 - d_2 + a - b``
(the inward horizontal reach of leg ``i``), ``B_1 - A_1 = (c_1, p_2)`` and ``B_2 - A_2 = (-c_2, p_2)``, so each
leg satisfies ``c_i² + p_2² = l_a²`` (eq. P2, the analogue of the paper's eq. 27) and its angle from the rail,
measured inwards, is ``tan θ_i = p_2 / c_i``. The working mode (legs leaning inwards, ``c_i = u > 0``) gives
eq. P3: ``d_1 = p_1 + a - b - u``, ``d_2 = -p_1 + a - b - u`` with ``u = sqrt(l_a² - p_2²)``.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import InputError, InvalidParametersError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.jacobians import (
    Jacobians,
    actuator_forces_through,
    condition_of,
    platform_force_through,
    platform_velocity_through,
    pose_status,
    velocity_through,
)
from tpm_viz.paper.kinematics import FkSolutions, MechanismPose, as_xy, finite_result, in_stroke
from tpm_viz.paper.status import WARN, FkStatus, SingularityThresholds

__all__ = [
    "actuator_acceleration",
    "actuator_forces_from_platform_force",
    "actuator_velocity",
    "classify",
    "condition_number",
    "forward_kinematics",
    "forward_kinematics_both",
    "forward_kinematics_nearest",
    "geometry_problem",
    "home",
    "in_stroke",
    "inverse_kinematics",
    "jacobians",
    "leg_angles",
    "leg_components",
    "mechanism_pose",
    "platform_force_from_actuator_forces",
    "platform_velocity",
    "reachable",
    "validate",
]


def _mm(x: float) -> str:
    mm = float(x) * 1e3
    return fixed(mm, ".1f") if abs(mm) < 1e9 else fixed(mm, ".3g")


def geometry_problem(a: float, b: float, l_a: float, stroke: float) -> Phrase | None:
    """Why no pose of the parallel arrangement fits in the stroke (None if one does), lengths in m.

    Eq. (P3): ``d_1 + d_2 = 2 (a - b - u)`` with ``u ∈ (0, l_a]`` and ``d_1 - d_2 = 2 p_1`` free, so both
    ``d_i ∈ [0, Δd]`` for some pose iff ``a - b > 0`` and ``a - b - l_a <= Δd``. Every such geometry also passes
    the perpendicular rules of :class:`~tpm_viz.core.params.Params` (``a - b - √2 l_a < Δd``, ``a - b + l_a > 0``).
    """
    if not a > b:
        return Phrase(
            "for the parallel arrangement b must be less than a = {a} mm, got b = {b} mm: otherwise the sliders "
            "would have to go behind d = 0 (the rule is a − b > 0)",
            a=_mm(a),
            b=_mm(b),
        )
    if a - b - l_a > stroke:
        return Phrase(
            "for the parallel arrangement l_a must be at least {bound} mm with a = {a} mm, b = {b} mm and the stroke "
            "Δd = {stroke} mm: otherwise the sliders would have to go beyond d = Δd (the rule is a − b − l_a <= Δd)",
            bound=_mm(a - b - stroke),
            a=_mm(a),
            b=_mm(b),
            stroke=_mm(stroke),
        )
    return None


def validate(params: Params) -> Params:
    """``params`` unchanged if the parallel arrangement has a pose inside the stroke; else
    :class:`InvalidParametersError` with the fix (:func:`geometry_problem`)."""
    problem = geometry_problem(params.a, params.b, params.l_a, params.stroke)
    if problem is not None:
        raise InvalidParametersError(problem)
    return params


def reachable(params: Params, p: ArrayLike) -> np.ndarray:
    """Whether eq. (P3) has a real solution: ``|p_2| < l_a`` and ``p`` finite (bool, shape ``(...)``)."""
    p = np.asarray(p, dtype=float)
    return (np.abs(p[..., 1]) < params.l_a) & np.all(np.isfinite(p), axis=-1)


def _ik_unchecked(params: Params, p: np.ndarray) -> np.ndarray:
    with np.errstate(invalid="ignore"):
        u = np.sqrt(params.l_a**2 - p[..., 1] ** 2)
    k = params.offset - u
    return np.stack([p[..., 0] + k, -p[..., 0] + k], axis=-1)


def inverse_kinematics(params: Params, p: ArrayLike) -> np.ndarray:
    """Actuator positions ``d`` [m] for platform positions ``p`` [m], eq. (P3) (working mode, legs inwards).

    Raises :class:`UnreachablePoseError` if some ``|p_2| >= l_a``. The stroke is not enforced (see ``classify``).
    """
    p = as_xy(p)
    ok = reachable(params, p)
    if not np.all(ok):
        bad = p[~ok][0] if p.ndim > 1 else p
        raise UnreachablePoseError(
            Phrase(
                "platform position ({x}, {y}) mm is unreachable: |p2| must be below l_a = {l_a:.1f} mm",
                x=_mm(bad[0]),
                y=_mm(bad[1]),
                l_a=params.l_a * 1e3,
            )
        )
    return _ik_unchecked(params, p)


def leg_components(params: Params, p: ArrayLike, d: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(c, s)``: ``c_i = l_a cos θ_i`` (inward reach) and ``s_i = p_2 = l_a sin θ_i`` [m], shape ``(..., 2)``."""
    p = np.asarray(p, dtype=float)
    d = np.asarray(d, dtype=float)
    c = np.stack([p[..., 0] - d[..., 0], -p[..., 0] - d[..., 1]], axis=-1) + params.offset
    return c, np.stack([p[..., 1], p[..., 1]], axis=-1)


def leg_angles(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angles ``θ_i`` [rad] from the rail, inwards (``tan θ_i = p_2 / c_i``), on ``d``'s branch."""
    p = as_xy(p)
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    c, s = leg_components(params, p, d)
    return np.arctan2(s, c)


def forward_kinematics_both(params: Params, d: ArrayLike) -> FkSolutions:
    """Both platform positions for actuator positions ``d`` [m]: the intersections of two circles of radius
    ``l_a`` about ``C_1 = (d_1 - a + b, 0)`` and ``C_2 = (a - b - d_2, 0)`` (eq. P7).

    Both centres lie on the X axis, so the two modes are mirror images: ``p_1 = (C_1 + C_2)/2``,
    ``p_2 = ±sqrt(l_a² - ((C_2 - C_1)/2)²)``. ``plus`` has ``det J_x = sin(θ_1 + θ_2) >= 0``: with the legs
    inwards (``C_1 < C_2``) it is the upper one. Statuses as the perpendicular one (:class:`FkStatus`).
    """
    d = as_xy(d, "d")
    k = params.offset
    with np.errstate(over="ignore", invalid="ignore"):
        c1 = d[..., 0] - k
        c2 = k - d[..., 1]
        gap = c2 - c1  # = c_1 + c_2 = l_a² det J_x / p_2
        half = np.abs(gap) / 2.0
        h = np.sqrt(np.maximum(params.l_a**2 - half**2, 0.0))
        exists = (half <= params.l_a * (1 + 1e-12)) & (np.abs(gap) > 1e-12 * params.l_a) & np.isfinite(gap)
        h = np.where(exists, h, np.nan)
        sign = np.where(gap >= 0, 1.0, -1.0)
        x = (c1 + c2) / 2.0
        plus = np.stack([x, sign * h], axis=-1)
        minus = np.stack([x, -sign * h], axis=-1)
        status = np.where(h <= 1e-9 * params.l_a, FkStatus.MODES_MERGE, FkStatus.TWO_MODES)
        status = np.where(half > params.l_a * (1 + 1e-12), FkStatus.APART, status)
        status = np.where(np.abs(gap) <= 1e-12 * params.l_a, FkStatus.COINCIDE, status)
    return FkSolutions(plus, minus, exists, np.where(np.isfinite(gap), status, FkStatus.APART))


def _raise_if_missing(params: Params, d: np.ndarray, sol: FkSolutions) -> None:
    if np.all(sol.exists):
        return
    bad = np.asarray(d)[~sol.exists][0] if np.ndim(sol.exists) else np.asarray(d)
    if abs(float(bad[0]) + float(bad[1]) - 2.0 * params.offset) <= 1e-12 * params.l_a:
        raise SingularConfigurationError(
            Phrase(
                "d1 + d2 = 2 (a - b) = {k} mm: the two leg circles coincide, the platform position is undetermined "
                "(direct singularity)",
                k=_mm(2.0 * params.offset),
            )
        )
    raise UnreachablePoseError(
        Phrase(
            "actuators at ({d1}, {d2}) mm cannot be assembled: the leg circles are more than 2 l_a apart",
            d1=_mm(bad[0]),
            d2=_mm(bad[1]),
        )
    )


def forward_kinematics(params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] for actuator positions ``d`` [m] in assembly ``mode`` (+1 upper, -1 lower)."""
    if mode not in (1, -1):
        raise InputError(f"assembly mode must be +1 or -1, got {mode!r}")
    d = as_xy(d, "d")
    sol = forward_kinematics_both(params, d)
    _raise_if_missing(params, d, sol)
    return sol.plus if mode == 1 else sol.minus


def forward_kinematics_nearest(params: Params, d: ArrayLike, p_prev: ArrayLike) -> tuple[np.ndarray, int]:
    """The assembly mode nearest a previous platform position: ``(p, mode)`` for one pose."""
    d = as_xy(d, "d")
    sol = forward_kinematics_both(params, d)
    _raise_if_missing(params, d, sol)
    p_prev = as_xy(p_prev, "p_prev")
    with np.errstate(over="ignore"):
        if np.sum((sol.plus - p_prev) ** 2) <= np.sum((sol.minus - p_prev) ** 2):
            return sol.plus, 1
    return sol.minus, -1


def mechanism_pose(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Every joint of one configuration (the perpendicular one's :class:`MechanismPose`); the second link of
    each parallelogram is offset by the pivot spacing along ``+Y`` (perpendicular to both rails)."""
    p = as_xy(p)
    if p.shape != (2,):
        raise InputError(f"mechanism_pose takes one position of shape (2,), got {p.shape}")
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    A = np.array([[d[0] - params.a, 0.0], [params.a - d[1], 0.0]])
    B = np.array([[p[0] - params.b, p[1]], [p[0] + params.b, p[1]]])
    offset = np.array([0.0, params.pivot_spacing])
    links = np.empty((2, 2, 2, 2))
    for i in range(2):
        links[i, 0] = [A[i], B[i]]
        links[i, 1] = [A[i] + offset, B[i] + offset]
    return MechanismPose(p=p.copy(), d=d.copy(), theta=leg_angles(params, p, d), A=A, B=B, links=links)


def _cos_sin(
    params: Params, p: ArrayLike, d: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    p = as_xy(p)
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    c, s = leg_components(params, p, d)
    return p, d, c / params.l_a, s / params.l_a


def jacobians(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> Jacobians:
    """``J_x ṗ = J_q ḋ`` (eq. P4): ``J_x = [[cos θ1, sin θ1], [-cos θ2, sin θ2]]``, ``J_q = diag(cos θ_i)``,
    ``J = J_q⁻¹ J_x = [[1, tan θ1], [-1, tan θ2]]`` (working mode: ``[[1, p2/u], [-1, p2/u]]``);
    ``det J_x = sin(θ1 + θ2)`` (direct singularity, working mode ``p_2 = 0``), ``det J_q = cos θ1 cos θ2``
    (inverse singularity, ``|p_2| = l_a``). Same :class:`Jacobians` as the perpendicular arrangement."""
    _, _, cos, sin = _cos_sin(params, p, d)
    zero = np.zeros_like(cos[..., 0])
    one = np.ones_like(zero)
    jx = np.stack([np.stack([cos[..., 0], sin[..., 0]], -1), np.stack([-cos[..., 1], sin[..., 1]], -1)], -2)
    jq = np.stack([np.stack([cos[..., 0], zero], -1), np.stack([zero, cos[..., 1]], -1)], -2)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan = sin / cos
    j = np.stack([np.stack([one, tan[..., 0]], -1), np.stack([-one, tan[..., 1]], -1)], -2)
    det_jx = cos[..., 0] * sin[..., 1] + sin[..., 0] * cos[..., 1]
    return Jacobians(jx, jq, j, det_jx, cos[..., 0] * cos[..., 1])


def condition_number(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """2-norm condition number of ``J`` (eq. P4); ``inf`` at a singularity. In the working mode it equals
    ``max(|p_2|/u, u/|p_2|)`` (eq. P6)."""
    return condition_of(jacobians(params, p, d).j)


def classify(params: Params, p: ArrayLike, thresholds: SingularityThresholds = WARN) -> np.ndarray:
    """Status per pose (:class:`PoseStatus` values), the most severe wins, with the perpendicular thresholds
    read on the same quantities: ``min_i |cos θ_i|`` (inverse) and ``|det J_x|`` = the sine of the angle between
    the legs (direct; here ``|sin(θ1 + θ2)|``, in the perpendicular arrangement ``|cos(θ1 + θ2)|``)."""
    p = np.asarray(p, dtype=float)
    ok = reachable(params, p)
    safe = np.where(ok[..., None], p, 0.0)
    d = _ik_unchecked(params, safe)
    return pose_status(ok, jacobians(params, safe, d), in_stroke(params, d), thresholds)


SINGULARITIES = ("cos θ1 cos θ2 = 0", "sin(θ1 + θ2) = 0")
"""The singularity equations named in a refusal, (inverse, direct), of the parallel arrangement."""


def actuator_velocity(params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """``ḋ = J ṗ`` [m/s] (eq. P4)."""
    return velocity_through(jacobians(params, p, d), dp, SINGULARITIES)


def platform_velocity(params: Params, p: ArrayLike, dd: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """``ṗ = J_x⁻¹ J_q ḋ`` [m/s] (needs ``det J_x != 0``)."""
    return platform_velocity_through(jacobians(params, p, d), dd, SINGULARITIES)


def actuator_acceleration(
    params: Params, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """``d̈`` [m/s²] (eq. P5): ``d̈_1 = p̈_1 + (ċ_1² + ṗ_2² + p_2 p̈_2)/c_1``,
    ``d̈_2 = -p̈_1 + (ċ_2² + ṗ_2² + p_2 p̈_2)/c_2`` with ``ċ_i = -p_2 ṗ_2 / c_i``."""
    p, d, cos, _ = _cos_sin(params, p, d)
    dp, ddp = as_xy(dp, "dp"), as_xy(ddp, "ddp")
    if np.any(np.abs(cos) < 1e-12):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="cos θ1 cos θ2 = 0"))
    c = cos * params.l_a
    with np.errstate(over="ignore", invalid="ignore"):
        cdot = -p[..., 1:2] * dp[..., 1:2] / c
        num = cdot**2 + dp[..., 1:2] ** 2 + p[..., 1:2] * ddp[..., 1:2]
        sign = np.array([1.0, -1.0])
        return finite_result(sign * ddp[..., 0:1] + num / c, T("the actuator accelerations"))


def actuator_forces_from_platform_force(
    params: Params, p: ArrayLike, f: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """``τ = J⁻ᵀ f`` [N] for a platform force ``f`` [N] (eq. P8, the analogue of eq. 13); holding an external load
    ``f_ext`` at rest takes ``f = -f_ext``. Computed as ``J_q J_x⁻ᵀ f``: finite at the inverse singularity, raises
    at the direct one."""
    return actuator_forces_through(jacobians(params, p, d), f, SINGULARITIES)


def platform_force_from_actuator_forces(
    params: Params, p: ArrayLike, tau: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """``f = Jᵀ τ`` [N] for actuator forces ``τ`` [N] (eq. P8)."""
    return platform_force_through(jacobians(params, p, d), tau, SINGULARITIES)


def home(params: Params) -> np.ndarray:
    """A central pose [m]: ``p_1 = 0`` (``d_1 = d_2``) with both sliders at mid-stroke when that pose keeps
    ``cos θ`` and ``sin θ`` at least 0.2 (clear of both singularities); otherwise the in-stroke pose nearest the
    isotropic one (``θ = 45°``, ``cond J = 1``). For a valid geometry (:func:`validate`) it is inside the stroke."""
    la, k = params.l_a, params.offset
    u = k - params.stroke / 2.0  # eq. (P3) with d_1 = d_2 = Δd / 2
    if not (0.2 * la <= u and la**2 - u**2 >= (0.2 * la) ** 2):
        lo, hi = max(k - params.stroke, 1e-3 * la), min(k, la)  # u with both d_i in [0, Δd]
        u = min(max(la / math.sqrt(2.0), lo), hi)
    return np.array([0.0, math.sqrt(max(la**2 - u**2, 0.0))])
