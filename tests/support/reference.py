"""Independent reference routes for the tests (written from first principles, not from tpm_viz).

- ``ik_quadratic``: eq. (3) solved as the general quadratic ``|m_i - d e_i|^2 = l_a^2``.
- ``rod_kinetic_energy``: kinetic energy of the rigid bodies (sliders, four uniform rods,
  platform) computed from the velocities of the joints. For a uniform rod whose ends move with
  velocities ``u`` and ``w``, ``K = m/6 (|u|^2 + u.w + |w|^2)``.
- ``minimal_coordinate_forces``: actuator forces from the minimal-coordinate Lagrangian in
  ``p``: ``F_p = d/dt(∂T/∂ṗ) - ∂T/∂p`` by central finite differences of ``T``, then
  ``J^T τ = F_p - f_ext`` (virtual work), with ``J`` itself from finite differences of eq. (3).
"""

from __future__ import annotations

import math

import numpy as np

E = np.eye(2)


def ik_quadratic(params, p, root=-1):
    """Eq. (3): ``d_i = m_i.e_i ± sqrt((m_i.e_i)^2 - m_i.m_i + l_a^2)``, ``m_i = p + (a - b) e_i``."""
    p = np.asarray(p, float)
    d = np.empty(2)
    for i in range(2):
        m = p + (params.a - params.b) * E[i]
        me = m @ E[i]
        d[i] = me + root * math.sqrt(me**2 - m @ m + params.l_a**2)
    return d


def jacobian_fd(params, p, h=1e-7):
    """``∂d/∂p`` by central differences of :func:`ik_quadratic`."""
    cols = [(ik_quadratic(params, p + h * e) - ik_quadratic(params, p - h * e)) / (2 * h) for e in E]
    return np.stack(cols, axis=1)


def rod_kinetic_energy(params, p, dp):
    """Total kinetic energy [J] from body velocities; actuator velocities by FD of eq. (3)."""
    dp = np.asarray(dp, float)
    dd = jacobian_fd(params, p) @ dp
    k = 0.5 * params.m_p * dp @ dp + 0.5 * params.m_a * dd @ dd
    for i in range(2):
        u, w = dd[i] * E[i], dp  # slider-side and platform-side pivots of both links
        k += 2 * (params.m_b / 2) / 6 * (u @ u + u @ w + w @ w)
    return k


def _kinetic_quadratic(params, p, dp):
    """Same energy with an exact Jacobian from the geometry (for the second derivatives)."""
    dp = np.asarray(dp, float)
    p = np.asarray(p, float)
    k = 0.5 * params.m_p * dp @ dp
    for i in range(2):
        j = 1 - i
        c = math.sqrt(params.l_a**2 - p[j] ** 2)  # e_i component of l_a s_i
        ddi = dp[i] + p[j] * dp[j] / c  # from d_i = p_i + a - b - c
        u, w = ddi * E[i], dp
        k += 0.5 * params.m_a * ddi**2 + params.m_b / 6 * (u @ u + u @ w + w @ w)
    return k


def minimal_coordinate_forces(params, p, dp, ddp, f_ext=(0.0, 0.0), h=1e-5):
    """Actuator forces [N] from the minimal-coordinate Lagrangian by finite differences."""
    p, dp, ddp = (np.asarray(x, float) for x in (p, dp, ddp))

    def dT_ddp(q, v):
        return np.array(
            [(_kinetic_quadratic(params, q, v + h * e) - _kinetic_quadratic(params, q, v - h * e)) / (2 * h) for e in E]
        )

    def dT_dp(q, v):
        return np.array(
            [(_kinetic_quadratic(params, q + h * e, v) - _kinetic_quadratic(params, q - h * e, v)) / (2 * h) for e in E]
        )

    dt = 1e-5
    ahead = dT_ddp(p + dp * dt + 0.5 * ddp * dt**2, dp + ddp * dt)
    behind = dT_ddp(p - dp * dt + 0.5 * ddp * dt**2, dp - ddp * dt)
    f_p = (ahead - behind) / (2 * dt) - dT_dp(p, dp)
    jac = jacobian_fd(params, p)
    return np.linalg.solve(jac.T, f_p - np.asarray(f_ext, float))
