"""The shape both arrangements of the 2-PPa share, written once: eqs. (1)-(4), (12), (23), (27) of the paper and
eqs. (P1)-(P3), (P7) of ``docs/parallel.md``.

Each arrangement has two legs: slider ``i`` runs on its rail (``d_i`` [m], growing inwards) and a parallelogram of
length ``l_a`` joins its pivot ``A_i`` to the platform pivot ``B_i``. Leg ``i`` is a circle in two lengths [m],

    c_i = σ_i p_{a_i} - d_i + a - b = l_a cos θ_i,    s_i = p_{b_i} = l_a sin θ_i,    c_i² + s_i² = l_a²

(eqs. 23 and 27; P2), where ``a_i`` is the component of ``p`` along rail ``i``, ``σ_i = ±1`` the sense in which
``d_i`` grows along it and ``b_i`` the component across it: perpendicular ``a = (1, 2)``, ``σ = (+1, +1)``,
``b = (2, 1)``; parallel ``a = (1, 1)``, ``σ = (+1, -1)``, ``b = (2, 2)``. A :class:`Legs` holds those indices and
each arrangement's own equations (inverse kinematics eq. 4 / P3, its leg circles, its joints eq. 1 / P1, its
refusals); the functions here are the rest: the checked inverse kinematics, the leg angles, the pair of circles of
the forward kinematics (eq. 27 / P7) and the choice of assembly mode, the parallelogram links of a pose.
:func:`tpm_viz.paper.jacobians.jacobians_of` builds both arrangements' Jacobians (eqs. 8-10 / P4) from the same
indices. Shapes: ``p`` and ``d`` are arrays of shape ``(..., 2)`` in metres.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.status import FkStatus

__all__ = [
    "FkSolutions",
    "Legs",
    "MechanismPose",
    "as_xy",
    "finite_result",
    "forward_kinematics",
    "forward_kinematics_nearest",
    "in_stroke",
    "inverse_kinematics",
    "leg_angles",
    "mechanism_pose",
    "meeting",
    "mm",
    "unreachable",
]


def as_xy(x: ArrayLike, name: str = "p") -> np.ndarray:
    """``x`` as a float array of shape ``(..., 2)``; raise :class:`InputError` otherwise."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise InputError(f"{name} must have shape (..., 2), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(Phrase("{name} contains a non-finite value (NaN or inf)", name=name))
    return arr


def mm(x: float) -> str:
    """A length [m] as millimetres for a message (no overflow warning for absurd values)."""
    value = float(x) * 1e3  # Python floats overflow to inf silently
    return fixed(value, ".1f") if abs(value) < 1e9 else fixed(value, ".3g")


def finite_result(arr: np.ndarray, what: str | Phrase) -> np.ndarray:
    """``arr`` unchanged if every entry is finite; otherwise an :class:`InputError` (overflow)."""
    if not np.all(np.isfinite(arr)):
        raise InputError(Phrase("{what} overflowed: the inputs are too large for finite results", what=what))
    return arr


def in_stroke(params: Params, d: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Whether both actuators are within ``0 <= d_i <= Δd`` (bool, shape ``(...)``; the same rule for both
    arrangements)."""
    d = np.asarray(d, dtype=float)
    return np.all((d >= -tol) & (d <= params.stroke + tol), axis=-1)


class FkSolutions(NamedTuple):
    """Both assembly modes of the forward kinematics (platform positions in m).

    ``plus`` has ``det J_x >= 0`` (perpendicular: ``cos(θ_1 + θ_2)``, the mode containing the home pose; parallel:
    ``sin(θ_1 + θ_2)``, eq. P4), ``minus`` has ``det J_x <= 0``. The direct singularity (eq. 12, ``s_1`` parallel to
    ``s_2``) takes two forms: ``s_1 = -s_2``, the circles touch and the two modes merge (perpendicular, working mode:
    the arc ``p_1² + p_2² = l_a²`` in the third quadrant); ``s_1 = s_2``, the circles coincide (``d_1 = d_2 = a - b``,
    first-quadrant arc) and the position is undetermined. ``exists`` is False where the circles do not meet or
    coincide (positions are NaN there); ``status`` holds a :class:`~tpm_viz.paper.status.FkStatus` value per input.
    """

    plus: np.ndarray
    minus: np.ndarray
    exists: np.ndarray
    status: np.ndarray


@dataclass(frozen=True)
class MechanismPose:
    """Every point needed to draw one configuration (metres, radians; XY plane).

    ``links[i, k]`` is link ``k`` (0 or 1) of leg ``i`` as a ``(2, 2)`` array of its slider-side
    and platform-side pivots; link 0 runs from ``A_i`` to ``B_i`` (eq. 2 / P1), link 1 is offset by
    the pivot spacing across rail ``i`` (along ``e_{b_i}``: ``e_j`` in the perpendicular arrangement, ``e_2`` in the
    parallel one).
    """

    p: np.ndarray  # (2,) platform centre P
    d: np.ndarray  # (2,) actuator positions d_i
    theta: np.ndarray  # (2,) leg angles θ_i
    A: np.ndarray  # (2, 2) slider joints A_i (row i)
    B: np.ndarray  # (2, 2) platform joints B_i (row i)
    links: np.ndarray  # (2, 2, 2, 2) leg, link, end, xy


Pair = tuple[int, int]


@dataclass(frozen=True)
class Legs:
    """One arrangement's legs (see the module docstring): the indices of ``c_i`` and ``s_i`` and its own equations.

    ``along``, ``sign``, ``across`` are ``a_i`` (0-based), ``σ_i`` and ``b_i``; ``singularities`` names the
    (inverse, direct) singularity equations in a refusal. The callables take a :class:`Params` first:
    ``reachable(p)`` (bool per pose), ``ik(p)`` (working-mode inverse kinematics on a reachable ``p``, no checks),
    ``components(p, d)`` (``(c, s)``), ``circles(d)`` (both assembly modes, :class:`FkSolutions`), ``joints(p, d)``
    (``(A, B)`` of one pose) and ``coincide(d)`` (the refusal where the leg circles coincide at ``d``, else None).
    ``unreachable`` is the refusal of a pose outside ``reachable``, a template with the fields ``x``, ``y`` and
    ``l_a`` [mm] (:func:`unreachable`).
    """

    along: Pair
    sign: tuple[float, float]
    across: Pair
    singularities: tuple[str, str]
    unreachable: Phrase
    reachable: Callable[[Params, ArrayLike], np.ndarray]
    ik: Callable[[Params, np.ndarray], np.ndarray]
    components: Callable[[Params, ArrayLike, ArrayLike], tuple[np.ndarray, np.ndarray]]
    circles: Callable[[Params, ArrayLike], FkSolutions]
    joints: Callable[[Params, np.ndarray, np.ndarray], tuple[np.ndarray, np.ndarray]]
    coincide: Callable[[Params, np.ndarray], Phrase | None]


def unreachable(legs: Legs, params: Params, x: str, y: str) -> Phrase:
    """The refusal of the platform position ``(x, y)`` (written in mm) where ``legs.reachable`` is False."""
    return Phrase(legs.unreachable.template, x=x, y=y, l_a=params.l_a * 1e3)


def inverse_kinematics(legs: Legs, params: Params, p: ArrayLike) -> np.ndarray:
    """Actuator positions ``d`` [m] of the working mode (eq. 4 / P3) for platform positions ``p`` [m]; raises
    :class:`UnreachablePoseError` (naming the first unreachable pose) where ``legs.reachable`` is False."""
    p = as_xy(p)
    ok = legs.reachable(params, p)
    if not np.all(ok):
        bad = p[~ok][0] if p.ndim > 1 else p
        raise UnreachablePoseError(unreachable(legs, params, mm(bad[0]), mm(bad[1])))
    return legs.ik(params, p)


def leg_angles(legs: Legs, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angles ``θ_i = atan2(s_i, c_i)`` [rad] (eq. 23 / P2) on the branch given by ``d`` (default: the working
    mode, where ``|θ_i| < π/2``)."""
    p = as_xy(p)
    d = inverse_kinematics(legs, params, p) if d is None else as_xy(d, "d")
    c, s = legs.components(params, p, d)
    return np.arctan2(s, c)


def meeting(params: Params, dist: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Where two leg circles of radius ``l_a`` meet whose centres are ``dist`` [m] apart (eq. 27 / P7): ``(h,
    exists, status)``, ``h`` [m] the distance of either crossing from the centres' midpoint (NaN where none),
    ``exists`` (bool) and ``status`` (:class:`~tpm_viz.paper.status.FkStatus` values): modes merge where ``h`` is
    below ``1e-9 l_a``, apart beyond ``2 l_a`` (or not finite), coincide below ``1e-12 l_a``."""
    la = params.l_a
    with np.errstate(over="ignore", invalid="ignore"):
        half = dist / 2.0
        h = np.sqrt(np.maximum(la**2 - half**2, 0.0))  # tangency within rounding: h = 0
    exists = (half <= la * (1 + 1e-12)) & (dist > 1e-12 * la) & np.isfinite(dist)
    h = np.where(exists, h, np.nan)
    status = np.where(h <= 1e-9 * la, FkStatus.MODES_MERGE, FkStatus.TWO_MODES)
    status = np.where(half > la * (1 + 1e-12), FkStatus.APART, status)
    status = np.where(dist <= 1e-12 * la, FkStatus.COINCIDE, status)
    return h, exists, np.where(np.isfinite(dist), status, FkStatus.APART)


def _raise_if_missing(legs: Legs, params: Params, d: np.ndarray, sol: FkSolutions) -> None:
    if np.all(sol.exists):
        return
    bad = np.asarray(d)[~sol.exists][0] if np.ndim(sol.exists) else np.asarray(d)
    coincide = legs.coincide(params, bad)
    if coincide is not None:
        raise SingularConfigurationError(coincide)
    raise UnreachablePoseError(
        Phrase(
            "actuators at ({d1}, {d2}) mm cannot be assembled: the leg circles are more than 2 l_a apart",
            d1=mm(bad[0]),
            d2=mm(bad[1]),
        )
    )


def forward_kinematics(legs: Legs, params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] for actuator positions ``d`` [m] in assembly ``mode`` (+1 or -1, see
    :class:`FkSolutions`); raises :class:`UnreachablePoseError` where the leg circles do not meet and
    :class:`SingularConfigurationError` where they coincide."""
    if mode not in (1, -1):
        raise InputError(f"assembly mode must be +1 or -1, got {mode!r}")
    d = as_xy(d, "d")
    sol = legs.circles(params, d)
    _raise_if_missing(legs, params, d, sol)
    return sol.plus if mode == 1 else sol.minus


def forward_kinematics_nearest(legs: Legs, params: Params, d: ArrayLike, p_prev: ArrayLike) -> tuple[np.ndarray, int]:
    """The assembly mode nearest a previous platform position: ``(p, mode)`` for one pose [m]."""
    d = as_xy(d, "d")
    sol = legs.circles(params, d)
    _raise_if_missing(legs, params, d, sol)
    p_prev = as_xy(p_prev, "p_prev")
    with np.errstate(over="ignore"):  # an absurd previous pose: both distances inf, keep "plus"
        if np.sum((sol.plus - p_prev) ** 2) <= np.sum((sol.minus - p_prev) ** 2):
            return sol.plus, 1
    return sol.minus, -1


def mechanism_pose(legs: Legs, params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Every joint of one configuration at platform position ``p`` [m] (and optional branch ``d``): the joints
    ``A_i``, ``B_i`` of the arrangement (eq. 1 / P1) and each leg's second link offset by the pivot spacing along
    ``e_{b_i}``."""
    p = as_xy(p)
    if p.shape != (2,):
        raise InputError(f"mechanism_pose takes one position of shape (2,), got {p.shape}")
    d = inverse_kinematics(legs, params, p) if d is None else as_xy(d, "d")
    A, B = legs.joints(params, p, d)
    e = np.eye(2)
    links = np.empty((2, 2, 2, 2))
    for i in range(2):
        offset = params.pivot_spacing * e[legs.across[i]]
        links[i, 0] = [A[i], B[i]]
        links[i, 1] = [A[i] + offset, B[i] + offset]
    return MechanismPose(p=p.copy(), d=d.copy(), theta=leg_angles(legs, params, p, d), A=A, B=B, links=links)
