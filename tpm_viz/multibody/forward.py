"""Forward dynamics of the closed-loop Pinocchio model: the KKT solve, the projection, the 2-DOF plant.

Two routes, both on the Pinocchio tree of :mod:`tpm_viz.multibody.model` (this module imports no
Pinocchio itself: it calls the model's evaluations):

- :func:`forward_dynamics` (with :func:`project`): joint accelerations of the 7 tree coordinates with
  the closures as constraints, on the null space that an SVD of ``J_c`` reveals (Gauss's principle).
  General, ~200 µs a call; the replay (:mod:`tpm_viz.multibody.replay`) uses it.
- :class:`PlatformPlant`: the same dynamics in the 2 independent coordinates ``p`` (coordinate
  partitioning). In the working mode the closures are solved in closed form, ``q = q(p)``, ``v = N(p) ṗ``
  and ``a = N(p) p̈ + a_0(p, ṗ)`` (``N = ∂q/∂p``, ``a_0`` the joint accelerations at ``p̈ = 0``); the
  equations of motion projected on the admissible motions are
  ``Nᵀ M N p̈ = Nᵀ Sᵀ τ - Nᵀ (M a_0 + C v)``, where ``Nᵀ Sᵀ = Jᵀ`` (eq. 13) and ``M N``,
  ``M a_0 + C v`` are three calls of Pinocchio's ``rnea`` (no gravity). ~15 µs a call, no constraint
  drift (the coordinates are minimal). The tests check ``q(p)`` against Pinocchio's closure residual,
  ``N`` against the null space of ``J_c`` and the accelerations against :func:`forward_dynamics`.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from typing import Any, Protocol

import numpy as np

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.multibody.assembly import DOF, NEWTON_FLOOR, NEWTON_MAX_ITER, NEWTON_TOL
from tpm_viz.multibody.rank import RankedSvd, ranked_svd
from tpm_viz.paper.plant import leg_cosines

__all__ = ["ClosedLoopModel", "PlatformPlant", "forward_dynamics", "project"]


class ClosedLoopModel(Protocol):
    """What this module uses of a :class:`~tpm_viz.multibody.model.MultibodyModel` (its Pinocchio evaluations)."""

    params: Params
    model: Any  # pinocchio.Model (Pinocchio ships no type information)
    index: dict[str, int]
    _s_t: np.ndarray

    def _closure_terms(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def _closure_svd(self, jc: np.ndarray) -> RankedSvd: ...

    def _drifts(self, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]: ...

    def _mass_matrix(self, q: np.ndarray) -> np.ndarray: ...

    def _nle(self, q: np.ndarray, v: np.ndarray) -> np.ndarray: ...

    def rnea_function(self) -> Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray]: ...


def forward_dynamics(model: ClosedLoopModel, q: np.ndarray, v: np.ndarray, tau: np.ndarray) -> np.ndarray:
    """Joint accelerations ``a`` (7,) [m/s², rad/s²] of ``model`` under actuator forces ``τ`` (2,) [N].

    Our own KKT solve (Gauss's principle) on the rank-revealed null space ``N`` of ``J_c``:
    ``a = a_c + N z`` with ``a_c = -J_c⁺ γ`` and ``(Nᵀ M N) z = Nᵀ (Sᵀ τ - nle - M a_c)``, ``M`` from
    ``crba`` and ``nle`` from Pinocchio. It is direct and exact with the redundant rows. The proximal
    ``pinocchio.constraintDynamics`` returns the same ``a`` (the tests check it), but with these
    redundant rows its reported residual never converges and it often runs to ``max_iter``, so it
    cannot tell a good step from a bad one.
    """
    svd = model._closure_svd(model._closure_terms(q)[1])
    n = svd.null_space
    gamma, _ = model._drifts(q, v)
    mass = model._mass_matrix(q)
    a_c = -svd.solve(gamma)
    rhs = model._s_t @ tau - model._nle(q, v) - mass @ a_c
    return a_c + n @ np.linalg.solve(n.T @ mass @ n, n.T @ rhs)


def project(model: ClosedLoopModel, q: np.ndarray, v: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Constraint stabilisation: the nearest ``q`` on the closures (minimum-norm Newton steps)
    and ``v`` projected on the admissible motions ``N Nᵀ v``."""
    q, previous = q.copy(), np.inf
    for _ in range(NEWTON_MAX_ITER):
        phi, jc = model._closure_terms(q)
        err = np.max(np.abs(phi))
        if err < NEWTON_FLOOR or (err < NEWTON_TOL and err > 0.5 * previous):
            break
        previous = err
        # Off the closures the redundant row is not exactly redundant (rank 6, σ_6 ~ the gap):
        # step on the 5 dominant directions only, the rank the constraints have on the closures.
        q -= ranked_svd(jc)._replace(rank=model.model.nv - DOF).solve(phi)
    else:
        raise SingularConfigurationError("the closures cannot be re-assembled (constraint drift too large)")
    n = model._closure_svd(jc).null_space
    return q, n @ (n.T @ v)


class PlatformPlant:
    """The closed-loop Pinocchio model reduced to the platform coordinates ``p`` (see the module docstring).

    Working mode only (``cos θ_i > 0``, eq. 4): ``sin θ_1 = p_2 / l_a``, ``sin θ_2 = p_1 / l_a``,
    ``d_i = p_i + a - b - l_a cos θ_i``; the link angles are ``φ_1k = θ_1``, ``φ_2k = -θ_2`` and the
    platform joint ``φ_p = -θ_1`` (:mod:`tpm_viz.multibody.model`). Not thread-safe (one ``Data`` each).
    """

    def __init__(self, model: ClosedLoopModel) -> None:
        self.params = model.params
        ix = model.index
        self._slots = (
            ix["slider1"],
            ix["link1_0"],
            ix["link1_1"],
            ix["platform"],
            ix["slider2"],
            ix["link2_0"],
            ix["link2_1"],
        )
        if self._slots != (0, 1, 3, 2, 4, 5, 6):  # the depth-first order of model._build
            raise AssertionError(f"unexpected joint order {self._slots}")
        self._rnea = model.rnea_function()
        self._zero = np.zeros(model.model.nv)
        self._la, self._k = self.params.l_a, self.params.offset

    def _place(self, d1: float, f1: float, fp: float, d2: float, f2: float) -> np.ndarray:
        """A joint vector (7,) from the slider, leg-1 link, platform, slider-2 and leg-2 link values."""
        i_d1, i_10, i_11, i_p, i_d2, i_20, i_21 = self._slots
        out = [0.0] * 7
        out[i_d1], out[i_10], out[i_11], out[i_p], out[i_d2], out[i_20], out[i_21] = d1, f1, f1, fp, d2, f2, f2
        return np.array(out)

    def _legs(self, p1: float, p2: float) -> tuple[float, float]:
        """``c_i = l_a cos θ_i`` [m]; raises when the pose leaves the working mode's domain."""
        return leg_cosines(self._la, p1, p2)

    def joint_state(
        self,
        p: Sequence[float] | np.ndarray,
        dp: Sequence[float] | np.ndarray,
        ddp: Sequence[float] | np.ndarray = (0.0, 0.0),
    ) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Tree coordinates ``(q, v, a)`` (7,) each for a platform state ``p, ṗ, p̈`` [m, m/s, m/s²]."""
        (p1, p2), (dp1, dp2), (ddp1, ddp2) = (map(float, x) for x in (p, dp, ddp))
        c1, c2 = self._legs(p1, p2)
        t1, t2, w1, w2 = p2 / c1, p1 / c2, dp2 / c1, dp1 / c2  # tan θ_i and θ̇_i (eq. 24)
        th1, th2 = math.asin(p2 / self._la), math.asin(p1 / self._la)
        q = self._place(p1 + self._k - c1, th1, -th1, p2 + self._k - c2, -th2)
        v = self._place(dp1 + t1 * dp2, w1, -w1, dp2 + t2 * dp1, -w2)
        # θ̈_i = (p̈_j + l_a sin θ_i θ̇_i²) / c_i and d̈_i = p̈_i + l_a (cos θ_i θ̇_i² + sin θ_i θ̈_i).
        a1, a2 = (ddp2 + p2 * w1 * w1) / c1, (ddp1 + p1 * w2 * w2) / c2
        a = self._place(ddp1 + c1 * w1 * w1 + p2 * a1, a1, -a1, ddp2 + c2 * w2 * w2 + p1 * a2, -a2)
        return q, v, a

    def null_space(self, p: Sequence[float] | np.ndarray) -> np.ndarray:
        """``N = ∂q/∂p`` (7, 2): joint velocities per unit platform velocity."""
        p1, p2 = float(p[0]), float(p[1])
        c1, c2 = self._legs(p1, p2)
        return np.stack(
            [self._place(1.0, 0.0, 0.0, p1 / c2, -1.0 / c2), self._place(p2 / c1, 1.0 / c1, -1.0 / c1, 1.0, 0.0)], -1
        )

    def acceleration(
        self, p1: float, p2: float, dp1: float, dp2: float, tau1: float, tau2: float
    ) -> tuple[float, float]:
        """Platform acceleration ``p̈`` [m/s²] (two floats) under actuator forces ``τ`` [N], from
        ``Nᵀ M N p̈ = Jᵀ τ - Nᵀ rnea(q, v, a_0)`` (module docstring). Plain floats and three ``rnea``
        calls: this is the inner loop of the control lab (4 calls per RK4 step)."""
        c1, c2 = self._legs(p1, p2)
        t1, t2, w1, w2 = p2 / c1, p1 / c2, dp2 / c1, dp1 / c2
        th1, th2 = math.asin(p2 / self._la), math.asin(p1 / self._la)
        g1, g2 = 1.0 / c1, 1.0 / c2
        s1, s2 = t1 * w1 * w1, t2 * w2 * w2  # θ̈_i at p̈ = 0
        # Joint order (d_1, φ_10, φ_p, φ_11, d_2, φ_20, φ_21), checked in __init__.
        q = np.array((p1 + self._k - c1, th1, -th1, th1, p2 + self._k - c2, -th2, -th2))
        v = np.array((dp1 + t1 * dp2, w1, -w1, w1, dp2 + t2 * dp1, -w2, -w2))
        a0 = np.array((c1 * w1 * w1 + p2 * s1, s1, -s1, s1, c2 * w2 * w2 + p1 * s2, -s2, -s2))
        rnea, zero = self._rnea, self._zero
        r_d1, r_10, r_p, r_11, r_d2, r_20, r_21 = rnea(q, v, a0).tolist()  # M a_0 + C v
        x_d1, _, _, _, x_d2, x_20, x_21 = rnea(
            q, zero, np.array((1.0, 0.0, 0.0, 0.0, t2, -g2, -g2))
        ).tolist()  # M N e_1
        y_d1, y_10, y_p, y_11, y_d2, y_20, y_21 = rnea(q, zero, np.array((t1, g1, -g1, g1, 1.0, 0.0, 0.0))).tolist()
        # Nᵀ x: row 1 = (1, 0, 0, 0, t_2, -1/c_2, -1/c_2), row 2 = (t_1, 1/c_1, -1/c_1, 1/c_1, 1, 0, 0).
        m11 = x_d1 + t2 * x_d2 - (x_20 + x_21) * g2
        m12 = y_d1 + t2 * y_d2 - (y_20 + y_21) * g2
        m22 = t1 * y_d1 + y_d2 + (y_10 + y_11 - y_p) * g1
        f1 = tau1 + t2 * tau2 - (r_d1 + t2 * r_d2 - (r_20 + r_21) * g2)  # Jᵀ τ (eqs. 10, 13) - velocity terms
        f2 = t1 * tau1 + tau2 - (t1 * r_d1 + r_d2 + (r_10 + r_11 - r_p) * g1)
        det = m11 * m22 - m12 * m12  # Nᵀ M N is symmetric
        return (m22 * f1 - m12 * f2) / det, (m11 * f2 - m12 * f1) / det
