"""Time-optimal timing of a geometric path within the motors' force limits (toppra), eqs. (9), (29)-(31).

Problem: along a path ``p(s)`` of :mod:`tpm_viz.app.paths` (arc length ``s`` [m]), find the fastest rest-to-rest
``s(t)`` with ``|τ_i| <= F_max`` [N] for both actuators, optionally ``|ṗ| <= v_max`` [m/s] (platform speed)
and ``|ḋ_i| <= v_act`` [m/s] (actuator speed, ``ḋ = J ṗ``, eq. 9).

The closed form ``τ(p, ṗ, p̈)`` (eqs. 29-31) is affine in ``p̈`` and quadratic in ``ṗ`` (no gravity, no friction),
so along the path, with ``ṗ = p' ṡ`` and ``p̈ = p' s̈ + p'' ṡ²``,

    ``τ = a(s) s̈ + b(s) ṡ²`` with ``a(s) = τ(p, 0, p')`` and ``b(s) = τ(p, p', p'')``,

which are exact (two evaluations of :func:`tpm_viz.paper.dynamics.inverse_dynamics` per grid point). toppra
(Pham & Pham 2018, reachability analysis, ``seidel`` LP solver) solves the discretised problem with the
*interpolation* scheme (the limits hold at both ends of every grid interval). The output keeps toppra's
piecewise-constant ``s̈`` per interval; ``s, ṡ`` are then exact quadratics and linear functions of time, and
``p, ṗ, p̈, τ`` are evaluated exactly from them (no numerical differentiation). A final uniform time scaling
(``τ`` scales as ``1/k²``) removes the residual overshoot between grid points found on a 1 kHz check.

Why toppra: it is maintained, takes a callable or precomputed second-order constraint and solves 300 grid points
in about 15 ms (``benchmarks/bench_planner.py``). Two details matter here: the LP solver uses absolute
tolerances, so the path parameter is rescaled to make the coefficients of order one (without it some parameter
sets fail as "not controllable"); and its ``xbound`` argument fails with ``seidel``, so speed limits enter as a
row ``ṡ² <= x_max`` of the constraint. Importing toppra loads matplotlib (~1 s): the command line imports this
module only in ``tpm-viz plan``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import SupportsFloat

import numpy as np
from numpy.typing import ArrayLike
from toppra.algorithm import TOPPRA, ParameterizationReturnCode
from toppra.constraint import DiscretizationType, LinearConstraint
from toppra.interpolator import AbstractGeometricPath

from tpm_viz.app.paths import GeometricPath, check_path
from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase, T
from tpm_viz.paper.arrangement import Arrangement, actuator_velocity, inverse_dynamics

__all__ = ["CHECK_RATE", "DEFAULT_GRID", "Limits", "Plan", "PlanSamples", "plan_cycle", "plan_path"]

DEFAULT_GRID = 300
"""Default number of grid points along the path."""
CHECK_RATE = 1000.0
"""Rate [Hz] at which the planned forces are checked (and the timing stretched if they overshoot)."""
MAX_GRID = 20_000
MAX_SAMPLES = 2_000_000
MAX_DURATION = 1e4
"""Longest motion [s] the planner returns."""
MAX_CHECK = 200_000
_PAPER = Arrangement.PERPENDICULAR  # the default arrangement of the helpers below


def _limit(value: str | SupportsFloat | None, name: str | Phrase, unit: str | Phrase, top: float = 1e9) -> float | None:
    if value is None:
        return None
    try:
        value = float(value)
    except (TypeError, ValueError):
        raise InputError(
            Phrase("{name} must be a number of {unit}, got {got}", name=name, unit=unit, got=repr(value))
        ) from None
    if not math.isfinite(value) or value <= 0:
        raise InputError(
            Phrase("{name} must be a positive, finite number of {unit}, got {got:g}", name=name, unit=unit, got=value)
        )
    if not 1e-6 <= value <= top:
        raise InputError(
            Phrase("{name} must be from 1e-06 to {top:g} {unit}, got {got:g}", name=name, unit=unit, top=top, got=value)
        )
    return value


@dataclass(frozen=True)
class Limits:
    """Bounds of the planned motion: ``|τ_i| <= force`` [N], ``|ṗ| <= speed`` [m/s], ``|ḋ_i| <= actuator_speed``."""

    force: float
    speed: float | None = None
    actuator_speed: float | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "force", _limit(self.force, T("the force limit"), T("newtons")))
        object.__setattr__(self, "speed", _limit(self.speed, T("the speed limit"), "m/s"))
        object.__setattr__(self, "actuator_speed", _limit(self.actuator_speed, T("the actuator speed limit"), "m/s"))


@dataclass(frozen=True)
class _TimeLaw:
    """``s(t)`` with constant ``s̈ = u[k]`` on ``[t[k], t[k+1]]`` (grid ``s_grid``, speeds ``sd``)."""

    s_grid: np.ndarray
    sd: np.ndarray
    u: np.ndarray
    t_grid: np.ndarray
    stretch: float = 1.0

    @classmethod
    def from_speeds(cls, s_grid: np.ndarray, sd: np.ndarray) -> _TimeLaw:
        ds = np.diff(s_grid)
        u = (sd[1:] ** 2 - sd[:-1] ** 2) / (2 * ds)  # constant s̈ on each interval [m/s²]
        dt = 2 * ds / (sd[1:] + sd[:-1])
        return cls(s_grid, sd, u, np.concatenate([[0.0], np.cumsum(dt)]))

    def scaled(self, k: float) -> _TimeLaw:
        """The same law run ``k`` times slower (``ṡ / k``, ``s̈ / k²``)."""
        return _TimeLaw(self.s_grid, self.sd / k, self.u / k**2, self.t_grid * k, self.stretch * k)

    def __call__(self, t: ArrayLike) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        t = np.clip(np.asarray(t, float), 0.0, self.t_grid[-1])
        k = np.clip(np.searchsorted(self.t_grid, t, side="right") - 1, 0, len(self.u) - 1)
        h = t - self.t_grid[k]
        s = self.s_grid[k] + self.sd[k] * h + 0.5 * self.u[k] * h**2
        return np.minimum(s, self.s_grid[-1]), self.sd[k] + self.u[k] * h, self.u[k]


def _coefficients(
    params: Params, path: GeometricPath, s: np.ndarray, side: str = "right", arrangement: Arrangement = _PAPER
) -> tuple[np.ndarray, np.ndarray]:
    """``a(s) = τ(p, 0, p')`` and ``b(s) = τ(p, p', p'')`` [N s²/m], so that ``τ = a s̈ + b ṡ²`` (eqs. 29-31).

    ``side`` picks the segment at a junction, where ``p''`` (hence ``b``) jumps; ``arrangement`` picks the closed form
    (:mod:`tpm_viz.paper.arrangement`).
    """
    p, ps, pss = path.evaluate(s), path.evaluate(s, 1), path.evaluate(s, 2, side)
    zero = np.zeros_like(p)
    return inverse_dynamics(arrangement, params, p, zero, ps), inverse_dynamics(arrangement, params, p, ps, pss)


def _speed_bound(
    params: Params, path: GeometricPath, s: np.ndarray, limits: Limits, arrangement: Arrangement = _PAPER
) -> np.ndarray:
    """Upper bound on ``ṡ²`` [m²/s²] from the speed limits (``|p'| = 1``; ``ḋ = J p' ṡ``, eq. 9)."""
    bound = np.full(s.shape, np.inf)
    if limits.speed is not None:
        bound[:] = limits.speed**2
    if limits.actuator_speed is not None:
        velocity = actuator_velocity(arrangement, params, path.evaluate(s), path.evaluate(s, 1))
        gain = np.max(np.abs(velocity), axis=-1)
        with np.errstate(divide="ignore"):
            bound = np.minimum(bound, (limits.actuator_speed / gain) ** 2)
    return bound


def _interpolation_rows(start: tuple, end: tuple, xmax: np.ndarray, s_grid: np.ndarray) -> tuple:
    """toppra's canonical form ``v = a u + b x``, ``F v <= g`` per grid interval, *interpolation* scheme.

    Interval ``k`` holds constant ``u = s̈`` and ``x = ṡ²``; its forces must lie within the limits both at its start
    (``start = (a, b)``, right-hand limits at the grid points) and at its end, where ``x`` has grown to
    ``x + 2 Δs u`` (``end``: left-hand limits, the same segment's curvature when a junction falls on a grid point).
    Forces are normalised by ``F_max``; a speed row ``ṡ² <= xmax`` is added when a speed limit applies.
    """
    (a, b), (a_end, b_end) = start, end
    n = len(s_grid)
    delta = np.append(np.diff(s_grid), 0.0)[:, None]
    nxt = np.append(np.arange(1, n), n - 1)
    a_next, b_next = a_end[nxt], b_end[nxt]
    aa = np.hstack([a, a_next + 2 * delta * b_next])
    bb = np.hstack([b, b_next])
    rows = np.vstack([np.eye(2), -np.eye(2)])
    f = np.zeros((8, 4))
    f[:4, :2], f[4:, 2:] = rows, rows
    g = np.ones((n, 8))
    if np.any(np.isfinite(xmax)):  # v_5 = ṡ² <= xmax (toppra's own xbound argument fails with seidel)
        aa, bb = np.column_stack([aa, np.zeros(n)]), np.column_stack([bb, np.ones(n)])
        f = np.vstack([np.column_stack([f, np.zeros(8)]), [0.0, 0.0, 0.0, 0.0, 1.0]])
        g = np.column_stack([g, np.minimum(xmax, 1e12)])
    return aa, bb, np.zeros_like(aa), np.repeat(f[None], n, axis=0), g


class _ForceLimits(LinearConstraint):
    """``|τ_i| <= F_max`` (and the speed limits) as toppra's canonical rows, precomputed and vectorised."""

    def __init__(self, rows: tuple) -> None:
        super().__init__()
        self.set_discretization_type(DiscretizationType.Interpolation)
        self.rows = rows

    def compute_constraint_params(
        self, path: object, gridpoints: np.ndarray, *args: object, **kwargs: object
    ) -> tuple[np.ndarray | None, ...]:
        return (*self.rows, None, None)


class _Interval(AbstractGeometricPath):
    """The path parameter's range for toppra; positions are never needed (the constraint holds the values)."""

    def __init__(self, s_grid: np.ndarray) -> None:
        self._interval = np.array([s_grid[0], s_grid[-1]])

    @property
    def dof(self) -> int:
        return 2

    @property
    def path_interval(self) -> np.ndarray:
        return self._interval

    def __call__(self, ss: ArrayLike, order: int = 0) -> np.ndarray:
        return np.zeros((*np.shape(ss), 2))


def _toppra_speeds(rows: tuple, s_grid: np.ndarray) -> np.ndarray:
    """Time-optimal rest-to-rest speeds ``ṡ`` at the grid points: toppra's TOPPRA with the ``seidel`` LP solver."""
    algo = TOPPRA([_ForceLimits(rows)], _Interval(s_grid), gridpoints=s_grid, solver_wrapper="seidel")
    algo.compute_parameterization(0.0, 0.0)
    data = algo.problem_data
    if data.return_code != ParameterizationReturnCode.Ok or data.sd_vec is None:
        raise InputError(
            Phrase("no feasible timing within the limits along this path ({code})", code=data.return_code.value)
        )
    return np.maximum(np.asarray(data.sd_vec, float).ravel(), 0.0)


def _scale(a: np.ndarray) -> float:
    """Path-parameter unit λ [m] that makes ``a λ`` of order one (``a`` normalised by ``F_max``)."""
    return 1.0 / float(np.median(np.max(np.abs(a), axis=1)))


def _plan_one(
    params: Params, path: GeometricPath, limits: Limits, grid: int, rate: float, arrangement: Arrangement = _PAPER
) -> _TimeLaw:
    """The time law of one rest-to-rest motion, stretched if the ``rate`` check finds an overshoot."""
    s_grid = np.unique(np.concatenate([np.linspace(0.0, path.length, int(grid)), path.junctions]))
    a, b = (x / limits.force for x in _coefficients(params, path, s_grid, "right", arrangement))
    a_end, b_end = (x / limits.force for x in _coefficients(params, path, s_grid, "left", arrangement))
    # toppra's LP solver works with absolute tolerances: run it on σ = s / λ, where the coefficients are O(1)
    lam = _scale(a)
    start, end = (a * lam, b * lam**2), (a_end * lam, b_end * lam**2)
    xmax = _speed_bound(params, path, s_grid, limits, arrangement) / lam**2
    sd = lam * _toppra_speeds(_interpolation_rows(start, end, xmax, s_grid / lam), s_grid / lam)
    if not np.all(sd[1:-1] > 0):
        raise InputError(Phrase("no feasible timing within the limits along this path: raise the limits or the grid"))
    law = _TimeLaw.from_speeds(s_grid, sd)
    if not law.t_grid[-1] <= MAX_DURATION:
        raise InputError(
            Phrase(
                "the motion would last {t:.3g} s (over {most:g} s): raise the limits",
                t=float(law.t_grid[-1]),
                most=MAX_DURATION,
            )
        )
    t = np.linspace(0.0, law.t_grid[-1], min(max(math.ceil(law.t_grid[-1] * rate) + 1, 2), MAX_CHECK))
    peak = float(np.max(np.abs(_state(params, path, law, t, arrangement)[-1]))) / limits.force
    return law.scaled(math.sqrt(peak)) if peak > 1.0 else law


def _state(
    params: Params, path: GeometricPath, law: _TimeLaw, t: np.ndarray, arrangement: Arrangement = _PAPER
) -> tuple:
    """``(s, ṡ, s̈, p, ṗ, p̈, τ)`` at local times ``t`` [s]: exact chain rule, closed-form ``τ`` (eqs. 29-31)."""
    s, ds, dds = law(t)
    ps, pss = path.evaluate(s, 1), path.evaluate(s, 2)
    p = path.evaluate(s)
    dp = ps * ds[..., None]
    ddp = ps * dds[..., None] + pss * (ds**2)[..., None]
    return s, ds, dds, p, dp, ddp, inverse_dynamics(arrangement, params, p, dp, ddp)


@dataclass(frozen=True)
class Plan:
    """A timed motion: one or more rest-to-rest moves back to back (e.g. the two strokes of a pick cycle).

    Use :meth:`sample` for the states at any times; ``duration`` [s] is the motion time (dwell not included),
    ``stretches`` the uniform time-scaling factor of each move after toppra (1 when no overshoot was found).
    """

    name: str
    params: Params
    limits: Limits
    paths: tuple[GeometricPath, ...]
    laws: tuple[_TimeLaw, ...] = field(repr=False)
    grid: int = DEFAULT_GRID
    arrangement: Arrangement = Arrangement.PERPENDICULAR

    @property
    def starts(self) -> np.ndarray:
        """Start time [s] of each move."""
        return np.concatenate([[0.0], np.cumsum([law.t_grid[-1] for law in self.laws])[:-1]])

    @property
    def duration(self) -> float:
        """Motion time [s] of all moves together."""
        return float(sum(law.t_grid[-1] for law in self.laws))

    @property
    def move_durations(self) -> tuple[float, ...]:
        """Duration [s] of each move."""
        return tuple(float(law.t_grid[-1]) for law in self.laws)

    @property
    def stretches(self) -> tuple[float, ...]:
        """How much each move was slowed after toppra to remove an overshoot between grid points (>= 1)."""
        return tuple(float(law.stretch) for law in self.laws)

    def sample(self, t: ArrayLike) -> PlanSamples:
        """The exact states at times ``t`` [s] ``(n,)`` (clipped to ``[0, duration]``); at a move boundary the
        later move is used."""
        t = np.asarray(t, dtype=float).ravel().clip(0.0, self.duration)  # the method: typed as an array
        starts = self.starts
        k = np.clip(np.searchsorted(starts, t, side="right") - 1, 0, len(self.laws) - 1)
        out = [np.empty(t.shape) for _ in range(3)] + [np.empty((*t.shape, 2)) for _ in range(4)]
        for j, (path, law) in enumerate(zip(self.paths, self.laws, strict=True)):
            sel = k == j
            state = _state(self.params, path, law, t[sel] - starts[j], self.arrangement)
            for arr, val in zip(out, state, strict=True):
                arr[sel] = val
        s, ds, dds, p, dp, ddp, tau = out
        dd = actuator_velocity(self.arrangement, self.params, p, dp)
        return PlanSamples(t, k, s, ds, dds, p, dp, ddp, tau, dd)

    def samples(self, rate: float = CHECK_RATE) -> PlanSamples:
        """The states at ``t = k / rate`` [s], plus the start and end of every move (exact times)."""
        checked = _limit(rate, T("the sample rate"), "Hz")
        rate = CHECK_RATE if checked is None else checked
        n = math.floor(self.duration * rate) + 1
        if n > MAX_SAMPLES:
            raise InputError(
                Phrase(
                    "{n} samples are too many: lower the sample rate (at most {most} samples)", n=n, most=MAX_SAMPLES
                )
            )
        marks = np.append(self.starts, self.duration)
        ticks = np.arange(n) / rate
        ticks = ticks[np.min(np.abs(ticks[:, None] - marks[None, :]), axis=1) > 1e-9 / rate]
        return self.sample(np.sort(np.concatenate([ticks, marks])))


@dataclass(frozen=True)
class PlanSamples:
    """Sampled states of a :class:`Plan`: ``t`` [s] ``(n,)``, ``move`` index ``(n,)``, path position ``s`` [m],
    speed ``ds`` [m/s], acceleration ``dds`` [m/s²]; ``p, dp, ddp`` ``(n, 2)`` [m, m/s, m/s²]; actuator forces
    ``tau`` ``(n, 2)`` [N] (eqs. 29-31) and actuator velocities ``dd`` ``(n, 2)`` [m/s] (eq. 9)."""

    t: np.ndarray
    move: np.ndarray
    s: np.ndarray
    ds: np.ndarray
    dds: np.ndarray
    p: np.ndarray
    dp: np.ndarray
    ddp: np.ndarray
    tau: np.ndarray
    dd: np.ndarray


def _check_grid(grid: object) -> int:
    if isinstance(grid, bool) or not isinstance(grid, (int, np.integer)) or not 10 <= grid <= MAX_GRID:
        raise InputError(
            Phrase(
                "the grid must be a whole number of points from 10 to {most}, got {got}", most=MAX_GRID, got=repr(grid)
            )
        )
    return int(grid)


def plan_path(
    params: Params,
    path: GeometricPath,
    limits: Limits,
    grid: int = DEFAULT_GRID,
    arrangement: Arrangement = Arrangement.PERPENDICULAR,
) -> Plan:
    """The time-optimal rest-to-rest motion along ``path`` within ``limits``.

    The path is first checked against the valid region (:func:`~tpm_viz.app.paths.check_path`). ``grid`` points
    are spread evenly in arc length (the path's junctions are added). Minimum time is bang-bang in the force
    limits: at almost every instant one actuator is at ``±F_max``. ``arrangement``: whose closed form (default the
    paper's perpendicular one).
    """
    grid = _check_grid(grid)
    check_path(params, path, arrangement=arrangement)
    law = _plan_one(params, path, limits, grid, CHECK_RATE, arrangement)
    return Plan(path.name, params, limits, (path,), (law,), grid, arrangement)


def plan_cycle(
    params: Params,
    path: GeometricPath,
    limits: Limits,
    grid: int = DEFAULT_GRID,
    arrangement: Arrangement = Arrangement.PERPENDICULAR,
) -> Plan:
    """There and back: ``path`` then :meth:`GeometricPath.reversed`, each rest-to-rest (a pick-and-place cycle).

    Both strokes are planned (without friction the back stroke is the forward one reversed in time, so both
    take the same time; the tests check it).
    """
    grid = _check_grid(grid)
    check_path(params, path, arrangement=arrangement)
    back = path.reversed()
    laws = tuple(_plan_one(params, pth, limits, grid, CHECK_RATE, arrangement) for pth in (path, back))
    return Plan(path.name, params, limits, (path, back), laws, grid, arrangement)
