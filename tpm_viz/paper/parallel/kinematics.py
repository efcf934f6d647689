"""The parallel 2-PPa (both rails on the X axis, facing each other): kinematics, Jacobians, statics, status.

Shapes and units as :mod:`tpm_viz.paper.kinematics`: ``p`` and ``d`` have shape ``(..., 2)`` [m]; matrices
``(..., 2, 2)``; every function broadcasts over the leading axes. Derivations: ``docs/parallel.md``.

Geometry (``docs/parallel.md``, eq. P1): ``A_1 = (d_1 - a, 0)``, ``A_2 = (a - d_2, 0)``, ``B_1 = P - (b, 0)``,
``B_2 = P + (b, 0)``, ``|B_i - A_i| = l_a``. Writing ``c_1 = p_1 - d_1 + a - b`` and ``c_2 = -p_1 - d_2 + a - b``
(the inward horizontal reach of leg ``i``), ``B_1 - A_1 = (c_1, p_2)`` and ``B_2 - A_2 = (-c_2, p_2)``, so each
leg satisfies ``c_i² + p_2² = l_a²`` (eq. P2, the analogue of the paper's eq. 27) and its angle from the rail,
measured inwards, is ``tan θ_i = p_2 / c_i``. The working mode (legs leaning inwards, ``c_i = u > 0``) gives
eq. P3: ``d_1 = p_1 + a - b - u``, ``d_2 = -p_1 + a - b - u`` with ``u = sqrt(l_a² - p_2²)``.

The parallel arrangement's own equations are here (P1, P3, P7, its geometry rule and home pose, P5), gathered in
:data:`PARALLEL`; the rest is the perpendicular arrangement's code, parameterised by it: :mod:`tpm_viz.paper.legs`
(checked inverse kinematics, leg angles, assembly modes, links) and :mod:`tpm_viz.paper.jacobians` (``J_x``, ``J_q``,
``J`` of P4 from the legs' indices, the statics of P8, the statuses).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InvalidParametersError, SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper import legs
from tpm_viz.paper.jacobians import (
    Jacobians,
    actuator_forces_through,
    classify_of,
    condition_of,
    cos_sin,
    jacobians_of,
    platform_force_through,
    platform_velocity_through,
    velocity_through,
)
from tpm_viz.paper.legs import FkSolutions, Legs, MechanismPose, as_xy, finite_result, in_stroke, mm
from tpm_viz.paper.status import WARN, SingularityThresholds

__all__ = [
    "PARALLEL",
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
            a=mm(a),
            b=mm(b),
        )
    if a - b - l_a > stroke:
        return Phrase(
            "for the parallel arrangement l_a must be at least {bound} mm with a = {a} mm, b = {b} mm and the stroke "
            "Δd = {stroke} mm: otherwise the sliders would have to go beyond d = Δd (the rule is a − b − l_a <= Δd)",
            bound=mm(a - b - stroke),
            a=mm(a),
            b=mm(b),
            stroke=mm(stroke),
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
    return legs.inverse_kinematics(PARALLEL, params, p)


def leg_components(params: Params, p: ArrayLike, d: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(c, s)``: ``c_i = l_a cos θ_i`` (inward reach) and ``s_i = p_2 = l_a sin θ_i`` [m], shape ``(..., 2)``."""
    p = np.asarray(p, dtype=float)
    d = np.asarray(d, dtype=float)
    c = np.stack([p[..., 0] - d[..., 0], -p[..., 0] - d[..., 1]], axis=-1) + params.offset
    return c, np.stack([p[..., 1], p[..., 1]], axis=-1)


def leg_angles(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angles ``θ_i`` [rad] from the rail, inwards (``tan θ_i = p_2 / c_i``), on ``d``'s branch."""
    return legs.leg_angles(PARALLEL, params, p, d)


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
        h, exists, status = legs.meeting(params, np.abs(gap))
        sign = np.where(gap >= 0, 1.0, -1.0)
        x = (c1 + c2) / 2.0
        plus = np.stack([x, sign * h], axis=-1)
        minus = np.stack([x, -sign * h], axis=-1)
    return FkSolutions(plus, minus, exists, status)


def _coincide(params: Params, d: np.ndarray) -> Phrase | None:
    if abs(float(d[0]) + float(d[1]) - 2.0 * params.offset) <= 1e-12 * params.l_a:
        return Phrase(
            "d1 + d2 = 2 (a - b) = {k} mm: the two leg circles coincide, the platform position is undetermined "
            "(direct singularity)",
            k=mm(2.0 * params.offset),
        )
    return None


def forward_kinematics(params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] for actuator positions ``d`` [m] in assembly ``mode`` (+1 upper, -1 lower)."""
    return legs.forward_kinematics(PARALLEL, params, d, mode)


def forward_kinematics_nearest(params: Params, d: ArrayLike, p_prev: ArrayLike) -> tuple[np.ndarray, int]:
    """The assembly mode nearest a previous platform position: ``(p, mode)`` for one pose."""
    return legs.forward_kinematics_nearest(PARALLEL, params, d, p_prev)


def _joints(params: Params, p: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (P1): ``A_1 = (d_1 - a, 0)``, ``A_2 = (a - d_2, 0)``, ``B_1 = P - (b, 0)``, ``B_2 = P + (b, 0)``."""
    A = np.array([[d[0] - params.a, 0.0], [params.a - d[1], 0.0]])
    B = np.array([[p[0] - params.b, p[1]], [p[0] + params.b, p[1]]])
    return A, B


def mechanism_pose(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Every joint of one configuration (the perpendicular one's :class:`MechanismPose`); the second link of
    each parallelogram is offset by the pivot spacing along ``+Y`` (perpendicular to both rails)."""
    return legs.mechanism_pose(PARALLEL, params, p, d)


def jacobians(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> Jacobians:
    """``J_x ṗ = J_q ḋ`` (eq. P4): ``J_x = [[cos θ1, sin θ1], [-cos θ2, sin θ2]]``, ``J_q = diag(cos θ_i)``,
    ``J = J_q⁻¹ J_x = [[1, tan θ1], [-1, tan θ2]]`` (working mode: ``[[1, p2/u], [-1, p2/u]]``);
    ``det J_x = sin(θ1 + θ2)`` (direct singularity, working mode ``p_2 = 0``), ``det J_q = cos θ1 cos θ2``
    (inverse singularity, ``|p_2| = l_a``). Same :class:`Jacobians` as the perpendicular arrangement
    (:func:`~tpm_viz.paper.jacobians.jacobians_of`)."""
    return jacobians_of(PARALLEL, params, p, d)


def condition_number(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """2-norm condition number of ``J`` (eq. P4); ``inf`` at a singularity. In the working mode it equals
    ``max(|p_2|/u, u/|p_2|)`` (eq. P6)."""
    return condition_of(jacobians(params, p, d).j)


def classify(params: Params, p: ArrayLike, thresholds: SingularityThresholds = WARN) -> np.ndarray:
    """Status per pose (:class:`PoseStatus` values), the most severe wins, with the perpendicular thresholds
    read on the same quantities: ``min_i |cos θ_i|`` (inverse) and ``|det J_x|`` = the sine of the angle between
    the legs (direct; here ``|sin(θ1 + θ2)|``, in the perpendicular arrangement ``|cos(θ1 + θ2)|``)."""
    return classify_of(PARALLEL, params, p, thresholds)


SINGULARITIES = ("cos θ1 cos θ2 = 0", "sin(θ1 + θ2) = 0")
"""The singularity equations named in a refusal, (inverse, direct), of the parallel arrangement."""

PARALLEL = Legs(
    along=(0, 0),
    sign=(1.0, -1.0),
    across=(1, 1),
    singularities=SINGULARITIES,
    unreachable=Phrase("platform position ({x}, {y}) mm is unreachable: |p2| must be below l_a = {l_a:.1f} mm"),
    reachable=reachable,
    ik=_ik_unchecked,
    components=leg_components,
    circles=forward_kinematics_both,
    joints=_joints,
    coincide=_coincide,
)
"""The parallel legs (:class:`~tpm_viz.paper.legs.Legs`): ``c_1 = p_1 - d_1 + a - b``,
``c_2 = -p_1 - d_2 + a - b``, ``s_i = p_2`` (eq. P2)."""


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
    p, d, cos, _ = cos_sin(PARALLEL, params, p, d)
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
