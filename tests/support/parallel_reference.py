"""Independent reference routes for the parallel arrangement (written from the geometry, not from tpm_viz).

- ``ik_quadratic``: ``|B_i - A_i|² = l_a²`` solved as a quadratic in ``d_i`` (root chosen so the legs lean inwards);
- ``joints``: the positions of ``A_1, A_2, B_1, B_2``;
- ``mass_matrix_ref``: ``K = ½ ṗᵀ M ṗ`` from rigid bodies: point masses, and each rod as ``½ m |v_G|² + ½ (m l²/12) ω²``
  with ``v_G`` and ``ω`` from central differences of the joint positions and the rod angle (not the end-velocity
  formula the library uses);
- ``minimal_coordinate_forces``: ``F_p = d/dt(M ṗ) - ½ ṗᵀ (∂M/∂p) ṗ`` by finite differences, then
  ``Jᵀ τ = F_p - f_ext`` (virtual work) with ``J`` from finite differences of ``ik_quadratic``.
"""

from __future__ import annotations

import math

import numpy as np

E = np.eye(2)


def ik_quadratic(params, p) -> np.ndarray:
    """``(p_1 - b - (d_1 - a))² + p_2² = l_a²`` and ``(p_1 + b - (a - d_2))² + p_2² = l_a²``, inward roots."""
    p1, p2 = float(p[0]), float(p[1])
    r = math.sqrt(params.l_a**2 - p2**2)
    # leg 1: d_1 = p_1 - b + a ± r; inwards (A_1 left of B_1) is the minus root
    # leg 2: d_2 = a - b - p_1 ± r; inwards (A_2 right of B_2) is the minus root
    return np.array([p1 - params.b + params.a - r, params.a - params.b - p1 - r])


def joints(params, p) -> np.ndarray:
    """``[A_1, A_2, B_1, B_2]`` (4, 2) [m] in the working mode."""
    d = ik_quadratic(params, p)
    p = np.asarray(p, float)
    return np.array(
        [[d[0] - params.a, 0.0], [params.a - d[1], 0.0], p - np.array([params.b, 0.0]), p + np.array([params.b, 0.0])]
    )


def _d5(f, h):
    """Five-point central difference ``f'(0)`` of a function of one scalar (error O(h⁴))."""
    return (f(-2 * h) - 8 * f(-h) + 8 * f(h) - f(2 * h)) / (12 * h)


def jacobian_fd(params, p, h=1e-7) -> np.ndarray:
    """``∂d/∂p`` by central differences of :func:`ik_quadratic`."""
    p = np.asarray(p, float)
    return np.stack([(ik_quadratic(params, p + h * e) - ik_quadratic(params, p - h * e)) / (2 * h) for e in E], 1)


def _coords(params, p) -> np.ndarray:
    """Every coordinate whose rate enters K: slider positions, rod centres, rod angles, platform."""
    a1, a2, b1, b2 = joints(params, p)
    ang = [math.atan2(*(b1 - a1)[::-1]), math.atan2(*(b2 - a2)[::-1])]
    return np.concatenate([a1, a2, (a1 + b1) / 2, (a2 + b2) / 2, ang, np.asarray(p, float)])


def mass_matrix_ref(params, p, h=1e-4) -> np.ndarray:
    """``M(p)`` (2, 2) [kg] of the rigid bodies (see the module docstring)."""
    p = np.asarray(p, float)
    jac = np.stack([_d5(lambda t, e=e: _coords(params, p + t * e), h) for e in E], 1)
    mb, la = params.m_b, params.l_a
    # per coordinate: slider xy (m_a), rod centre xy (m_b: two rods of m_b/2 move alike), angles (I), platform xy
    w = np.array([params.m_a] * 4 + [mb] * 4 + [mb * la**2 / 12] * 2 + [params.m_p] * 2)
    return jac.T @ (w[:, None] * jac)


def kinetic_energy_ref(params, p, dp) -> float:
    dp = np.asarray(dp, float)
    return float(0.5 * dp @ mass_matrix_ref(params, p) @ dp)


def minimal_coordinate_forces(params, p, dp, ddp, f_ext=(0.0, 0.0), h=2e-4, dt=2e-4) -> np.ndarray:
    """Actuator forces [N] from the minimal-coordinate Lagrangian by (five-point) finite differences."""
    p, dp, ddp = (np.asarray(x, float) for x in (p, dp, ddp))

    def momentum(t):
        q, v = p + dp * t + 0.5 * ddp * t**2, dp + ddp * t
        return mass_matrix_ref(params, q) @ v

    dmom = _d5(momentum, dt)
    dm = [_d5(lambda t, e=e: mass_matrix_ref(params, p + t * e), h) for e in E]
    f_p = dmom - 0.5 * np.array([dp @ m @ dp for m in dm])
    return np.linalg.solve(jacobian_fd(params, p).T, f_p - np.asarray(f_ext, float))
