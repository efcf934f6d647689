"""The two arrangements of the 2-PPa and one door to each: the paper's perpendicular one and the parallel one.

:class:`Arrangement` names them; the functions below take an arrangement first and otherwise the arguments,
shapes, units and returned types of the perpendicular functions (:mod:`tpm_viz.paper.kinematics`,
:mod:`tpm_viz.paper.jacobians`, :mod:`tpm_viz.paper.dynamics`) and their parallel mirrors
(:mod:`tpm_viz.paper.parallel`, ``docs/parallel.md``), so that a caller treats both alike.
"""

from __future__ import annotations

import enum
from types import ModuleType, SimpleNamespace

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params, geometry_problem
from tpm_viz.core.words import Phrase
from tpm_viz.paper import dynamics as _perp_dyn
from tpm_viz.paper import jacobians as _perp_jac
from tpm_viz.paper import kinematics as _perp_kin
from tpm_viz.paper import parallel as _par
from tpm_viz.paper.jacobians import Jacobians
from tpm_viz.paper.kinematics import FkSolutions, MechanismPose
from tpm_viz.paper.status import WARN, SingularityThresholds

__all__ = [
    "Arrangement",
    "actuator_forces_from_platform_force",
    "actuator_velocity",
    "classify",
    "condition_number",
    "force_per_acceleration",
    "forward_kinematics",
    "forward_kinematics_both",
    "geometry_problem_of",
    "home",
    "in_stroke",
    "inverse_dynamics",
    "inverse_kinematics",
    "jacobians",
    "kinetic_energy",
    "mechanism_pose",
    "reachable",
    "validate",
]


class Arrangement(enum.Enum):
    """How the two rails are laid out (``value``: the command-line word)."""

    PERPENDICULAR = "perpendicular"
    """The paper's: rail 1 along X, rail 2 along Y (Pham & Kim 2013)."""
    PARALLEL = "parallel"
    """Liu & Wang 2004's: both rails on the X axis, facing each other (``docs/parallel.md``)."""

    @classmethod
    def parse(cls, text: object) -> Arrangement:
        """The arrangement named ``text`` (its value, any case), or :class:`InputError` naming the choices."""
        if isinstance(text, Arrangement):
            return text
        word = str(text).strip().lower()
        for arrangement in cls:
            if word == arrangement.value:
                return arrangement
        raise InputError(
            Phrase("unknown arrangement {got}: choose perpendicular or parallel", got=repr(str(text))[:40])
        )


_PERPENDICULAR = SimpleNamespace(
    kin=_perp_kin,
    jac=_perp_jac,
    dyn=_perp_dyn,
)
_PARALLEL = SimpleNamespace(kin=_par, jac=_par, dyn=_par)


def _ns(arrangement: Arrangement) -> SimpleNamespace:
    return _PARALLEL if Arrangement.parse(arrangement) is Arrangement.PARALLEL else _PERPENDICULAR


def _kin(arrangement: Arrangement) -> ModuleType:
    return _ns(arrangement).kin


def geometry_problem_of(arrangement: Arrangement, a: float, b: float, l_a: float, stroke: float) -> Phrase | None:
    """Why no pose of this arrangement fits in the stroke, as the fix (None if one does); lengths in m."""
    if Arrangement.parse(arrangement) is Arrangement.PARALLEL:
        return _par.geometry_problem(a, b, l_a, stroke) or geometry_problem(a, b, l_a, stroke)
    return geometry_problem(a, b, l_a, stroke)


def validate(arrangement: Arrangement, params: Params) -> Params:
    """``params`` if the arrangement has a pose inside the stroke (:class:`Params` checks the perpendicular
    rules on construction; the parallel ones are stricter), else :class:`InvalidParametersError`."""
    return _par.validate(params) if Arrangement.parse(arrangement) is Arrangement.PARALLEL else params


def home(arrangement: Arrangement, params: Params) -> np.ndarray:
    """A central platform position [m]: ``(0, 0)`` (perpendicular, ``J = I``) or :func:`parallel.home`."""
    return _par.home(params) if Arrangement.parse(arrangement) is Arrangement.PARALLEL else np.zeros(2)


def reachable(arrangement: Arrangement, params: Params, p: ArrayLike) -> np.ndarray:
    """Whether the inverse kinematics has a real solution at ``p`` [m] (bool, shape ``(...)``)."""
    return _kin(arrangement).reachable(params, p)


def in_stroke(arrangement: Arrangement, params: Params, d: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Whether both actuators are within ``0 <= d_i <= Δd`` (the same rule for both arrangements)."""
    return _perp_kin.in_stroke(params, d, tol)


def inverse_kinematics(arrangement: Arrangement, params: Params, p: ArrayLike) -> np.ndarray:
    """Actuator positions ``d`` [m], working mode (eq. 4 or eq. P3)."""
    return _kin(arrangement).inverse_kinematics(params, p)


def forward_kinematics(arrangement: Arrangement, params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] in assembly ``mode`` (+1 contains the working mode's regular poses)."""
    return _kin(arrangement).forward_kinematics(params, d, mode)


def forward_kinematics_both(arrangement: Arrangement, params: Params, d: ArrayLike) -> FkSolutions:
    """Both assembly modes (:class:`FkSolutions`)."""
    return _kin(arrangement).forward_kinematics_both(params, d)


def mechanism_pose(arrangement: Arrangement, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Every joint of one configuration, for drawing (:class:`MechanismPose`)."""
    return _kin(arrangement).mechanism_pose(params, p, d)


def jacobians(arrangement: Arrangement, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> Jacobians:
    """``J_x``, ``J_q``, ``J`` and the singularity measures ``det J_x`` (direct), ``det J_q`` (inverse)."""
    return _ns(arrangement).jac.jacobians(params, p, d)


def condition_number(arrangement: Arrangement, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """2-norm condition number of ``J``; ``inf`` at a singularity."""
    return _ns(arrangement).jac.condition_number(params, p, d)


def classify(
    arrangement: Arrangement, params: Params, p: ArrayLike, thresholds: SingularityThresholds = WARN
) -> np.ndarray:
    """:class:`~tpm_viz.paper.status.PoseStatus` values per pose, the same thresholds for both."""
    return _ns(arrangement).jac.classify(params, p, thresholds)


def actuator_velocity(
    arrangement: Arrangement, params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """``ḋ = J ṗ`` [m/s]."""
    return _ns(arrangement).jac.actuator_velocity(params, p, dp, d)


def actuator_forces_from_platform_force(
    arrangement: Arrangement, params: Params, p: ArrayLike, f: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """``τ = J⁻ᵀ f`` [N] (eq. 13 / P8); to hold an external load ``f_ext`` pass ``f = -f_ext``."""
    return _ns(arrangement).jac.actuator_forces_from_platform_force(params, p, f, d)


def inverse_dynamics(
    arrangement: Arrangement,
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None = None,
    d: ArrayLike | None = None,
) -> np.ndarray:
    """Actuator forces ``τ`` [N] by the closed form (eqs. 29-31 / P14)."""
    return _ns(arrangement).dyn.inverse_dynamics(params, p, dp, ddp, f_ext, d)


def kinetic_energy(
    arrangement: Arrangement, params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None
) -> np.ndarray:
    """Total kinetic energy [J]."""
    return _ns(arrangement).dyn.kinetic_energy(params, p, dp, d)


def force_per_acceleration(arrangement: Arrangement, params: Params, p: ArrayLike) -> np.ndarray:
    """``J⁻ᵀ M(p)`` [kg], shape ``(..., 2, 2)``: actuator forces per unit platform acceleration at rest (column
    ``k``: ``τ`` for ``p̈ = e_k``, ``ṗ = 0``, no load), from the closed-form inverse dynamics."""
    p = np.asarray(p, dtype=float)
    zero = np.zeros_like(p)
    cols = [inverse_dynamics(arrangement, params, p, zero, np.broadcast_to(e, p.shape)) for e in np.eye(2)]
    return np.stack(cols, axis=-1)
