"""The paper's closed-form inverse dynamics (Lagrange's equations of the first kind, eqs. 16-31).

Generalised coordinates ``q = (p_1, p_2, d_1, d_2)`` (eq. 16), constraints
``Γ_i = c_i^2 + p_j^2 - l_a^2`` with ``c_i = p_i - d_i + a - b`` (eq. 27). The procedure of
Section 3, steps (a)-(e):

(a) ``d_i`` from the inverse kinematics, eq. (4);
(b) ``ḋ = J ṗ``, eq. (9);
(c) ``d̈`` from eq. (14) (with the corrected sign of ``J̇_q`` in eq. 15);
(d) multipliers ``λ = G_p^{-1} (v - f_ext)`` with ``G_p = [[2 c_1, 2 p_1], [2 p_2, 2 c_2]]``,
    eqs. (28)-(29);
(e) actuator forces ``τ_i = w_i + 2 λ_i c_i``, eqs. (30)-(31).

``v_i`` and ``w_i`` are the printed expressions below eqs. (29) and (31), written with
``c_i`` in place of ``p_i - d_i + a - b``; both were re-derived and agree with the paper.
Mass model (``conventions.md``): sliders ``m_a`` and platform ``m_p`` translate; each
parallelogram's two links (together ``m_b``) are uniform slender rods, which gives the
link kinetic energy of eq. (22) read with ``ḋ_i^2`` (the paper prints ``d_i^2``: erratum).
No gravity (horizontal plane, ``U = 0``), no friction. Forces in N, SI throughout.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .errors import SingularConfigurationError
from .jacobians import actuator_acceleration, actuator_velocity
from .kinematics import as_xy, inverse_kinematics, leg_components
from .params import Params

__all__ = ["DynamicsResult", "inverse_dynamics", "inverse_dynamics_detail", "kinetic_energy"]


@dataclass(frozen=True)
class DynamicsResult:
    """Every intermediate of the procedure (a)-(e); arrays of shape ``(..., 2)`` in SI units."""

    p: np.ndarray  # platform position [m]
    dp: np.ndarray  # platform velocity [m/s]
    ddp: np.ndarray  # platform acceleration [m/s^2]
    d: np.ndarray  # (a) actuator positions [m]
    dd: np.ndarray  # (b) actuator velocities [m/s]
    ddd: np.ndarray  # (c) actuator accelerations [m/s^2]
    v: np.ndarray  # eq. (29) right-hand side v_i [N]
    w: np.ndarray  # eq. (31) w_i [N]
    lam: np.ndarray  # (d) Lagrange multipliers λ_i [N/m]
    tau: np.ndarray  # (e) actuator forces τ_i [N]


def _v_terms(params: Params, p, dp, ddp, d, dd, ddd, c) -> np.ndarray:
    """``v_i`` below eq. (29) [N] (``i`` along the last axis, ``j`` the other leg)."""
    mp, mb = params.m_p, params.m_b
    pi, pj = p, p[..., ::-1]
    dpi, dpj = dp, dp[..., ::-1]
    ddpi = ddp
    ddi, ddj = dd, dd[..., ::-1]
    dddj = ddd[..., ::-1]
    ci, cj = c, c[..., ::-1]
    return (
        (mp + mb / 3.0) * ddpi
        - mb * pj * ddi * dpj / (2.0 * ci**2)
        + mb * pj**2 * dpj**2 / (3.0 * ci**3)
        + mb * pi * (-(ddj**2) + ddj * dpj - cj * dddj) / (2.0 * cj**2)
        + mb * pi * dpi**2 / (3.0 * cj**2)
        + mb * pi**2 * (2.0 * dpi * (ddj - dpj) + cj * ddpi) / (3.0 * cj**3)
    )


def _w_terms(params: Params, p, dp, ddp, ddd, c) -> np.ndarray:
    """``w_i`` below eq. (31) [N]."""
    ma, mb = params.m_a, params.m_b
    pj = p[..., ::-1]
    dpi, dpj = dp, dp[..., ::-1]
    ddpj = ddp[..., ::-1]
    return (
        (ma + mb) * ddd
        - mb * dpj**2 / (2.0 * c)
        - mb * pj**2 * dpj**2 / (3.0 * c**3)
        + mb * pj * (dpi * dpj - c * ddpj) / (2.0 * c**2)
    )


def inverse_dynamics_detail(params: Params, p, dp, ddp, f_ext=None, d=None) -> DynamicsResult:
    """The paper's procedure (a)-(e) with every intermediate (see module docstring).

    ``p, dp, ddp`` [m, m/s, m/s²] have shape ``(..., 2)``; ``f_ext`` [N] is an external force
    applied to the platform (eq. 28), broadcastable to ``(..., 2)``; ``d`` selects the branch
    (default: working mode, eq. 4). Raises :class:`SingularConfigurationError` at a singular
    configuration (``cos θ_i = 0`` or ``cos(θ1 + θ2) = 0``).
    """
    p, dp, ddp = as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp")
    p, dp, ddp = np.broadcast_arrays(p, dp, ddp)
    d = inverse_kinematics(params, p) if d is None else np.broadcast_to(as_xy(d, "d"), p.shape)  # (a)
    dd = actuator_velocity(params, p, dp, d)  # (b)
    ddd = actuator_acceleration(params, p, dp, ddp, d, dd)  # (c)
    c, _ = leg_components(params, p, d)
    v = _v_terms(params, p, dp, ddp, d, dd, ddd, c)
    if f_ext is not None:
        v = v - as_xy(f_ext, "f_ext")  # eq. (28): the bracket is v - f
    # (d) eq. (29): [[2c1, 2p1], [2p2, 2c2]] λ = v; determinant 4 (c1 c2 - p1 p2) ∝ det J_x.
    g11, g12, g21, g22 = 2 * c[..., 0], 2 * p[..., 0], 2 * p[..., 1], 2 * c[..., 1]
    det = g11 * g22 - g12 * g21
    if np.any(np.abs(det) < 1e-12 * params.l_a**2):
        raise SingularConfigurationError("singular configuration: cos(θ1 + θ2) = 0 (eq. 12)")
    lam = np.stack(
        [(g22 * v[..., 0] - g12 * v[..., 1]) / det, (-g21 * v[..., 0] + g11 * v[..., 1]) / det], -1
    )
    w = _w_terms(params, p, dp, ddp, ddd, c)
    tau = w + 2.0 * lam * c  # (e) eq. (31)
    return DynamicsResult(p=p, dp=dp, ddp=ddp, d=d, dd=dd, ddd=ddd, v=v, w=w, lam=lam, tau=tau)


def inverse_dynamics(params: Params, p, dp, ddp, f_ext=None, d=None) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, by the paper's closed form (eqs. 29, 31).

    See :func:`inverse_dynamics_detail` for the arguments and the intermediates.
    """
    return inverse_dynamics_detail(params, p, dp, ddp, f_ext, d).tau


def kinetic_energy(params: Params, p, dp, d=None) -> np.ndarray:
    """Total kinetic energy ``K`` [J] of eqs. (20)-(22) (``ḋ_i^2`` read for ``d_i^2`` in eq. 22)."""
    p, dp = as_xy(p), as_xy(dp, "dp")
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    dd = actuator_velocity(params, p, dp, d)
    c, s = leg_components(params, p, d)
    th_dot = dp[..., ::-1] / c  # eq. (24): θ̇_i = ṗ_j / (l_a cos θ_i), l_a cos θ_i = c_i
    sin = s / params.l_a
    la, ma, mb = params.l_a, params.m_a, params.m_b
    k_p = 0.5 * params.m_p * np.sum(dp**2, axis=-1)
    k_a = 0.5 * ma * np.sum(dd**2, axis=-1)
    k_b = np.sum(mb * la**2 * th_dot**2 / 6.0 + 0.5 * mb * (dd**2 - la * dd * th_dot * sin), axis=-1)
    return k_p + k_a + k_b
