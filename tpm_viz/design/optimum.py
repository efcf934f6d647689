"""The best design under constraints: a global search (differential evolution) polished by Nelder-Mead
(``docs/design.md``, *The optimiser*).

The free variables are named by ``bounds`` (``{name: (low, high)}``, SI): design parameters, and ``task_cx``,
``task_cy`` [m], where the task's centre stands in the machine's frame. The objective is the pick cycle time at the
force limit (:func:`tpm_viz.design.indices.evaluate`); a design that is infeasible or breaks the footprint
:class:`~tpm_viz.design.atlas.Limits` costs :data:`PENALTY` or more (:meth:`Problem.cost`).

- :func:`search`: :func:`scipy.optimize.differential_evolution` (seeded, strategy :data:`STRATEGY`, a
  Latin-hypercube start, each generation evaluated as one batch) on the variables scaled to ``[0, 1]``, then
  Nelder-Mead from its best; returns the full row of the better of the two. Every design is evaluated with the
  caller's settings (the same objective throughout: no coarse planner grid that could rank designs differently).
- :func:`optimise`: Nelder-Mead (:func:`scipy.optimize.minimize`) from a start, within the bounds (a local method:
  the polish, and what the atlas used alone before).
"""

from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np
from scipy import optimize

from tpm_viz.design.atlas import Limits, Row, design_row, task_columns
from tpm_viz.design.indices import Settings, Task
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["PENALTY", "STRATEGY", "Evaluate", "Problem", "Search", "optimise", "population", "search"]

PENALTY = 1e3
"""Objective [s] of a design that breaks a constraint."""

STRATEGY = "rand1bin"
"""Differential evolution's strategy: mutation around random members, not the best one (``best1bin``, SciPy's
default, tended to settle in a neighbouring basin of the paper's ``--hold link`` comparison)."""

Adjust = Callable[[dict[str, float]], dict[str, float]]
Evaluate = Callable[[Callable[[np.ndarray], float], Sequence[np.ndarray]], Sequence[float]]
"""``evaluate(cost, points)``: the costs of a batch of points, in order (a ``map``; the app runs the batches as
jobs of its fair worker). ``cost`` is the search's :meth:`Problem.cost` (a bound method: ``cost.__self__`` tells
one search from the next, :class:`~tpm_viz.design.tally.Tally`); a batch is a generation of differential evolution
(the population) or one design of the Nelder-Mead polish."""


def _in_turn(cost: Callable[[np.ndarray], float], points: Sequence[np.ndarray]) -> list[float]:
    """The default :data:`Evaluate`: in this thread, in order."""
    return [cost(x) for x in points]


@dataclass(frozen=True)
class Search:
    """How :func:`search` looks: differential evolution with ``population`` members per free variable for at most
    ``generations`` (stopping earlier when the members' cycle times agree to ``tol``, relative), seeded by
    ``seed``; then Nelder-Mead with at most ``polish`` designs."""

    seed: int = 0
    population: int = 15
    generations: int = 100
    tol: float = 1e-4
    polish: int = 120


def population(how: Search, free: int) -> int:
    """Members of the search's population with ``free`` variables: a batch of every generation (and of the first
    population), so a search evaluates at most ``(generations + 1) * population + polish`` designs."""
    return max(how.population * free, 5)


class Problem:
    """One optimisation problem: a point ``x`` of the unit cube is a design and a task placement; its row is
    computed once (cached by ``x``)."""

    def __init__(
        self,
        arrangement: Arrangement,
        base: dict[str, float],
        bounds: dict[str, tuple[float, float]],
        task: Task,
        settings: Settings,
        limits: Limits = Limits(),
        adjust: Adjust | None = None,
    ) -> None:
        self.arrangement, self.base, self.task, self.settings = arrangement, base, task, settings
        self.limits, self.adjust, self.names = limits, adjust, list(bounds)
        self.lo = np.array([bounds[n][0] for n in self.names], dtype=float)
        span = np.array([bounds[n][1] - bounds[n][0] for n in self.names], dtype=float)
        self.span = np.where(span > 0, span, 1.0)
        self.found: dict[tuple, Row] = {}

    def scaled(self, values: dict[str, float]) -> np.ndarray:
        """The unit-cube point of ``values`` (SI)."""
        return (np.array([values[n] for n in self.names]) - self.lo) / self.span

    def row(self, x: np.ndarray, cycle_only: bool = True) -> Row:
        """The row of ``x`` (clipped to the cube): the design's parameters, indices and task columns."""
        x = np.clip(np.asarray(x, dtype=float), 0.0, 1.0)
        key = (cycle_only, *np.round(x, 12).tolist())
        if key not in self.found:
            values = dict(zip(self.names, (self.lo + x * self.span).tolist(), strict=True))
            centre = self.task.centre
            moved = self.task.centred_at(values.pop("task_cx", centre[0]), values.pop("task_cy", centre[1]))
            merged = {**self.base, **values}
            merged = self.adjust(merged) if self.adjust is not None else merged
            box = (moved.x0, moved.x1, moved.y0, moved.y1)
            row = design_row(self.arrangement.value, merged, {}, box, self.settings, cycle_only)
            row.update(task_columns(moved))
            self.found[key] = row
        return self.found[key]

    def cost(self, x: np.ndarray) -> float:
        """The cycle time [s] of ``x``; :data:`PENALTY` times 1 to 2 for a feasible design over the footprint
        limits (by how much), 2 to 3 for an infeasible one (by its ``shortfall``): graded, so that a search whose
        first designs are all infeasible still has a way to go."""
        row = self.row(x)
        if self.limits.allows(row):
            return float(row["cycle_time"])
        if row["feasible"]:
            return PENALTY * (1.0 + self.limits.excess(row))
        return PENALTY * (2.0 + min(max(float(row.get("shortfall", 1.0)), 0.0), 1.0))


def _nelder_mead(problem: Problem, x0: np.ndarray, evaluations: int, evaluate: Evaluate = _in_turn) -> np.ndarray:
    """Nelder-Mead from ``x0`` within the unit cube, each design through ``evaluate``; the better of its end and
    ``x0``."""
    result = optimize.minimize(
        lambda x: float(evaluate(problem.cost, [x])[0]),
        x0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * len(x0),
        options={"maxfev": int(evaluations), "xatol": 1e-4, "fatol": 1e-5, "initial_simplex": _simplex(x0)},
    )
    return np.asarray(result.x) if problem.cost(result.x) <= problem.cost(x0) else x0


def optimise(
    arrangement: Arrangement,
    base: dict[str, float],
    start: dict[str, float],
    bounds: dict[str, tuple[float, float]],
    task: Task,
    settings: Settings = Settings(),
    limits: Limits = Limits(),
    max_evaluations: int = 120,
    adjust: Adjust | None = None,
) -> Row:
    """The design with the shortest pick cycle near ``start`` (values of the names in ``bounds``, SI): Nelder-Mead
    on the variables scaled to ``[0, 1]``, at most ``max_evaluations`` designs, a constraint broken costing
    :data:`PENALTY`; ``adjust`` maps a candidate's parameters to the design's (e.g. link mass with its length).
    Returns the full row of the best design found, with the task's columns (the start's if nothing is better)."""
    problem = Problem(arrangement, base, bounds, task, settings, limits, adjust)
    best = _nelder_mead(problem, problem.scaled(start), max_evaluations)
    return problem.row(best, cycle_only=False)


def search(
    arrangement: Arrangement,
    base: dict[str, float],
    bounds: dict[str, tuple[float, float]],
    task: Task,
    settings: Settings = Settings(),
    limits: Limits = Limits(),
    adjust: Adjust | None = None,
    how: Search = Search(),
    starts: Sequence[dict[str, float]] = (),
    evaluate: Evaluate | None = None,
) -> Row | None:
    """The design with the shortest pick cycle within ``bounds`` and ``limits`` (see the module docstring), or None
    when no design the search met is feasible. ``starts``: known designs (values of the names in ``bounds``) put in
    the first population (e.g. the best point of an atlas's grid); ``evaluate``: how a batch of designs is
    evaluated (the results do not depend on it)."""
    evaluate = _in_turn if evaluate is None else evaluate
    problem = Problem(arrangement, base, bounds, task, settings, limits, adjust)
    k = len(problem.names)
    size = population(how, k)
    init: str | np.ndarray = "latinhypercube"
    if starts:
        rng = np.random.default_rng(how.seed)
        known = np.clip([problem.scaled(s) for s in starts][:size], 0.0, 1.0)
        init = np.concatenate([known, _latin(rng, size - len(known), k)])
    result = optimize.differential_evolution(
        problem.cost,
        [(0.0, 1.0)] * k,
        strategy=STRATEGY,
        maxiter=how.generations,
        popsize=how.population,
        tol=how.tol,
        seed=how.seed,
        init=init,
        polish=False,
        updating="deferred",
        workers=lambda _, points: evaluate(problem.cost, list(points)),  # SciPy's wrapper of it calls it as it is
    )
    if not problem.limits.allows(problem.row(result.x)):
        return None
    best = _nelder_mead(problem, np.asarray(result.x), how.polish, evaluate)
    return problem.row(best, cycle_only=False)


def _latin(rng: np.random.Generator, n: int, k: int) -> np.ndarray:
    """``n`` Latin-hypercube points of the unit cube ``(n, k)``."""
    if n <= 0:
        return np.zeros((0, k))
    cells = np.stack([rng.permutation(n) for _ in range(k)], axis=1)
    return (cells + rng.random((n, k))) / n


def _simplex(x0: np.ndarray, step: float = 0.1) -> np.ndarray:
    """A start simplex of edges ``step`` (of the scaled range) inside ``[0, 1]``."""
    pts = [x0]
    for k in range(len(x0)):
        e = x0.copy()
        e[k] = x0[k] + step if x0[k] + step <= 1.0 else x0[k] - step
        pts.append(e)
    return np.array(pts)
