"""The parallel 2-PPa as its own closed-loop Pinocchio model (``docs/parallel.md``, ``docs/pinocchio.md``).

Same construction, mass model and solves as :class:`~tpm_viz.multibody.model.MultibodyModel` (it subclasses it:
the rank-revealing inverse and forward dynamics, the Newton assembly, the reachability refusal and the assembly from
actuator positions, and the lock are the perpendicular model's); only the tree, the closures, the legs (which poses
are reachable, :data:`tpm_viz.paper.parallel.kinematics.PARALLEL`), the starting guesses and the sign of
``det J_x`` that names an assembly mode differ. Depth-first tree, ``q = (d_1, φ_10, φ_p, φ_11, d_2,
φ_20, φ_21)`` (read :attr:`index`)::

    universe ─PX─ slider1 (origin A_1 = (d_1 - a, 0)) ─RZ─ link1_0 (pivot A_1) ─RZ─ platform (pivot B_1)
                                                    └RZ─ link1_1 (pivot A_1 + s e_2)
    universe ─PX─ slider2 (frame turned by π at (a, 0): origin A_2 = (a - d_2, 0)) ─RZ─ link2_0 (pivot A_2)
                                                                                  └RZ─ link2_1 (pivot A_2 + s e_2)

Each link's x axis runs along the link: ``φ_1k = θ_1`` and, in slider 2's turned frame, ``φ_2k = -θ_2``
(``θ_i`` measured from the rail inwards, ``docs/parallel.md``); ``φ_p = -θ_1`` keeps the platform translating.
Closures: the tips of link1_1, link2_0 and link2_1 to ``B_1 + s e_2``, ``B_2 = B_1 + 2b e_1`` and
``B_2 + s e_2`` on the platform (``CONTACT_3D``, ``LOCAL_WORLD_ALIGNED``; 9 rows of rank 5 as in the
perpendicular model). Independent of the closed form of :mod:`tpm_viz.paper.parallel.dynamics`.
"""

from __future__ import annotations

import functools
import math

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.multibody.model import MultibodyModel, checked_model
from tpm_viz.multibody.tree import Built, closed_tree, point_mass, rod, se3
from tpm_viz.paper import parallel as par
from tpm_viz.paper.parallel.kinematics import PARALLEL

__all__ = ["ParallelMultibodyModel", "inverse_dynamics", "parallel_model_for"]

_SINGULAR_RTOL = 1e-9


def _build_parallel(params: Params) -> Built:
    """The Pinocchio model of the parallel arrangement, its closures and the part frame ids."""
    a, b, la, sp = params.a, params.b, params.l_a, params.pivot_spacing
    link = rod(params.m_b / 2.0, la)
    tree = [
        ("slider1", "universe", pin.JointModelPX(), se3([-a, 0, 0]), point_mass(params.m_a)),
        ("link1_0", "slider1", pin.JointModelRZ(), se3([0, 0, 0]), link),
        ("platform", "link1_0", pin.JointModelRZ(), se3([la, 0, 0]), point_mass(params.m_p, [b, 0, 0])),
        ("link1_1", "slider1", pin.JointModelRZ(), se3([0, sp, 0]), link),
        ("slider2", "universe", pin.JointModelPX(), se3([a, 0, 0], math.pi), point_mass(params.m_a)),
        ("link2_0", "slider2", pin.JointModelRZ(), se3([0, 0, 0]), link),
        ("link2_1", "slider2", pin.JointModelRZ(), se3([0, -sp, 0]), link),  # +s e_2 in the world
    ]
    on_platform = {"link1_1": [0, sp, 0], "link2_0": [2 * b, 0, 0], "link2_1": [2 * b, sp, 0]}  # from B_1
    return closed_tree(params, tree, on_platform)


class ParallelMultibodyModel(MultibodyModel):
    """The closed-loop Pinocchio model of the parallel arrangement (see the module docstring); the public
    methods are :class:`MultibodyModel`'s (``inverse_dynamics``, ``configuration``, ``placements``, ...)."""

    _build_model = staticmethod(_build_parallel)
    legs = PARALLEL

    def _guess_from_platform(self, p: np.ndarray, d: np.ndarray | None) -> np.ndarray:
        """Working mode (eq. P3), ``sin θ_i = p_2 / l_a``, or links pointing at the pivots from given ``d``."""
        if d is not None:
            return self._guess_from_both(p, d)
        theta = math.asin(float(p[1]) / self.params.l_a)
        return self._pack(par.inverse_kinematics(self.params, p), theta, -theta)

    def _guess_from_both(self, p: np.ndarray, d: np.ndarray) -> np.ndarray:
        """Links pointing from ``A_i`` towards ``B_i``; leg 2's link direction is ``(-cos φ, -sin φ)``."""
        pose_a = np.array([[d[0] - self.params.a, 0.0], [self.params.a - d[1], 0.0]])
        b = np.array([[p[0] - self.params.b, p[1]], [p[0] + self.params.b, p[1]]])
        u = b - pose_a
        return self._pack(d, math.atan2(u[0, 1], u[0, 0]), math.atan2(-u[1, 1], -u[1, 0]))

    def _tau(
        self, q: np.ndarray, v: np.ndarray, a: np.ndarray, n: np.ndarray, jp: np.ndarray, f_ext: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        """The perpendicular model's solve, after a scale-free check of ``Nᵀ Sᵀ = Jᵀ``: here its second row
        ``(tan θ_1, tan θ_2)`` vanishes at the direct singularity, which a per-row test cannot see."""
        g = n[self._slider_idx].T
        if abs(np.linalg.det(g)) < _SINGULAR_RTOL * float(np.max(np.abs(g))) ** 2:
            raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq="sin(θ1 + θ2) = 0"))
        return super()._tau(q, v, a, n, jp, f_ext)

    def _assembly_guesses(self, d: np.ndarray) -> list[np.ndarray] | None:
        """Both assembly modes of the closed form (eq. P7) as Newton's starting points; None where the leg circles
        do not meet."""
        sol = par.forward_kinematics_both(self.params, d)
        return [sol.plus, sol.minus] if bool(sol.exists) else None

    def _mode(self, q: np.ndarray) -> float:
        """The sign of ``det J_x = sin(θ1 + θ2)`` (eq. P4; +1: the upper mode with the legs inwards)."""
        f1, f2 = self._link_angles(q)  # (θ_1, -θ_2)
        return float(np.sign(math.sin(f1 - f2)))


@functools.lru_cache(maxsize=16)
def parallel_model_for(params: Params) -> ParallelMultibodyModel:
    """The cached :class:`ParallelMultibodyModel` of a parameter set."""
    return ParallelMultibodyModel(params)


def inverse_dynamics(
    params: Params, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None = None
) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, from the parallel Pinocchio model (one cached per params)."""
    return checked_model(parallel_model_for, params).inverse_dynamics(p, dp, ddp, f_ext)
