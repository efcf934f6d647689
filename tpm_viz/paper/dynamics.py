"""The paper's closed-form inverse dynamics (Lagrange's equations of the first kind, eqs. 16-31).

Generalised coordinates ``q = (p_1, p_2, d_1, d_2)`` (eq. 16), constraints
``Γ_i = c_i^2 + p_j^2 - l_a^2`` with ``c_i = p_i - d_i + a - b`` (eq. 27). The procedure of
Section 3, steps (a)-(e):

(a) ``d_i`` from the inverse kinematics, eq. (4);
(b) ``ḋ = J ṗ``, eq. (9);
(c) ``d̈`` from eq. (14) (with the corrected sign of ``J̇_q`` in eq. 15);
(d) multipliers ``λ = G_p^{-1} (v - f_ext)`` with ``G_p = [[2 c_1, 2 p_1], [2 p_2, 2 c_2]]``,
    eqs. (28)-(29);
(e) actuator forces ``τ_i = w_i + 2 λ_i c_i``, eqs. (30)-(31).

``v_i`` and ``w_i`` are the printed expressions below eqs. (29) and (31), written with
``c_i`` in place of ``p_i - d_i + a - b``; both were re-derived and agree with the paper.
Mass model (``docs/conventions.md``): sliders ``m_a`` and platform ``m_p`` translate; each
parallelogram's two links (together ``m_b``) are uniform slender rods, which gives the
link kinetic energy of eq. (22) read with ``ḋ_i^2`` (the paper prints ``d_i^2``: erratum).
No gravity (horizontal plane, ``U = 0``), no friction. Forces in N, SI throughout.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import cast

import numpy as np
from numpy.typing import ArrayLike, NDArray

from tpm_viz.core.errors import SingularConfigurationError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.jacobians import actuator_velocity
from tpm_viz.paper.kinematics import as_xy, finite_result, inverse_kinematics, leg_components

__all__ = ["SINGULAR_TOL", "DynamicsResult", "inverse_dynamics", "inverse_dynamics_detail", "kinetic_energy"]


Component = float | NDArray[np.float64]
"""One component of a state [SI]: a float, or an array of them (all of one shape). The C generator
(:mod:`tpm_viz.exchange.c.code`) traces :func:`_procedure` with its own symbols instead."""


@dataclass(frozen=True)
class DynamicsResult:
    """Every intermediate of the procedure (a)-(e); arrays of shape ``(..., 2)`` in SI units."""

    p: np.ndarray  # platform position [m]
    dp: np.ndarray  # platform velocity [m/s]
    ddp: np.ndarray  # platform acceleration [m/s^2]
    d: np.ndarray  # (a) actuator positions [m]
    dd: np.ndarray  # (b) actuator velocities [m/s]
    ddd: np.ndarray  # (c) actuator accelerations [m/s^2]
    v: np.ndarray  # eq. (29) right-hand side v_i [N]
    w: np.ndarray  # eq. (31) w_i [N]
    lam: np.ndarray  # (d) Lagrange multipliers λ_i [N/m]
    tau: np.ndarray  # (e) actuator forces τ_i [N]


def _v_leg(
    mp: float,
    mb: float,
    pi: Component,
    pj: Component,
    dpi: Component,
    dpj: Component,
    ddpi: Component,
    ci: Component,
    cj: Component,
    ddi: Component,
    ddj: Component,
    dddj: Component,
) -> Component:
    """``v_i`` below eq. (29) [N] as printed; ``j`` is the other leg. Floats or arrays. :func:`_procedure` computes
    the same terms regrouped; this form is the tests' reference for the regrouping."""
    return (
        (mp + mb / 3.0) * ddpi
        - mb * pj * ddi * dpj / (2.0 * ci**2)
        + mb * pj**2 * dpj**2 / (3.0 * ci**3)
        + mb * pi * (-(ddj**2) + ddj * dpj - cj * dddj) / (2.0 * cj**2)
        + mb * pi * dpi**2 / (3.0 * cj**2)
        + mb * pi**2 * (2.0 * dpi * (ddj - dpj) + cj * ddpi) / (3.0 * cj**3)
    )


def _w_leg(
    ma: float, mb: float, pj: Component, dpi: Component, dpj: Component, ddpj: Component, ci: Component, dddi: Component
) -> Component:
    """``w_i`` below eq. (31) [N] as printed. Floats or arrays (the tests' reference, see :func:`_v_leg`)."""
    return (
        (ma + mb) * dddi
        - mb * dpj**2 / (2.0 * ci)
        - mb * pj**2 * dpj**2 / (3.0 * ci**3)
        + mb * pj * (dpi * dpj - ci * ddpj) / (2.0 * ci**2)
    )


def _procedure(
    params: Params,
    p1: Component,
    p2: Component,
    dp1: Component,
    dp2: Component,
    ddp1: Component,
    ddp2: Component,
    c1: Component,
    c2: Component,
    f1: Component,
    f2: Component,
) -> tuple:
    """Steps (b)-(e) on components (floats or equal-shape arrays); ``c_i = p_i - d_i + a - b``.

    Returns ``(dd1, dd2, ddd1, ddd2, v1, v2, w1, w2, lam1, lam2, tau1, tau2)``. The terms of ``v_i`` and ``w_i``
    are those printed below eqs. (29) and (31) (:func:`_v_leg`, :func:`_w_leg`) regrouped with
    ``t_i = tan θ_i = p_j / c_i`` (eq. 23), ``ω_i = θ̇_i = ṗ_j / c_i`` (eq. 24) and ``q_i = t_i ω_i`` so that
    each appears once (~110 operations instead of ~190; ``tests/paper/test_dynamics_factored.py`` checks the
    regrouping against the printed forms). The generated C (:mod:`tpm_viz.exchange.c.code`) is traced from here.
    """
    u1, u2 = 1.0 / c1, 1.0 / c2
    t1, t2 = p2 * u1, p1 * u2  # tan θ_i
    o1, o2 = dp2 * u1, dp1 * u2  # θ̇_i
    dd1 = dp1 + t1 * dp2  # (b) eq. (9): ḋ_i = ṗ_i + tan θ_i ṗ_j
    dd2 = dp2 + t2 * dp1
    q1, q2 = t1 * o1, t2 * o2
    k1, k2 = q1 * dd1, q2 * dd2
    ddd1 = o1 * (dp2 - t1 * dp1) + ddp1 + t1 * ddp2 + k1  # (c) eq. (14), corrected eq. (15): jacobians.eq14_row
    ddd2 = o2 * (dp1 - t2 * dp2) + ddp2 + t2 * ddp1 + k2
    mp, ma, mb = params.m_p, params.m_a, params.m_b
    h, r, m0, m1 = 0.5 * mb, mb / 3.0, mp + mb / 3.0, ma + mb
    e1, e2 = r * (q1 * q1 * c1), r * (q2 * q2 * c2)  # m_b p_j² ṗ_j² / (3 c_i³)
    # with ḋ_i - ṗ_i = t_i ṗ_j (eq. 9): (ḋ_i ṗ_i - ḋ_i²) / c_i - d̈_i = -(k_i + d̈_i), 2 ṗ_j (ḋ_i - ṗ_i) / c_i = 2 q_i ṗ_j
    n1, n2 = k1 + ddd1, k2 + ddd2
    g1, g2 = q1 * dp2, q2 * dp1  # r g_i = m_b p_j ṗ_j² / (3 c_i²), a term of v_j
    ht1, ht2 = h * t1, h * t2
    v1 = m0 * ddp1 - h * k1 + e1 - ht2 * n2 + r * g2 + r * (t2 * t2) * (2.0 * g2 + ddp1) - f1
    v2 = m0 * ddp2 - h * k2 + e2 - ht1 * n1 + r * g1 + r * (t1 * t1) * (2.0 * g1 + ddp2) - f2
    # (d) eq. (29): [[2c1, 2p1], [2p2, 2c2]] λ = v - f (eq. 28); determinant 4 (c1 c2 - p1 p2) = 4 l_a² det J_x.
    g = 0.5 / (c1 * c2 - p1 * p2)
    lam1 = (c2 * v1 - p1 * v2) * g
    lam2 = (c1 * v2 - p2 * v1) * g
    w1 = m1 * ddd1 - h * o1 * dp2 - e1 + ht1 * (dp1 * o1 - ddp2)
    w2 = m1 * ddd2 - h * o2 * dp1 - e2 + ht2 * (dp2 * o2 - ddp1)
    return dd1, dd2, ddd1, ddd2, v1, v2, w1, w2, lam1, lam2, w1 + 2.0 * lam1 * c1, w2 + 2.0 * lam2 * c2  # (e)


SINGULAR_TOL = 1e-12
"""The closed form refuses a pose with ``|c_1 c_2| < SINGULAR_TOL l_a²`` (``|cos θ1 cos θ2|`` below it, eq. 11)
or ``|c_1 c_2 - p_1 p_2| < SINGULAR_TOL l_a²`` (``|cos(θ1 + θ2)|`` below it, eq. 12); the generated C too, and the
parallel closed form on ``|c_1 c_2|`` and ``|p_2 (c_1 + c_2)|`` (``|sin(θ1 + θ2)|``, eq. P12)."""


_EQ11 = "cos θ1 cos θ2 = 0 (eq. 11)"
_EQ12 = "cos(θ1 + θ2) = 0 (eq. 12)"


def _check_regular(params: Params, c1: Component, c2: Component, p1: Component, p2: Component) -> None:
    l2 = params.l_a**2
    if np.any(np.abs(c1 * c2) < SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq=_EQ11))
    if np.any(np.abs(c1 * c2 - p1 * p2) < SINGULAR_TOL * l2):
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq=_EQ12))


_BLOCK = 8192
"""States per block of the vectorised path: its temporaries (64 KiB each) stay in the cache, below the allocator's
mmap threshold; 2-3x faster than whole 10^5-state arrays, ~1.4x faster than blocks of 2048 where numpy's per-call
overhead starts to count (benchmarks/bench_core.py)."""


def _vectorised(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None,
    d: ArrayLike | None,
    outputs: tuple[int, ...] = tuple(range(12)),
) -> tuple[
    NDArray[np.float64], NDArray[np.float64], NDArray[np.float64], NDArray[np.float64] | None, NDArray[np.float64]
]:
    """Steps (a)-(e) on broadcast arrays: returns ``(p, dp, ddp, d, out)``; ``out[k]`` (shape ``(...)``) is the
    ``outputs[k]``-th result of :func:`_procedure`; ``d`` is None unless every output is wanted."""
    p, dp, ddp = np.broadcast_arrays(as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp"))
    f = np.zeros(2) if f_ext is None else as_xy(f_ext, "f_ext")
    shape = p.shape[:-1]
    n = math.prod(shape)
    cols = np.empty((10, n))  # rows p1 p2 dp1 dp2 ddp1 ddp2 c1 c2 f1 f2, each contiguous
    for k, arr in enumerate((p, dp, ddp)):
        cols[2 * k : 2 * k + 2] = arr.reshape(n, 2).T
    cols[8:10] = np.broadcast_to(f, p.shape).reshape(n, 2).T
    working = d is None
    if d is None:  # (a) eq. (4), working mode: c_i = sqrt(l_a² - p_j²) (in the loop), d_i = p_i + a - b - c_i
        if n and not np.abs(cols[0:2]).max() < params.l_a:
            inverse_kinematics(params, p)  # raises the precise error
    else:
        d = np.broadcast_to(as_xy(d, "d"), p.shape)
        cols[6:8] = leg_components(params, p, d)[0].reshape(n, 2).T
    la2 = params.l_a**2
    out = np.empty((len(outputs), n))
    with np.errstate(over="ignore", invalid="ignore"):
        for start in range(0, n, _BLOCK):  # block by block: every pass over the states stays in the cache
            blk = cols[:, start : start + _BLOCK]
            if working:
                np.sqrt(la2 - blk[1] ** 2, out=blk[6])
                np.sqrt(la2 - blk[0] ** 2, out=blk[7])
            _check_regular(params, blk[6], blk[7], blk[0], blk[1])
            block = _procedure(params, *blk)
            for row, k in enumerate(outputs):
                out[row, start : start + _BLOCK] = block[k]
    if working and len(outputs) == 12:
        d = (cols[0:2] + params.offset - cols[6:8]).T.reshape(p.shape)
    return p, dp, ddp, d, out.reshape(len(outputs), *shape)


def inverse_dynamics_detail(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None = None,
    d: ArrayLike | None = None,
) -> DynamicsResult:
    """The paper's procedure (a)-(e) with every intermediate (see module docstring).

    ``p, dp, ddp`` [m, m/s, m/s²] have shape ``(..., 2)``; ``f_ext`` [N] is an external force
    applied to the platform (eq. 28), broadcastable to ``(..., 2)``; ``d`` selects the branch
    (default: working mode, eq. 4). Raises :class:`SingularConfigurationError` at a singular
    configuration (``cos θ_i = 0`` or ``cos(θ1 + θ2) = 0``).
    """
    p, dp, ddp, d, out = _vectorised(params, p, dp, ddp, f_ext, d)
    assert d is not None  # every output was asked for
    dd, ddd, v, w, lam, tau = (np.stack(tuple(out[k : k + 2]), -1) for k in range(0, 12, 2))
    finite_result(tau, T("the actuator forces"))
    return DynamicsResult(p=p, dp=dp, ddp=ddp, d=d, dd=dd, ddd=ddd, v=v, w=w, lam=lam, tau=tau)


def _pair(x: object) -> tuple[float, float] | None:
    """``x`` as two floats if it is one 2-vector (a sequence or an array of shape ``(2,)``), else None."""
    if isinstance(x, np.ndarray):
        if x.shape != (2,):
            return None
        x = cast(list, x.tolist())
    elif not isinstance(x, (list, tuple)) or len(x) != 2:
        return None
    try:
        return float(x[0]), float(x[1])
    except (TypeError, ValueError):
        return None


def _inverse_dynamics_one(
    params: Params, p: ArrayLike, dp: ArrayLike, ddp: ArrayLike, f_ext: ArrayLike | None, d: ArrayLike | None = None
) -> np.ndarray | None:
    """Fast path for one state given as 2-vectors: pure ``math``, no array temporaries (~5 µs).

    Returns None when the input is not a plain single state, or not finite (the caller then vectorises,
    which raises the precise error).
    """
    pp, vv, aa = _pair(p), _pair(dp), _pair(ddp)
    ff = (0.0, 0.0) if f_ext is None else _pair(f_ext)
    dd = None if d is None else _pair(d)
    if pp is None or vv is None or aa is None or ff is None or (d is not None and dd is None):
        return None
    (p1, p2), (dp1, dp2), (ddp1, ddp2), (f1, f2) = pp, vv, aa, ff
    la = params.l_a
    isfinite = math.isfinite
    if not (abs(p1) < la and abs(p2) < la and isfinite(dp1 + dp2) and isfinite(ddp1 + ddp2) and isfinite(f1 + f2)):
        return None  # unreachable or not finite (a sum of two finite floats may overflow: then vectorise too)
    la2 = la**2
    if dd is None:
        c1, c2 = math.sqrt(la2 - p2 * p2), math.sqrt(la2 - p1 * p1)  # eq. (4): c_i = sqrt(l_a² - p_j²)
    else:
        if not isfinite(dd[0] + dd[1]):
            return None
        c1, c2 = p1 - dd[0] + params.offset, p2 - dd[1] + params.offset  # c_i = l_a cos θ_i on d's branch
    if abs(c1 * c2) < SINGULAR_TOL * la2:
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq=_EQ11))
    if abs(c1 * c2 - p1 * p2) < SINGULAR_TOL * la2:
        raise SingularConfigurationError(Phrase("singular configuration: {eq}", eq=_EQ12))
    try:
        out = _procedure(params, p1, p2, dp1, dp2, ddp1, ddp2, c1, c2, f1, f2)
        tau1, tau2 = out[10], out[11]
    except OverflowError:
        tau1 = tau2 = math.inf
    if not (isfinite(tau1) and isfinite(tau2)):
        finite_result(np.array([tau1, tau2]), T("the actuator forces"))  # raises
    return np.array((tau1, tau2))


def inverse_dynamics(
    params: Params,
    p: ArrayLike,
    dp: ArrayLike,
    ddp: ArrayLike,
    f_ext: ArrayLike | None = None,
    d: ArrayLike | None = None,
) -> np.ndarray:
    """Actuator forces ``τ`` [N], shape ``(..., 2)``, by the paper's closed form (eqs. 29, 31).

    See :func:`inverse_dynamics_detail` for the arguments and the intermediates. One state given as 2-vectors
    (with or without ``d``) takes a scalar fast path (same formulas, same refusals, ~5 µs).
    """
    tau = _inverse_dynamics_one(params, p, dp, ddp, f_ext, d)
    if tau is not None:
        return tau
    out = _vectorised(params, p, dp, ddp, f_ext, d, (10, 11))[4]
    return finite_result(np.stack((out[0], out[1]), -1), T("the actuator forces"))


def kinetic_energy(params: Params, p: ArrayLike, dp: ArrayLike, d: ArrayLike | None = None) -> np.ndarray:
    """Total kinetic energy ``K`` [J] of eqs. (20)-(22) (``ḋ_i^2`` read for ``d_i^2`` in eq. 22)."""
    p, dp = as_xy(p), as_xy(dp, "dp")
    d = inverse_kinematics(params, p) if d is None else as_xy(d, "d")
    dd = actuator_velocity(params, p, dp, d)
    c, s = leg_components(params, p, d)
    th_dot = dp[..., ::-1] / c  # eq. (24): θ̇_i = ṗ_j / (l_a cos θ_i), l_a cos θ_i = c_i
    sin = s / params.l_a
    la, ma, mb = params.l_a, params.m_a, params.m_b
    k_p = 0.5 * params.m_p * np.sum(dp**2, axis=-1)
    k_a = 0.5 * ma * np.sum(dd**2, axis=-1)
    k_b = np.sum(mb * la**2 * th_dot**2 / 6.0 + 0.5 * mb * (dd**2 - la * dd * th_dot * sin), axis=-1)
    return k_p + k_a + k_b
