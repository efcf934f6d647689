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
Mass model (``docs/conventions.md``): sliders ``m_a`` and platform ``m_p`` translate; each
parallelogram's two links (together ``m_b``) are uniform slender rods, which gives the
link kinetic energy of eq. (22) read with ``ḋ_i^2`` (the paper prints ``d_i^2``: erratum).
No gravity (horizontal plane, ``U = 0``), no friction. Forces in N, SI throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tpm_viz.errors import SingularConfigurationError
from tpm_viz.paper.jacobians import actuator_velocity, eq14_row
from tpm_viz.paper.kinematics import as_xy, finite_result, inverse_kinematics, leg_components
from tpm_viz.params import Params
from tpm_viz.words import Phrase, T

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


def _v_leg(mp, mb, pi, pj, dpi, dpj, ddpi, ci, cj, ddi, ddj, dddj):
    """``v_i`` below eq. (29) [N]; ``j`` is the other leg. Floats or arrays."""
    return (
        (mp + mb / 3.0) * ddpi
        - mb * pj * ddi * dpj / (2.0 * ci**2)
        + mb * pj**2 * dpj**2 / (3.0 * ci**3)
        + mb * pi * (-(ddj**2) + ddj * dpj - cj * dddj) / (2.0 * cj**2)
        + mb * pi * dpi**2 / (3.0 * cj**2)
        + mb * pi**2 * (2.0 * dpi * (ddj - dpj) + cj * ddpi) / (3.0 * cj**3)
    )


def _w_leg(ma, mb, pj, dpi, dpj, ddpj, ci, dddi):
    """``w_i`` below eq. (31) [N]. Floats or arrays."""
    return (
        (ma + mb) * dddi
        - mb * dpj**2 / (2.0 * ci)
        - mb * pj**2 * dpj**2 / (3.0 * ci**3)
        + mb * pj * (dpi * dpj - ci * ddpj) / (2.0 * ci**2)
    )


def _procedure(params: Params, p1, p2, dp1, dp2, ddp1, ddp2, c1, c2, f1, f2) -> tuple:
    """Steps (b)-(e) on components (floats or equal-shape arrays); ``c_i = p_i - d_i + a - b``.

    Returns ``(dd1, dd2, ddd1, ddd2, v1, v2, w1, w2, lam1, lam2, tau1, tau2)``.
    """
    dd1 = dp1 + p2 * dp2 / c1  # (b) eq. (9): ḋ_i = ṗ_i + tan θ_i ṗ_j
    dd2 = dp2 + p1 * dp1 / c2
    ddd1 = eq14_row(p1, p2, dp1, dp2, ddp1, ddp2, c1, dd1)  # (c) eq. (14)
    ddd2 = eq14_row(p2, p1, dp2, dp1, ddp2, ddp1, c2, dd2)
    mp, ma, mb = params.m_p, params.m_a, params.m_b
    v1 = _v_leg(mp, mb, p1, p2, dp1, dp2, ddp1, c1, c2, dd1, dd2, ddd2) - f1  # eq. (28): v - f
    v2 = _v_leg(mp, mb, p2, p1, dp2, dp1, ddp2, c2, c1, dd2, dd1, ddd1) - f2
    # (d) eq. (29): [[2c1, 2p1], [2p2, 2c2]] λ = v; determinant 4 (c1 c2 - p1 p2) = 4 l_a² det J_x.
    det = 4.0 * (c1 * c2 - p1 * p2)
    lam1 = (2.0 * c2 * v1 - 2.0 * p1 * v2) / det
    lam2 = (2.0 * c1 * v2 - 2.0 * p2 * v1) / det
    w1 = _w_leg(ma, mb, p2, dp1, dp2, ddp2, c1, ddd1)
    w2 = _w_leg(ma, mb, p1, dp2, dp1, ddp1, c2, ddd2)
    return dd1, dd2, ddd1, ddd2, v1, v2, w1, w2, lam1, lam2, w1 + 2.0 * lam1 * c1, w2 + 2.0 * lam2 * c2  # (e)


_SINGULAR_TOL = 1e-12


def _check_regular(params: Params, c1, c2, p1, p2) -> None:
    l2 = params.l_a**2
    if np.any(np.abs(c1 * c2) < _SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="cos θ1 cos θ2 = 0 (eq. 11)"))
    if np.any(np.abs(c1 * c2 - p1 * p2) < _SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="cos(θ1 + θ2) = 0 (eq. 12)"))


def _vectorised(params: Params, p, dp, ddp, f_ext, d) -> tuple:
    p, dp, ddp = np.broadcast_arrays(as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp"))
    d = inverse_kinematics(params, p) if d is None else np.broadcast_to(as_xy(d, "d"), p.shape)  # (a)
    f = np.zeros(2) if f_ext is None else as_xy(f_ext, "f_ext")
    c, _ = leg_components(params, p, d)
    _check_regular(params, c[..., 0], c[..., 1], p[..., 0], p[..., 1])
    with np.errstate(over="ignore", invalid="ignore"):
        out = _procedure(
            params,
            p[..., 0],
            p[..., 1],
            dp[..., 0],
            dp[..., 1],
            ddp[..., 0],
            ddp[..., 1],
            c[..., 0],
            c[..., 1],
            f[..., 0],
            f[..., 1],
        )
    return p, dp, ddp, d, out


def inverse_dynamics_detail(params: Params, p, dp, ddp, f_ext=None, d=None) -> DynamicsResult:
    """The paper's procedure (a)-(e) with every intermediate (see module docstring).

    ``p, dp, ddp`` [m, m/s, m/s²] have shape ``(..., 2)``; ``f_ext`` [N] is an external force
    applied to the platform (eq. 28), broadcastable to ``(..., 2)``; ``d`` selects the branch
    (default: working mode, eq. 4). Raises :class:`SingularConfigurationError` at a singular
    configuration (``cos θ_i = 0`` or ``cos(θ1 + θ2) = 0``).
    """
    p, dp, ddp, d, out = _vectorised(params, p, dp, ddp, f_ext, d)
    dd, ddd, v, w, lam, tau = (np.stack(out[k : k + 2], -1) for k in range(0, 12, 2))
    finite_result(tau, T("the actuator forces"))
    return DynamicsResult(p=p, dp=dp, ddp=ddp, d=d, dd=dd, ddd=ddd, v=v, w=w, lam=lam, tau=tau)


def _inverse_dynamics_one(params: Params, p, dp, ddp, f_ext, d=None) -> np.ndarray | None:
    """Fast path for one state given as length-2 sequences: pure ``math``, no temporaries.

    Returns None when the input is not a plain single state (the caller then vectorises).
    """
    try:
        p1, p2 = float(p[0]), float(p[1])
        dp1, dp2 = float(dp[0]), float(dp[1])
        ddp1, ddp2 = float(ddp[0]), float(ddp[1])
        f1, f2 = (0.0, 0.0) if f_ext is None else (float(f_ext[0]), float(f_ext[1]))
        d1, d2 = (0.0, 0.0) if d is None else (float(d[0]), float(d[1]))
        if d is not None and len(d) != 2:
            return None
    except (TypeError, ValueError, IndexError):
        return None
    vals = (p1, p2, dp1, dp2, ddp1, ddp2, f1, f2, d1, d2)
    if not all(map(math.isfinite, vals)) or not abs(p1) < params.l_a or not abs(p2) < params.l_a:
        return None  # let the vectorised path raise the precise error
    la2 = params.l_a**2
    if d is None:
        c1, c2 = math.sqrt(la2 - p2 * p2), math.sqrt(la2 - p1 * p1)  # eq. (4): c_i = sqrt(l_a² - p_j²)
    else:
        c1, c2 = p1 - d1 + params.offset, p2 - d2 + params.offset  # c_i = l_a cos θ_i on d's branch
    _check_regular(params, c1, c2, p1, p2)
    try:
        out = _procedure(params, p1, p2, dp1, dp2, ddp1, ddp2, c1, c2, f1, f2)
    except OverflowError:
        out = (math.inf,) * 12
    return finite_result(np.array(out[10:12]), T("the actuator forces"))


def inverse_dynamics(params: Params, p, dp, ddp, f_ext=None, d=None) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, by the paper's closed form (eqs. 29, 31).

    See :func:`inverse_dynamics_detail` for the arguments and the intermediates. One state of
    shape ``(2,)`` (with or without ``d``) takes a scalar fast path (same formulas, ~10 µs).
    """
    if np.ndim(p) == 1 and np.ndim(dp) == 1 and np.ndim(ddp) == 1 and np.ndim(f_ext) <= 1 and np.ndim(d) <= 1:
        if len(p) == 2 and len(dp) == 2 and len(ddp) == 2:
            tau = _inverse_dynamics_one(params, p, dp, ddp, f_ext, d)
            if tau is not None:
                return tau
    return finite_result(np.stack(_vectorised(params, p, dp, ddp, f_ext, d)[4][10:12], -1), T("the actuator forces"))


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
