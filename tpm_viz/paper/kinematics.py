"""Position kinematics of the 2-PPa TPM: inverse (eq. 4), forward (both assembly modes), part poses.

Shapes: a platform position ``p`` and actuator positions ``d`` are arrays of shape
``(..., 2)`` in metres; every function broadcasts over the leading axes.

Geometry (eq. 1, ``docs/conventions.md``): ``A_i = (d_i - a) e_i``, ``B_i = P - b e_i`` and
``l_a s_i = B_i - A_i``. Writing ``c_i = p_i - d_i + a - b`` (the ``e_i`` component of
``l_a s_i``), leg ``i`` satisfies ``c_i^2 + p_j^2 = l_a^2`` (eq. 27) and the leg angles are
``tan θ_i = p_j / c_i`` (eq. 23): ``θ_1`` from ``e_1`` towards ``e_2``, ``θ_2`` from ``e_2``
towards ``e_1``.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import NamedTuple

import numpy as np
from numpy.typing import ArrayLike

from tpm_viz.core.errors import InputError, SingularConfigurationError, UnreachablePoseError
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.paper.status import FK_STATUS, FkStatus

__all__ = [
    "FK_STATUS",
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


def as_xy(x: ArrayLike, name: str = "p") -> np.ndarray:
    """``x`` as a float array of shape ``(..., 2)``; raise :class:`InputError` otherwise."""
    arr = np.asarray(x, dtype=float)
    if arr.ndim == 0 or arr.shape[-1] != 2:
        raise InputError(f"{name} must have shape (..., 2), got {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise InputError(Phrase("{name} contains a non-finite value (NaN or inf)", name=name))
    return arr


def _mm(x: float) -> str:
    """A length [m] as millimetres for a message (no overflow warning for absurd values)."""
    mm = float(x) * 1e3  # Python floats overflow to inf silently
    return fixed(mm, ".1f") if abs(mm) < 1e9 else fixed(mm, ".3g")


def finite_result(arr: np.ndarray, what: str | Phrase) -> np.ndarray:
    """``arr`` unchanged if every entry is finite; otherwise an :class:`InputError` (overflow)."""
    if not np.all(np.isfinite(arr)):
        raise InputError(Phrase("{what} overflowed: the inputs are too large for finite results", what=what))
    return arr


def reachable(params: Params, p: ArrayLike) -> np.ndarray:
    """Whether eq. (4) has a real solution for both legs: ``|p_j| < l_a`` (bool, shape ``(...)``)."""
    p = np.asarray(p, dtype=float)
    return np.all(np.abs(p) < params.l_a, axis=-1) & np.all(np.isfinite(p), axis=-1)


def in_stroke(params: Params, d: ArrayLike, tol: float = 1e-12) -> np.ndarray:
    """Whether both actuators are within ``0 <= d_i <= Δd`` (bool, shape ``(...)``)."""
    d = np.asarray(d, dtype=float)
    return np.all((d >= -tol) & (d <= params.stroke + tol), axis=-1)


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
    p = as_xy(p)
    ok = reachable(params, p)
    if not np.all(ok):
        bad = p[~ok][0] if p.ndim > 1 else p
        raise UnreachablePoseError(
            Phrase(
                "platform position ({x}, {y}) mm is unreachable: each |p_j| must be below l_a = {l_a:.1f} mm",
                x=_mm(bad[0]),
                y=_mm(bad[1]),
                l_a=params.l_a * 1e3,
            )
        )
    return _ik_unchecked(params, p)


def leg_components(params: Params, p: ArrayLike, d: ArrayLike) -> tuple[np.ndarray, np.ndarray]:
    """``(c, s)`` with ``c_i = p_i - d_i + a - b = l_a cos θ_i`` and ``s_i = p_j = l_a sin θ_i`` [m]."""
    p = np.asarray(p, dtype=float)
    d = np.asarray(d, dtype=float)
    return p - d + params.offset, p[..., ::-1]


def leg_angles(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Leg angles ``θ = (θ_1, θ_2)`` [rad] from eq. (23), on the branch given by ``d``.

    ``d`` defaults to the working-mode inverse kinematics (eq. 4), where ``|θ_i| < π/2``.
    """
    p = as_xy(p)
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    c, s = leg_components(params, p, d)
    return np.arctan2(s, c)


class FkSolutions(NamedTuple):
    """Both assembly modes of the forward kinematics (platform positions in m).

    ``plus`` has ``det J_x = cos(θ_1 + θ_2) >= 0`` (the mode containing the home pose),
    ``minus`` has ``det J_x <= 0``. The direct singularity (eq. 12, ``s_1`` parallel to ``s_2``)
    takes two forms: ``s_1 = -s_2``, the circles touch and the two modes merge (in the working
    mode: the arc ``p_1² + p_2² = l_a²`` in the third quadrant); ``s_1 = s_2``, the circles
    coincide (``d_1 = d_2 = a - b``, first-quadrant arc) and the position is undetermined.
    ``exists`` is False where the circles do not meet or coincide (positions are NaN there);
    ``status`` holds a :class:`~tpm_viz.paper.status.FkStatus` value per input.
    """

    plus: np.ndarray
    minus: np.ndarray
    exists: np.ndarray
    status: np.ndarray


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
    half = dist / 2.0
    with np.errstate(invalid="ignore", divide="ignore"):
        h = np.sqrt(np.maximum(params.l_a**2 - half**2, 0.0))  # tangency within rounding: h = 0
        u = delta / dist[..., None]
    exists = (half <= params.l_a * (1 + 1e-12)) & (dist > 1e-12 * params.l_a) & np.isfinite(dist)
    h = np.where(exists, h, np.nan)
    mid = (c1 + c2) / 2.0
    normal = np.stack([-u[..., 1], u[..., 0]], axis=-1)  # u rotated by +90 deg
    cand_a = mid + h[..., None] * normal
    cand_b = mid - h[..., None] * normal
    # Order by the assembly mode: sign of s_1 x s_2 = cos(θ1+θ2) = det J_x (eq. 12).
    det_a = _cross_s(params, cand_a, d)
    swap = (det_a < 0)[..., None]
    plus = np.where(swap, cand_b, cand_a)
    minus = np.where(swap, cand_a, cand_b)
    status = np.where(h <= 1e-9 * params.l_a, FkStatus.MODES_MERGE, FkStatus.TWO_MODES)
    status = np.where(half > params.l_a * (1 + 1e-12), FkStatus.APART, status)
    status = np.where(dist <= 1e-12 * params.l_a, FkStatus.COINCIDE, status)
    return FkSolutions(plus, minus, exists, np.where(np.isfinite(dist), status, FkStatus.APART))


def _cross_s(params: Params, p: np.ndarray, d: np.ndarray) -> np.ndarray:
    """``l_a^2 (s_1 x s_2)_z = c_1 c_2 - p_2 p_1`` (proportional to det J_x, eq. 12)."""
    c, s = leg_components(params, p, d)
    return c[..., 0] * c[..., 1] - s[..., 0] * s[..., 1]


def _raise_if_missing(params: Params, d: np.ndarray, sol: FkSolutions) -> None:
    if np.all(sol.exists):
        return
    bad = np.asarray(d)[~sol.exists][0] if np.ndim(sol.exists) else np.asarray(d)
    k = params.offset
    if abs(float(bad[0]) - k) + abs(float(bad[1]) - k) <= 1e-12 * params.l_a:
        raise SingularConfigurationError(
            Phrase(
                "d1 = d2 = a - b = {k} mm: the two leg circles coincide, the platform position is undetermined "
                "(direct singularity, eq. 12)",
                k=_mm(k),
            )
        )
    raise UnreachablePoseError(
        Phrase(
            "actuators at ({d1}, {d2}) mm cannot be assembled: the leg circles are more than 2 l_a apart",
            d1=_mm(bad[0]),
            d2=_mm(bad[1]),
        )
    )


def forward_kinematics(params: Params, d: ArrayLike, mode: int = +1) -> np.ndarray:
    """Platform position [m] for actuator positions ``d`` [m] in assembly ``mode`` (+1 or -1).

    Raises :class:`UnreachablePoseError` if the two leg circles do not meet and
    :class:`SingularConfigurationError` if they coincide.
    """
    if mode not in (1, -1):
        raise InputError(f"assembly mode must be +1 or -1, got {mode!r}")
    d = as_xy(d, "d")
    sol = forward_kinematics_both(params, d)
    _raise_if_missing(params, d, sol)
    return sol.plus if mode == 1 else sol.minus


def forward_kinematics_nearest(params: Params, d: ArrayLike, p_prev: ArrayLike) -> tuple[np.ndarray, int]:
    """The assembly mode nearest a previous platform position: ``(p, mode)`` for one pose."""
    d = as_xy(d, "d")
    sol = forward_kinematics_both(params, d)
    _raise_if_missing(params, d, sol)
    p_prev = as_xy(p_prev, "p_prev")
    with np.errstate(over="ignore"):  # an absurd previous pose: both distances inf, keep "plus"
        if np.sum((sol.plus - p_prev) ** 2) <= np.sum((sol.minus - p_prev) ** 2):
            return sol.plus, 1
    return sol.minus, -1


@dataclass(frozen=True)
class MechanismPose:
    """Every point needed to draw one configuration (metres, radians; XY plane).

    ``links[i, k]`` is link ``k`` (0 or 1) of leg ``i`` as a ``(2, 2)`` array of its slider-side
    and platform-side pivots; link 0 runs from ``A_i`` to ``B_i`` (eq. 2), link 1 is offset by
    the pivot spacing along ``e_j`` (perpendicular to rail ``i``).
    """

    p: np.ndarray  # (2,) platform centre P
    d: np.ndarray  # (2,) actuator positions d_i
    theta: np.ndarray  # (2,) leg angles θ_i
    A: np.ndarray  # (2, 2) slider joints A_i (row i)
    B: np.ndarray  # (2, 2) platform joints B_i (row i)
    links: np.ndarray  # (2, 2, 2, 2) leg, link, end, xy


def mechanism_pose(params: Params, p: ArrayLike, d: ArrayLike | None = None) -> MechanismPose:
    """Positions of every joint for one platform position ``p`` (and optional branch ``d``)."""
    p = as_xy(p)
    if p.shape != (2,):
        raise InputError(f"mechanism_pose takes one position of shape (2,), got {p.shape}")
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    e = np.eye(2)
    A = (d[:, None] - params.a) * e
    B = p[None, :] - params.b * e
    links = np.empty((2, 2, 2, 2))
    for i in range(2):
        offset = params.pivot_spacing * e[1 - i]
        links[i, 0] = [A[i], B[i]]
        links[i, 1] = [A[i] + offset, B[i] + offset]
    return MechanismPose(p=p.copy(), d=d.copy(), theta=leg_angles(params, p, d), A=A, B=B, links=links)
