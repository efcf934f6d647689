"""Closed-loop assembly of the Pinocchio model: the full configuration ``q`` from ``p`` or from ``d``.

A mixin of :class:`~tpm_viz.multibody.model.MultibodyModel`: Gauss-Newton on Pinocchio's own closure
residual (``Φ(q) = 0``) plus the driven coordinates (platform position or actuator positions), from
a geometric starting guess that only selects the branch. It calls the model's Pinocchio evaluations
(``_closure_terms``, ``_platform_position_now``, ``_platform_jacobian``) and imports no Pinocchio itself.
"""

from __future__ import annotations

import math
import threading
from collections.abc import Callable
from typing import Any

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.multibody.locking import locked
from tpm_viz.paper.kinematics import PERPENDICULAR
from tpm_viz.paper.legs import Legs, unreachable

__all__ = ["DOF", "NEWTON_FLOOR", "NEWTON_MAX_ITER", "NEWTON_TOL", "ClosedLoopAssembly", "ThreeArrays"]

DOF = 2
NEWTON_TOL = 1e-12  # m: accepted residual of the closure and platform/actuator equations ...
NEWTON_FLOOR = 1e-15  # m: ... but Newton polishes down to this or until it stops improving
NEWTON_MAX_ITER = 40
_MAX_ANGLE_STEP = 0.5  # rad, Newton step limit on the revolute coordinates
ThreeArrays = tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]
"""Three arrays: ``(q, J_c, J_P)`` of an assembly, ``(q, v, a)`` of a motion."""


class ClosedLoopAssembly:
    """Mixin: the closed-loop kinematics of :class:`~tpm_viz.multibody.model.MultibodyModel`.

    The arrangement's own parts are :attr:`legs` (its reachability and refusal, :mod:`tpm_viz.paper.legs`), the
    starting guesses (:meth:`_guess_from_platform`, :meth:`_guess_from_both`, :meth:`_assembly_guesses`) and
    :meth:`_mode` (the sign of ``det J_x``); another arrangement overrides them.
    """

    legs: Legs = PERPENDICULAR
    """The arrangement's legs: which poses are reachable and how an unreachable one is refused."""

    # What the model provides (built in MultibodyModel.__init__):
    params: Params
    model: Any  # pinocchio.Model (Pinocchio ships no type information)
    index: dict[str, int]
    _cdatas: Any  # pinocchio.StdVec_RigidConstraintData
    _lock: threading.RLock
    _slider_idx: np.ndarray
    _angle_idx: np.ndarray
    _s_t: np.ndarray
    _last: tuple[np.ndarray, np.ndarray, np.ndarray | None] | None
    _closure_terms: Callable[[np.ndarray], tuple[np.ndarray, np.ndarray]]
    _platform_position_now: Callable[[], np.ndarray]
    _platform_jacobian: Callable[[], np.ndarray]
    _one: Callable[[ArrayLike, str], np.ndarray]

    def _newton(
        self, q: np.ndarray, target: np.ndarray, driven: str
    ) -> tuple[NDArray[np.float64], bool, NDArray[np.float64], NDArray[np.float64]]:
        """Gauss-Newton on ``[Φ(q); x(q) - target] = 0``, ``x`` = platform P or actuators d.

        ``[J_c; J_x]`` has full column rank away from singularities, so the normal equations give the
        step. Returns ``(q, converged, J_c, J_x)`` with the Jacobians at the returned ``q``.
        """
        q, previous, nc = q.copy(), np.inf, 3 * len(self._cdatas)
        a, r = np.empty((nc + DOF, self.model.nv)), np.empty(nc + DOF)
        for _ in range(NEWTON_MAX_ITER):
            r[:nc], a[:nc] = self._closure_terms(q)
            if driven == "platform":
                r[nc:], a[nc:] = self._platform_position_now() - target, self._platform_jacobian()
            else:
                r[nc:], a[nc:] = q[self._slider_idx] - target, self._s_t.T
            err = abs(r).max()
            if err < NEWTON_FLOOR or (err < NEWTON_TOL and err > 0.5 * previous):  # at the rounding floor
                return q, True, a[:nc].copy(), a[nc:].copy()
            previous = err
            try:
                dq = -np.linalg.solve(a.T @ a, a.T @ r)
            except np.linalg.LinAlgError:
                break
            big = abs(dq[self._angle_idx]).max()
            if big > _MAX_ANGLE_STEP:
                dq *= _MAX_ANGLE_STEP / big
            q += dq
        return q, False, a[:nc].copy(), a[nc:].copy()

    def _is_parallelogram(self, q: np.ndarray) -> bool:
        """Both links of each leg parallel and the platform translating (``φ_p = -φ_10``)."""
        f10, f11, f20, f21, fp = q[self._angle_idx].tolist()
        return all(abs(math.remainder(x, 2 * math.pi)) < 1e-6 for x in (f11 - f10, f21 - f20, fp + f10))

    def _wrap(self, q: np.ndarray) -> np.ndarray:
        """``q`` with every angle in ``[-π, π]``."""
        q = q.copy()
        q[self._angle_idx] = [math.remainder(x, 2 * math.pi) for x in q[self._angle_idx].tolist()]
        return q

    def _pack(self, d: ArrayLike, phi1: float, phi2: float) -> np.ndarray:
        """``q`` from actuator positions and the link angles ``φ_1 = θ_1``, ``φ_2 = -θ_2`` of a parallelogram."""
        q = np.empty(self.model.nq)
        q[self._slider_idx] = d
        q[self._angle_idx] = [phi1, phi1, phi2, phi2, -phi1]
        return q

    def _link_angles(self, q: np.ndarray) -> tuple[float, float]:
        """``(φ_10, φ_20) = (θ_1, -θ_2)``."""
        return float(q[self.index["link1_0"]]), float(q[self.index["link2_0"]])

    def _guess_from_platform(self, p: np.ndarray, d: np.ndarray | None) -> np.ndarray:
        """Starting point: the working mode with leg angles ``sin θ_1 = p_2 / l_a``, ``sin θ_2 = p_1 / l_a``
        (docs/conventions.md), or links pointing at the platform pivots from given actuator positions ``d``.
        Only a guess: Newton accepts it only once Pinocchio's own closure residual is at the rounding floor."""
        if d is not None:
            return self._guess_from_both(p, d)
        la, k = self.params.l_a, self.params.offset
        theta = (math.asin(float(p[1]) / la), math.asin(float(p[0]) / la))
        d_guess = (p[0] + k - la * math.cos(theta[0]), p[1] + k - la * math.cos(theta[1]))
        return self._pack(d_guess, theta[0], -theta[1])

    def _guess_from_both(self, p: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Links pointing from the slider joints ``A_i`` towards the platform pivots ``B_i``."""
        a, b = self.params.a, self.params.b
        u1 = (p[0] - b) - (d[0] - a), p[1]  # B_1 - A_1
        u2 = p[0], (p[1] - b) - (d[1] - a)  # B_2 - A_2
        t1 = np.arctan2(u1[1], u1[0])
        t2 = np.arctan2(-u2[0], u2[1])  # link frame of leg 2 is rotated by +90 deg
        return self._pack(d, t1, t2)

    @locked
    def configuration(self, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
        """Full configuration ``q`` (7,) for platform position ``p`` (2,) [m], by Newton on Pinocchio's
        closure residual. Working mode (eq. 4: ``cos θ_i > 0``) unless actuator positions ``d`` (2,)
        are given: they are the starting point and so select the branch."""
        p = self._one(p, "p")
        return self._configure(p, None if d is None else self._one(d, "d"))[0]

    def _configure(self, p: np.ndarray, d: np.ndarray | None) -> ThreeArrays:
        """``(q, J_c, J_P)`` at the closed-loop configuration of platform position ``p`` (refused, as the
        arrangement's inverse kinematics refuses it, where unreachable)."""
        if not bool(self.legs.reachable(self.params, p)):
            x, y = (fixed(v, ".1f", 1e3) for v in p.tolist())
            raise UnreachablePoseError(unreachable(self.legs, self.params, x, y))
        return self._assembled(p, d)

    def _assembled(self, p: np.ndarray, d: np.ndarray | None) -> ThreeArrays:
        """``(q, J_c, J_P)`` by Newton from the arrangement's guess (``_guess_from_platform``: the working mode, or
        ``d``'s branch), then from the last pose (continuation with its tangent predictor); the first closed
        parallelogram on the working mode (``c_i = l_a cos θ_i > 0``, eq. 4 / eq. P3) unless ``d`` picks the branch.
        ``p`` [m] is reachable (the caller checked)."""
        starts = [lambda: self._guess_from_platform(p, d)]
        if d is None and self._last is not None:  # fallback: continuation from the last pose, tangent predictor
            p_last, q_last, dq_dp = self._last
            starts.append(lambda: q_last if dq_dp is None else q_last + dq_dp @ (p - p_last))
        for start in starts:
            q, ok, jc, jp = self._newton(start(), p, "platform")
            working = min(math.cos(x) for x in self._link_angles(q)) > 0  # c_i = l_a cos θ_i > 0
            if ok and self._is_parallelogram(q) and (d is not None or working):
                q = self._wrap(q)
                if d is None:
                    self._last = (p.copy(), q, None)
                return q, jc, jp
        raise SingularConfigurationError(
            Phrase(
                "no closed-loop configuration found at ({x}, {y}) mm (too close to cos θ_i = 0, eq. 11)",
                x=fixed(float(p[0]), ".1f", 1e3),
                y=fixed(float(p[1]), ".1f", 1e3),
            )
        )

    def _assembly_guesses(self, d: np.ndarray) -> list[np.ndarray] | None:
        """Platform positions [m] to start Newton from for actuator positions ``d``, one on each side of the line
        of the leg circles' centres ``C_1 = (d_1 - a + b) e_1``, ``C_2 = (d_2 - a + b) e_2``; None where the
        circles do not meet."""
        k, la = self.params.a - self.params.b, self.params.l_a
        c1, c2 = np.array([d[0] - k, 0.0]), np.array([0.0, d[1] - k])  # leg circle centres
        gap = math.hypot(float(d[0] - k), float(d[1] - k))  # |C_2 - C_1|, no overflow for huge d
        if not gap < 2 * la or gap == 0:
            return None
        normal = np.array([c1[1] - c2[1], c2[0] - c1[0]]) / gap
        return [(c1 + c2) / 2 + side * (la / np.sqrt(2.0)) * normal for side in (1.0, -1.0)]

    def _mode(self, q: np.ndarray) -> float:
        """The assembly mode of a closed configuration: the sign of ``det J_x = cos(θ1 + θ2)`` (eq. 12)."""
        return float(np.sign(np.cos(np.subtract(*self._link_angles(self._wrap(q))))))

    @locked
    def configuration_from_actuators(self, d: ArrayLike, mode: int = +1) -> np.ndarray:
        """Full configuration ``q`` (7,) for actuator positions ``d`` (2,) [m] in assembly ``mode`` (+1: ``det J_x >
        0``, perpendicular ``cos(θ1 + θ2) > 0``, the home mode; -1: the other), by Newton on the closures from each
        of the arrangement's guesses (:meth:`_assembly_guesses`) in turn."""
        if mode not in (1, -1):
            raise InputError(f"assembly mode must be +1 or -1, got {mode!r}")
        d = self._one(d, "d")
        guesses = self._assembly_guesses(d)
        if guesses is None:
            raise UnreachablePoseError(
                Phrase("actuator positions cannot be assembled: the leg circles are more than 2 l_a apart")
            )
        for p0 in guesses:  # guesses only: Newton on Pinocchio's closures decides
            q, ok, _, _ = self._newton(self._guess_from_both(p0, d), d, "actuators")
            if ok and self._is_parallelogram(q) and self._mode(q) == mode:
                return self._wrap(q)
        raise SingularConfigurationError(
            Phrase("assembly mode {mode} not found: d is at or near the direct singularity", mode=f"{mode:+d}")
        )
