"""Closed-form inverse dynamics of the parallel 2-PPa, in the paper's framework (Lagrange, first kind).

Derivation: ``docs/parallel.md`` (eqs. P9-P15, the analogues of the paper's eqs. 16-31). Generalised coordinates
``q = (p_1, p_2, d_1, d_2)``, constraints ``Γ_i = c_i² + p_2² - l_a²`` with ``c_1 = p_1 - d_1 + a - b`` and
``c_2 = -p_1 - d_2 + a - b`` (eq. P2). Same mass model as the paper (``docs/conventions.md``): sliders ``m_a`` and
platform ``m_p`` translate, each parallelogram is two uniform rods of ``m_b/2``. Written with the rod's end
velocities, the kinetic energy is a constant quadratic form in ``q̇`` (eq. P9), so ``∂K/∂q = 0``:

(a) ``d`` from eq. (P3);
(b) ``ḋ = J ṗ`` (eq. P4);
(c) ``d̈`` (eq. P5);
(d) ``G_p λ = v - f_ext`` with ``G_p = [[2c_1, -2c_2], [2p_2, 2p_2]]``, ``v_1 = m_P p̈_1 + (m_b/6)(d̈_1 - d̈_2)``,
    ``v_2 = m_P p̈_2``, ``m_P = m_p + 2 m_b / 3`` (eqs. P11-P12);
(e) ``τ_i = w_i + 2 λ_i c_i`` with ``w_1 = m_A d̈_1 + (m_b/6) p̈_1``, ``w_2 = m_A d̈_2 - (m_b/6) p̈_1``,
    ``m_A = m_a + m_b / 3`` (eqs. P13-P14).

No gravity (horizontal plane), no friction; forces in N, SI throughout.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.dynamics import SINGULAR_TOL, DynamicsResult
from tpm_viz.paper.legs import as_xy, finite_result
from tpm_viz.paper.parallel.kinematics import actuator_velocity, inverse_kinematics, jacobians, leg_components

__all__ = ["coordinate_mass_matrix", "inverse_dynamics", "inverse_dynamics_detail", "kinetic_energy", "mass_matrix"]


def coordinate_mass_matrix(params: Params) -> np.ndarray:
    """The constant ``4 x 4`` mass matrix [kg] of ``K = ½ q̇ᵀ M_q q̇`` in ``q = (p_1, p_2, d_1, d_2)`` (eq. P10)."""
    mp = params.m_p + 2.0 * params.m_b / 3.0
    ma = params.m_a + params.m_b / 3.0
    x = params.m_b / 6.0
    return np.array([[mp, 0.0, x, -x], [0.0, mp, 0.0, 0.0], [x, 0.0, ma, 0.0], [-x, 0.0, 0.0, ma]])


def _procedure(
    params: Params,
    p: NDArray[np.float64],
    dp: NDArray[np.float64],
    ddp: NDArray[np.float64],
    c: NDArray[np.float64],
    f: NDArray[np.float64],
) -> tuple[NDArray[np.float64], ...]:
    """Steps (b)-(e) on arrays of shape ``(..., 2)``; returns ``(dd, ddd, v, w, lam, tau)``."""
    p2 = p[..., 1]
    dp1, dp2 = dp[..., 0], dp[..., 1]
    ddp1, ddp2 = ddp[..., 0], ddp[..., 1]
    c1, c2 = c[..., 0], c[..., 1]
    dd1 = dp1 + p2 * dp2 / c1  # (b) eq. (P4)
    dd2 = -dp1 + p2 * dp2 / c2
    cd1, cd2 = -p2 * dp2 / c1, -p2 * dp2 / c2  # ċ_i = -p_2 ṗ_2 / c_i
    common = dp2**2 + p2 * ddp2
    ddd1 = ddp1 + (cd1**2 + common) / c1  # (c) eq. (P5)
    ddd2 = -ddp1 + (cd2**2 + common) / c2
    m_plat = params.m_p + 2.0 * params.m_b / 3.0
    m_act = params.m_a + params.m_b / 3.0
    x = params.m_b / 6.0
    v1 = m_plat * ddp1 + x * (ddd1 - ddd2)  # eq. (P11)
    v2 = m_plat * ddp2
    r1, r2 = v1 - f[..., 0], v2 - f[..., 1]
    det = 4.0 * p2 * (c1 + c2)  # (d) eq. (P12): det G_p = 4 l_a² det J_x
    lam1 = (2.0 * p2 * r1 + 2.0 * c2 * r2) / det
    lam2 = (2.0 * c1 * r2 - 2.0 * p2 * r1) / det
    w1 = m_act * ddd1 + x * ddp1  # eq. (P13)
    w2 = m_act * ddd2 - x * ddp1
    tau = np.stack([w1 + 2.0 * lam1 * c1, w2 + 2.0 * lam2 * c2], -1)  # (e) eq. (P14)
    pairs = ((dd1, dd2), (ddd1, ddd2), (v1, v2), (w1, w2), (lam1, lam2))
    return (*(np.stack(pair, -1) for pair in pairs), tau)


def _check_regular(params: Params, p: np.ndarray, c: np.ndarray) -> None:
    l2 = params.l_a**2
    if np.any(np.abs(c[..., 0] * c[..., 1]) < SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="cos θ1 cos θ2 = 0"))
    if np.any(np.abs(p[..., 1] * (c[..., 0] + c[..., 1])) < SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="sin(θ1 + θ2) = 0"))


def inverse_dynamics_detail(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None = None,
    d: ArrayLike | None = None,
) -> DynamicsResult:
    """Steps (a)-(e) with every intermediate (the perpendicular one's :class:`DynamicsResult`).

    ``p, dp, ddp`` [m, m/s, m/s²] of shape ``(..., 2)``; ``f_ext`` [N] applied to the platform, broadcastable;
    ``d`` selects the branch (default: working mode, eq. P3). Raises :class:`SingularConfigurationError` at
    ``cos θ_i = 0`` or ``det J_x = sin(θ1 + θ2) = 0`` (working mode: ``p_2 = 0``).
    """
    p, dp, ddp = np.broadcast_arrays(as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp"))
    d = inverse_kinematics(params, p) if d is None else np.broadcast_to(as_xy(d, "d"), p.shape)  # (a)
    f = np.zeros(2) if f_ext is None else as_xy(f_ext, "f_ext")
    c, _ = leg_components(params, p, d)
    _check_regular(params, p, c)
    with np.errstate(over="ignore", invalid="ignore"):
        dd, ddd, v, w, lam, tau = _procedure(params, p, dp, ddp, c, f)
    finite_result(tau, T("the actuator forces"))
    return DynamicsResult(p=p, dp=dp, ddp=ddp, d=d, dd=dd, ddd=ddd, v=v, w=w, lam=lam, tau=tau)


def inverse_dynamics(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None = None,
    d: ArrayLike | None = None,
) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, by the closed form of eq. (P14) (see the module docstring)."""
    return inverse_dynamics_detail(params, p, dp, ddp, f_ext, d).tau


def kinetic_energy(params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Total kinetic energy ``K = ½ q̇ᵀ M_q q̇`` [J] (eq. P9), ``q̇ = (ṗ, J ṗ)``."""
    p, dp = as_xy(p), as_xy(dp, "dp")
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    qd = np.concatenate([dp, actuator_velocity(params, p, dp, d)], axis=-1)
    return 0.5 * np.einsum("...i,ij,...j->...", qd, coordinate_mass_matrix(params), qd)


def mass_matrix(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """The platform-space mass matrix ``M(p) = Tᵀ M_q T`` [kg], ``T = [I; J]`` (eq. P15), shape ``(..., 2, 2)``:
    ``K = ½ ṗᵀ M(p) ṗ`` and, at rest, ``τ = J⁻ᵀ (M(p) p̈ - f_ext)``."""
    p = as_xy(p)
    j = jacobians(params, p, d).j
    eye = np.broadcast_to(np.eye(2), j.shape)
    t = np.concatenate([eye, j], axis=-2)
    return np.einsum("...ki,kl,...lj->...ij", t, coordinate_mass_matrix(params), t)
