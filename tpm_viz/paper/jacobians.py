"""Jacobians, singularities, statics, velocities and accelerations of the 2-PPa TPM (eqs. 6-15).

All functions broadcast over leading axes: ``p`` and ``d`` have shape ``(..., 2)`` [m],
matrices have shape ``(..., 2, 2)``. ``d`` (the branch) defaults to the working-mode
inverse kinematics (eq. 4).

Velocity relation (eqs. 6-10): ``J_x ṗ = J_q ḋ`` with
``J_x = [[cos θ1, sin θ1], [sin θ2, cos θ2]]``, ``J_q = diag(cos θ1, cos θ2)`` and
``J = J_q^{-1} J_x = [[1, tan θ1], [tan θ2, 1]]``. Both arrangements' Jacobians (eq. P4 for the parallel one)
are built by :func:`~tpm_viz.paper.jacobians.jacobians_of` from their legs (:class:`~tpm_viz.paper.legs.Legs`), and
both share the statuses (:func:`classify_of`, :func:`pose_status`), the condition number and the statics through
the ``*_through`` functions.

Erratum (eq. 15): the paper prints ``J̇_q = diag(+sin θ_i θ̇_i)``; the time derivative of
``cos θ_i`` is ``-sin θ_i θ̇_i``. :func:`actuator_acceleration` uses the corrected sign; the
test suite shows the printed sign disagrees with finite differences of eq. (4).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper import legs as shared
from tpm_viz.paper.kinematics import PERPENDICULAR
from tpm_viz.paper.legs import Legs, as_xy, finite_result, in_stroke
from tpm_viz.paper.status import STATUS_LABELS, WARN, PoseStatus, SingularityThresholds

__all__ = [
    "STATUS_LABELS",
    "Jacobians",
    "SingularityThresholds",
    "actuator_acceleration",
    "actuator_forces_from_platform_force",
    "actuator_forces_through",
    "actuator_velocity",
    "check_regular",
    "classify",
    "classify_of",
    "condition_number",
    "condition_of",
    "cos_sin",
    "eq14_row",
    "jacobians",
    "jacobians_of",
    "platform_force_from_actuator_forces",
    "platform_force_through",
    "platform_velocity",
    "platform_velocity_through",
    "pose_status",
    "theta_dot",
    "velocity_through",
]


#: a scalar [SI] or an array of them, broadcast together (eq. 14 row by row)
FloatOrArray = float | NDArray[np.float64]


class Jacobians(NamedTuple):
    """``J_x``, ``J_q`` (eq. 8), ``J`` (eq. 10) and the two singularity measures (eqs. 11-12)."""

    jx: np.ndarray  # (..., 2, 2)
    jq: np.ndarray  # (..., 2, 2)
    j: np.ndarray  # (..., 2, 2)  d_dot = J p_dot
    det_jx: np.ndarray  # (...,) cos(θ1 + θ2), direct singularity at 0
    det_jq: np.ndarray  # (...,) cos θ1 cos θ2, inverse singularity at 0


def cos_sin(
    legs: Legs, params: Params, p: ArrayLike, d: ArrayLike | None
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """``(p, d, cos θ, sin θ)`` of either arrangement: ``cos θ_i = c_i / l_a``, ``sin θ_i = s_i / l_a`` (eq. 23 /
    P2), ``d`` the working mode's (eq. 4 / P3) unless given; ``p``, ``d`` checked (:func:`as_xy`)."""
    p = as_xy(p)
    d = shared.inverse_kinematics(legs, params, p) if d is None else as_xy(d, "d")
    c, s = legs.components(params, p, d)
    return p, d, c / params.l_a, s / params.l_a


def _row(legs: Legs, i: int, first: np.ndarray, second: np.ndarray, zero: np.ndarray) -> np.ndarray:
    """Row ``i`` with ``σ_i first`` in column ``a_i`` and ``second`` in column ``b_i``."""
    entries = [zero, zero]
    entries[legs.along[i]] = first if legs.sign[i] > 0 else -first
    entries[legs.across[i]] = second
    return np.stack(entries, -1)


def jacobians_of(legs: Legs, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> Jacobians:
    """The Jacobians of either arrangement at ``p`` [m] (dimensionless). Differentiating ``c_i² + s_i² = l_a²``
    (:mod:`tpm_viz.paper.legs`) gives ``J_x ṗ = J_q ḋ`` with row ``i`` of ``J_x`` holding ``σ_i cos θ_i`` in
    column ``a_i`` and ``sin θ_i`` in column ``b_i``, ``J_q = diag(cos θ_i)``, ``J = J_q⁻¹ J_x`` (``σ_i`` and
    ``tan θ_i``): eqs. (8) and (10), ``[[cos θ1, sin θ1], [sin θ2, cos θ2]]``, or eq. (P4),
    ``[[cos θ1, sin θ1], [-cos θ2, sin θ2]]``. ``det J_x`` (eq. 12: ``cos(θ1 + θ2)``; P4: ``sin(θ1 + θ2)``) and
    ``det J_q = cos θ1 cos θ2`` (eq. 11) are the singularity measures."""
    _, _, cos, sin = cos_sin(legs, params, p, d)
    zero = np.zeros_like(cos[..., 0])
    jx = np.stack([_row(legs, i, cos[..., i], sin[..., i], zero) for i in (0, 1)], -2)
    jq = np.stack([np.stack([cos[..., 0], zero], -1), np.stack([zero, cos[..., 1]], -1)], -2)
    with np.errstate(divide="ignore", invalid="ignore"):
        tan = sin / cos
    one = np.ones_like(zero)
    j = np.stack([_row(legs, i, one, tan[..., i], zero) for i in (0, 1)], -2)
    det_jx = jx[..., 0, 0] * jx[..., 1, 1] - jx[..., 0, 1] * jx[..., 1, 0]
    det_jq = cos[..., 0] * cos[..., 1]
    return Jacobians(jx, jq, j, det_jx, det_jq)


def jacobians(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> Jacobians:
    """The Jacobian matrices of eqs. (8) and (10) at ``p`` [m] (dimensionless): ``J_x = [[cos θ1, sin θ1],
    [sin θ2, cos θ2]]``, ``J_q = diag(cos θ_i)``, ``J = [[1, tan θ1], [tan θ2, 1]]``
    (:func:`~tpm_viz.paper.jacobians.jacobians_of`)."""
    return jacobians_of(PERPENDICULAR, params, p, d)


def condition_number(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """2-norm condition number of ``J`` (eq. 10); ``inf`` at a singularity (shape ``(...)``)."""
    return condition_of(jacobians(params, p, d).j)


def condition_of(j: np.ndarray) -> np.ndarray:
    """2-norm condition number ``σ_max / σ_min`` of Jacobians ``j`` (..., 2, 2) of either arrangement (eq. 10 /
    eq. P4); ``inf`` where ``j`` is singular or not finite (shape ``(...)``, dimensionless)."""
    bad = ~np.all(np.isfinite(j), axis=(-2, -1))
    sv = np.linalg.svd(np.where(bad[..., None, None], 0.0, j), compute_uv=False)
    with np.errstate(divide="ignore", invalid="ignore"):
        cond = sv[..., 0] / sv[..., -1]
    return np.where(bad | ~np.isfinite(cond), np.inf, cond)


def classify_of(legs: Legs, params: Params, p: ArrayLike, thresholds: SingularityThresholds = WARN) -> np.ndarray:
    """Status per pose of either arrangement (:func:`pose_status` of its Jacobians at the working mode's ``d``);
    non-finite poses count as unreachable."""
    p = np.asarray(p, dtype=float)
    ok = legs.reachable(params, p)
    safe = np.where(ok[..., None], p, 0.0)
    d = legs.ik(params, safe)
    return pose_status(ok, jacobians_of(legs, params, safe, d), in_stroke(params, d), thresholds)


def classify(params: Params, p: ArrayLike, thresholds: SingularityThresholds = WARN) -> np.ndarray:
    """Status per pose (values of :class:`~tpm_viz.paper.status.PoseStatus`); the most severe condition wins.

    Working-mode inverse kinematics (eq. 4). Non-finite poses count as unreachable.
    """
    return classify_of(PERPENDICULAR, params, p, thresholds)


#: the singularity equations named in a refusal, (inverse, direct), of the paper's arrangement
SINGULARITIES = PERPENDICULAR.singularities


def pose_status(
    ok: np.ndarray, jac: Jacobians, stroke_ok: np.ndarray, thresholds: SingularityThresholds = WARN
) -> np.ndarray:
    """Status per pose from its Jacobians, either arrangement: ``min_i |cos θ_i|`` (the diagonal of ``J_q``)
    against the inverse threshold, ``|det J_x|`` against the direct one, then the stroke, then reachability
    (``ok``); the most severe condition wins."""
    cos = np.stack([jac.jq[..., 0, 0], jac.jq[..., 1, 1]], -1)
    status = np.full(ok.shape, PoseStatus.REGULAR, dtype=int)
    status = np.where(np.min(np.abs(cos), axis=-1) < thresholds.inverse, PoseStatus.NEAR_INVERSE, status)
    status = np.where(np.abs(jac.det_jx) < thresholds.direct, PoseStatus.NEAR_DIRECT, status)
    status = np.where(~stroke_ok, PoseStatus.OUT_OF_STROKE, status)
    return np.where(ok, status, PoseStatus.UNREACHABLE)


def check_regular(jac: Jacobians, which: str, equations: tuple[str, str] = SINGULARITIES) -> None:
    """Refuse (:class:`SingularConfigurationError`) where ``det J_q`` (``which="inverse"``) or ``det J_x``
    (``"direct"``) vanishes, naming the ``equations`` (inverse, direct) of the arrangement."""
    det = jac.det_jq if which == "inverse" else jac.det_jx
    if np.any(np.abs(det) < 1e-12):
        eq = equations[0] if which == "inverse" else equations[1]
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq=eq))


def velocity_through(jac: Jacobians, dp: ArrayLike, equations: tuple[str, str] = SINGULARITIES) -> np.ndarray:
    """``ḋ = J ṗ`` [m/s] with the Jacobians of a pose (eq. 9; refused at an inverse singularity)."""
    check_regular(jac, "inverse", equations)
    with np.errstate(over="ignore", invalid="ignore"):
        return finite_result(np.einsum("...ij,...j->...i", jac.j, as_xy(dp, "dp")), T("the actuator velocities"))


def platform_velocity_through(jac: Jacobians, dd: ArrayLike, equations: tuple[str, str] = SINGULARITIES) -> np.ndarray:
    """``ṗ = J_x⁻¹ J_q ḋ`` [m/s] with the Jacobians of a pose (refused at a direct singularity)."""
    check_regular(jac, "direct", equations)
    with np.errstate(over="ignore", invalid="ignore"):
        rhs = np.einsum("...ij,...j->...i", jac.jq, as_xy(dd, "dd"))
        return finite_result(np.linalg.solve(jac.jx, rhs[..., None])[..., 0], T("the platform velocity"))


def actuator_forces_through(jac: Jacobians, f: ArrayLike, equations: tuple[str, str] = SINGULARITIES) -> np.ndarray:
    """``τ = J⁻ᵀ f`` [N] for a platform force ``f`` [N] with the Jacobians of a pose (eq. 13; eq. P8 in the parallel
    arrangement), computed as ``J_q J_x⁻ᵀ f`` (``J_q`` diagonal): finite at an inverse singularity, refused at a
    direct one (``equations`` name the arrangement's singularities)."""
    check_regular(jac, "direct", equations)
    jxt = np.swapaxes(jac.jx, -1, -2)
    with np.errstate(over="ignore", invalid="ignore"):
        g = np.linalg.solve(jxt, as_xy(f, "f")[..., None])[..., 0]
        return finite_result(np.einsum("...ij,...j->...i", jac.jq, g), T("the actuator forces"))


def platform_force_through(jac: Jacobians, tau: ArrayLike, equations: tuple[str, str] = SINGULARITIES) -> np.ndarray:
    """``f = Jᵀ τ`` [N] for actuator forces ``τ`` [N] with the Jacobians of a pose (eq. 13; eq. P8 in the parallel
    arrangement), refused at an inverse singularity."""
    check_regular(jac, "inverse", equations)
    with np.errstate(over="ignore", invalid="ignore"):
        return finite_result(np.einsum("...ji,...j->...i", jac.j, as_xy(tau, "tau")), T("the platform force"))


def actuator_velocity(params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Actuator velocities ``ḋ = J ṗ`` [m/s], eq. (9)."""
    return velocity_through(jacobians(params, p, d), dp)


def platform_velocity(params: Params, p: ArrayLike, dd: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Platform velocity ``ṗ = J^{-1} ḋ`` [m/s] (inverse of eq. 9; needs ``det J_x != 0``)."""
    return platform_velocity_through(jacobians(params, p, d), dd)


def theta_dot(params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angular rates ``θ̇_i = ṗ_j / (l_a cos θ_i)`` [rad/s], eq. (24)."""
    _, _, cos, _ = cos_sin(PERPENDICULAR, params, p, d)
    if np.any(np.abs(cos) < 1e-12):
        raise SingularConfigurationError("singular configuration: cos θ1 cos θ2 = 0 (eq. 11)")
    with np.errstate(over="ignore", invalid="ignore"):
        return finite_result(as_xy(dp, "dp")[..., ::-1] / (params.l_a * cos), T("the leg angular rates"))


def eq14_row(
    pi: FloatOrArray,
    pj: FloatOrArray,
    dpi: FloatOrArray,
    dpj: FloatOrArray,
    ddpi: FloatOrArray,
    ddpj: FloatOrArray,
    ci: FloatOrArray,
    ddi: FloatOrArray,
) -> FloatOrArray:
    """Row ``i`` of eq. (14) with the corrected eq. (15), for floats or arrays [m/s²].

    With ``cos θ_i = c_i / l_a``, ``sin θ_i = p_j / l_a`` and ``θ̇_i = ṗ_j / c_i`` (eq. 24),
    ``d̈_i = [(J̇_x ṗ)_i + (J_x p̈)_i - (J̇_q ḋ)_i] / cos θ_i`` becomes
    ``θ̇_i (ṗ_j - t_i ṗ_i) + p̈_i + t_i p̈_j + t_i θ̇_i ḋ_i`` where ``t_i = tan θ_i = p_j / c_i``.
    The last term carries the corrected sign of ``J̇_q``.
    """
    ti = pj / ci
    thi = dpj / ci
    return thi * (dpj - ti * dpi) + ddpi + ti * ddpj + ti * thi * ddi


def actuator_acceleration(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    d: ArrayLike | None = None,
    dd: NDArray[np.float64] | None = None,
) -> np.ndarray:
    """Actuator accelerations [m/s²], eq. (14) with the corrected eq. (15).

    ``d̈ = J_q^{-1} (J̇_x ṗ + J_x p̈ - J̇_q ḋ)`` with
    ``J̇_x = [[-sin θ1 θ̇1, cos θ1 θ̇1], [cos θ2 θ̇2, -sin θ2 θ̇2]]`` and
    ``J̇_q = diag(-sin θ1 θ̇1, -sin θ2 θ̇2)`` (the paper prints ``+sin``: erratum). See :func:`eq14_row`.
    """
    p, d, cos, _ = cos_sin(PERPENDICULAR, params, p, d)
    dp, ddp = as_xy(dp, "dp"), as_xy(ddp, "ddp")
    if np.any(np.abs(cos) < 1e-12):
        raise SingularConfigurationError("singular configuration: cos θ1 cos θ2 = 0 (eq. 11)")
    if dd is None:
        dd = actuator_velocity(params, p, dp, d)
    c = cos * params.l_a
    with np.errstate(over="ignore", invalid="ignore"):
        rows = [
            eq14_row(p[..., i], p[..., j], dp[..., i], dp[..., j], ddp[..., i], ddp[..., j], c[..., i], dd[..., i])
            for i, j in ((0, 1), (1, 0))
        ]
    return finite_result(np.stack(rows, -1), T("the actuator accelerations"))


def actuator_forces_from_platform_force(
    params: Params, p: ArrayLike, f: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """Actuator forces ``τ = J^{-T} f`` [N] for a platform force ``f`` [N], eq. (13).

    ``f`` is the force the platform exerts on its surroundings (eq. 13: ``f = J^T τ``). To
    hold an external load ``f_ext`` applied *to* the platform at rest, pass ``f = -f_ext``
    (this is what :func:`tpm_viz.inverse_dynamics` does with zero velocity and acceleration).
    Computed as ``τ = J_q J_x^{-T} f`` (``J_q`` is diagonal), which stays finite at an inverse
    singularity (eq. 11: the leg carries the load with no actuator force along it); raises only
    at the direct singularity (eq. 12).
    """
    return actuator_forces_through(jacobians(params, p, d), f)


def platform_force_from_actuator_forces(
    params: Params, p: ArrayLike, tau: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """Platform force ``f = J^T τ`` [N] for actuator forces ``τ`` [N], eq. (13)."""
    return platform_force_through(jacobians(params, p, d), tau)
