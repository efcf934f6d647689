"""Position kinematics of the 2-PPa TPM: inverse (eq. 4), forward (both assembly modes), part poses.

Shapes: a platform position ``p`` and actuator positions ``d`` are arrays of shape
``(..., 2)`` in metres; every function broadcasts over the leading axes.

Geometry (eq. 1, ``docs/conventions.md``): ``A_i = (d_i - a) e_i``, ``B_i = P - b e_i`` and
``l_a s_i = B_i - A_i``. Writing ``c_i = p_i - d_i + a - b`` (the ``e_i`` component of
``l_a s_i``), leg ``i`` satisfies ``c_i^2 + p_j^2 = l_a^2`` (eq. 27) and the leg angles are
``tan θ_i = p_j / c_i`` (eq. 23): ``θ_1`` from ``e_1`` towards ``e_2``, ``θ_2`` from ``e_2``
towards ``e_1``.

The paper's own equations are here (eq. 4, the two leg circles, the joints of eq. 1, the refusals), gathered in
:data:`PERPENDICULAR`; what both arrangements share (the checked inverse kinematics, the leg angles, the choice of
assembly mode, the links of a pose) is :mod:`tpm_viz.paper.legs`, written once.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper import legs
from tpm_viz.paper.legs import FkSolutions, Legs, MechanismPose, as_xy, finite_result, in_stroke, mm
from tpm_viz.paper.status import FK_STATUS

__all__ = [
    "FK_STATUS",
    "PERPENDICULAR",
    "FkSolutions",
    "MechanismPose",
    "as_xy",
    "finite_result",
    "forward_kinematics",
    "forward_kinematics_both",
    "forward_kinematics_nearest",
    "in_stroke",
    "inverse_kinematics",
    "leg_angles",
    "leg_components",
    "mechanism_pose",
    "reachable",
]


def reachable(params: Params, p: ArrayLike) -> np.ndarray:
    """Whether eq. (4) has a real solution for both legs: ``|p_j| < l_a`` (bool, shape ``(...)``)."""
    p = np.asarray(p, dtype=float)
    return np.all(np.abs(p) < params.l_a, axis=-1) & np.all(np.isfinite(p), axis=-1)


def _ik_unchecked(params: Params, p: np.ndarray) -> np.ndarray:
    """Eq. (4) without checks: ``d_i = p_i + a - b - sqrt(l_a^2 - p_j^2)``; NaN where unreachable."""
    with np.errstate(invalid="ignore"):
        root = np.sqrt(params.l_a**2 - p[..., ::-1] ** 2)
    return p + params.offset - root


def inverse_kinematics(params: Params, p: ArrayLike) -> np.ndarray:
    """Actuator positions ``d`` [m] for platform positions ``p`` [m], eq. (4).

    Uses the negative root of eq. (3) (the working mode: each slider on its base side
    of the platform). Raises :class:`UnreachablePoseError` if some ``|p_j| >= l_a``.
    The stroke is not enforced here: see :func:`in_stroke` and ``classify``.
    """
    return legs.inverse_kinematics(PERPENDICULAR, params, p)


def leg_components(params: Params, p: ArrayLike, d: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(c, s)`` with ``c_i = p_i - d_i + a - b = l_a cos θ_i`` and ``s_i = p_j = l_a sin θ_i`` [m]."""
    p = np.asarray(p, dtype=float)
    d = np.asarray(d, dtype=float)
    return p - d + params.offset, p[..., ::-1]


def leg_angles(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angles ``θ = (θ_1, θ_2)`` [rad] from eq. (23), on the branch given by ``d``.

    ``d`` defaults to the working-mode inverse kinematics (eq. 4), where ``|θ_i| < π/2``.
    """
    return legs.leg_angles(PERPENDICULAR, params, p, d)


def forward_kinematics_both(params: Params, d: ArrayLike) -> FkSolutions:
    """Both platform positions for actuator positions ``d`` [m] (intersections of two circles).

    Leg 1 confines ``P`` to the circle of radius ``l_a`` about ``C_1 = (d_1 - a + b, 0)``,
    leg 2 to the circle about ``C_2 = (0, d_2 - a + b)``.
    """
    d = as_xy(d, "d")
    with np.errstate(over="ignore", invalid="ignore", divide="ignore"):
        return _fk_both(params, d)


def _fk_both(params: Params, d: np.ndarray) -> FkSolutions:
    k = params.offset
    c1 = np.stack([d[..., 0] - k, np.zeros_like(d[..., 0])], axis=-1)
    c2 = np.stack([np.zeros_like(d[..., 1]), d[..., 1] - k], axis=-1)
    delta = c2 - c1
    dist = np.linalg.norm(delta, axis=-1)
    h, exists, status = legs.meeting(params, dist)
    u = delta / dist[..., None]
    mid = (c1 + c2) / 2.0
    normal = np.stack([-u[..., 1], u[..., 0]], axis=-1)  # u rotated by +90 deg
    cand_a = mid + h[..., None] * normal
    cand_b = mid - h[..., None] * normal
    # Order by the assembly mode: sign of s_1 x s_2 = cos(θ1+θ2) = det J_x (eq. 12).
    det_a = _cross_s(params, cand_a, d)
    swap = (det_a < 0)[..., None]
    plus = np.where(swap, cand_b, cand_a)
    minus = np.where(swap, cand_a, cand_b)
    return FkSolutions(plus, minus, exists, status)


def _cross_s(params: Params, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``l_a^2 (s_1 x s_2)_z = c_1 c_2 - p_2 p_1`` (proportional to det J_x, eq. 12)."""
    c, s = leg_components(params, p, d)
    return c[..., 0] * c[..., 1] - s[..., 0] * s[..., 1]


def _coincide(params: Params, d: np.ndarray) -> Phrase | None:
    k = params.offset
    if abs(float(d[0]) - k) + abs(float(d[1]) - k) <= 1e-12 * params.l_a:
        return Phrase(
            "d1 = d2 = a - b = {k} mm: the two leg circles coincide, the platform position is undetermined "
            "(direct singularity, eq. 12)",
            k=mm(k),
        )
    return None


def forward_kinematics(params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] for actuator positions ``d`` [m] in assembly ``mode`` (+1 or -1).

    Raises :class:`UnreachablePoseError` if the two leg circles do not meet and
    :class:`SingularConfigurationError` if they coincide.
    """
    return legs.forward_kinematics(PERPENDICULAR, params, d, mode)


def forward_kinematics_nearest(params: Params, d: ArrayLike, p_prev: ArrayLike) -> tuple[np.ndarray, int]:
    """The assembly mode nearest a previous platform position: ``(p, mode)`` for one pose."""
    return legs.forward_kinematics_nearest(PERPENDICULAR, params, d, p_prev)


def _joints(params: Params, p: np.ndarray, d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Eq. (1): ``A_i = (d_i - a) e_i``, ``B_i = P - b e_i``."""
    e = np.eye(2)
    return (d[:, None] - params.a) * e, p[None, :] - params.b * e


def mechanism_pose(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Positions of every joint for one platform position ``p`` (and optional branch ``d``); link 1 of leg ``i``
    is offset by the pivot spacing along ``e_j`` (perpendicular to rail ``i``)."""
    return legs.mechanism_pose(PERPENDICULAR, params, p, d)


PERPENDICULAR = Legs(
    along=(0, 1),
    sign=(1.0, 1.0),
    across=(1, 0),
    singularities=("cos θ1 cos θ2 = 0 (eq. 11)", "cos(θ1 + θ2) = 0 (eq. 12)"),
    unreachable=Phrase("platform position ({x}, {y}) mm is unreachable: each |p_j| must be below l_a = {l_a:.1f} mm"),
    reachable=reachable,
    ik=_ik_unchecked,
    components=leg_components,
    circles=forward_kinematics_both,
    joints=_joints,
    coincide=_coincide,
)
"""The paper's legs (:class:`~tpm_viz.paper.legs.Legs`): ``c_i = p_i - d_i + a - b``, ``s_i = p_j``."""
