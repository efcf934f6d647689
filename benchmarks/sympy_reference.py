"""An independent inverse dynamics for the benchmarks: sympy from the Lagrangian, lambdified for numpy.

Not from the closed form (eqs. 29-31) and not from tpm_viz: the kinetic energy of the rigid bodies in the minimal
coordinates ``p``, Lagrange's equations of the second kind, and virtual work for the actuators.

- Inverse kinematics (eq. 3, working mode): ``d_i = p_i + a - b - sqrt(l_a² - p_j²)``.
- Kinetic energy: platform ``m_p |ṗ|²/2``; slider ``m_a ḋ_i²/2``; the two links of leg ``i`` (together ``m_b``,
  uniform rods whose ends move with ``u = ḋ_i e_i`` and ``w = ṗ``): ``m_b/6 (|u|² + u·w + |w|²)``.
- Generalised forces ``F = d/dt ∂T/∂ṗ - ∂T/∂p``, expanded by the chain rule; virtual work
  ``Jᵀ τ + f_ext = F`` with ``J = ∂d/∂p``, so ``τ = J^{-T} (F - f_ext)``.

sympy derives ``τ`` once at import (a few seconds) and ``lambdify(..., "numpy", cse=True)`` turns it into one
numpy function of scalars or arrays: the kind of implementation a careful engineer would generate by machine.
``tests/paper/test_sympy_reference.py`` checks it agrees with :func:`tpm_viz.inverse_dynamics`.
"""

from __future__ import annotations

import sympy as sp

__all__ = ["reference_inverse_dynamics"]


def _derive():
    a, b, la, ma, mb, mp = sp.symbols("a b l_a m_a m_b m_p", positive=True)
    p = sp.Matrix(sp.symbols("p1 p2", real=True))
    dp = sp.Matrix(sp.symbols("dp1 dp2", real=True))
    ddp = sp.Matrix(sp.symbols("ddp1 ddp2", real=True))
    f = sp.Matrix(sp.symbols("f1 f2", real=True))
    d = sp.Matrix([p[0] + a - b - sp.sqrt(la**2 - p[1] ** 2), p[1] + a - b - sp.sqrt(la**2 - p[0] ** 2)])
    jac = d.jacobian(p)
    dd = jac * dp
    e = sp.eye(2)
    energy = mp * (dp.T * dp)[0] / 2
    for i in range(2):
        u = dd[i] * e[:, i]
        energy += ma * dd[i] ** 2 / 2 + mb / 6 * ((u.T * u)[0] + (u.T * dp)[0] + (dp.T * dp)[0])
    grad_v = sp.Matrix([sp.diff(energy, v) for v in dp])
    forces = grad_v.jacobian(dp) * ddp + grad_v.jacobian(p) * dp - sp.Matrix([sp.diff(energy, q) for q in p])
    tau = jac.T.inv() * (forces - f)
    args = [a, b, la, ma, mb, mp, *p, *dp, *ddp, *f]
    return sp.lambdify(args, [tau[0], tau[1]], "numpy", cse=True)


_TAU = _derive()


def reference_inverse_dynamics(params, p1, p2, dp1, dp2, ddp1, ddp2, f1=0.0, f2=0.0):
    """``(τ_1, τ_2)`` [N] for floats or equal-shape arrays (``params``: anything with ``a, b, l_a, m_a, m_b, m_p``)."""
    return _TAU(
        params.a, params.b, params.l_a, params.m_a, params.m_b, params.m_p, p1, p2, dp1, dp2, ddp1, ddp2, f1, f2
    )
