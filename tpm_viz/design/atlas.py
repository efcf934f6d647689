"""The atlas of designs: a grid over ``a, b, l_a, Δd`` (and the masses), every design's indices, the Pareto front,
and the best design under constraints by a real optimiser (``docs/design.md``).

- :class:`Vary`: ``NAME=START:STOP:COUNT`` (COUNT evenly spaced values, both ends included, SI units);
- :func:`designs`: the grid's parameter overrides, in row-major order of the ``--vary`` options;
- :func:`design_row` evaluates one design (a plain function of plain data: it runs in a process pool or on a
  Dask worker alike); :func:`sweep` runs a grid on a process pool with a progress callback;
- :func:`pareto`: the non-dominated feasible rows (GCI up, cycle time down, footprint area down);
- :func:`best`: the fastest cycle among the rows within the footprint limits, then :func:`optimise`:
  Nelder-Mead (:func:`scipy.optimize.minimize`) over the varied parameters within the grid's ranges, started there.
"""

from __future__ import annotations

import itertools
import math
import os
from collections.abc import Callable, Iterable, Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from typing import Any

import numpy as np
from scipy.optimize import minimize

from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.design.indices import INDEX_COLUMNS, Indices, Settings, Task, evaluate, reason
from tpm_viz.paper.arrangement import Arrangement

__all__ = [
    "MAX_DESIGNS",
    "PARAMETER_COLUMNS",
    "VARIABLE",
    "Limits",
    "Row",
    "Vary",
    "best",
    "chunks",
    "columns_for",
    "design_row",
    "designs",
    "optimise",
    "pareto",
    "run_chunk",
    "sweep",
    "task_columns",
    "values_of",
]

Row = dict[str, Any]
"""One design's row: parameter and index values by column name (SI), ``why`` for an infeasible one."""

PARAMETER_COLUMNS = ("arrangement", "a", "b", "l_a", "stroke")
"""The parameter columns of every row (then the masses that vary, then
:data:`~tpm_viz.design.indices.INDEX_COLUMNS`)."""
VARIABLE = ("a", "b", "l_a", "stroke", "m_a", "m_b", "m_p")
"""Parameters an atlas may vary."""
MASSES = ("m_a", "m_b", "m_p")
MAX_DESIGNS = 1_000_000
"""Largest grid."""
MAX_COUNT = 10_000
"""Most values of one parameter."""


@dataclass(frozen=True)
class Vary:
    """``count`` evenly spaced values of parameter ``name`` from ``start`` to ``stop`` inclusive (SI)."""

    name: str
    start: float
    stop: float
    count: int

    @classmethod
    def parse(cls, text: str) -> Vary:
        """``NAME=START:STOP:COUNT``."""
        name, sep, rest = str(text).partition("=")
        name = name.strip()
        if not sep or name not in VARIABLE:
            raise InputError(
                "--vary expects NAME=START:STOP:COUNT with NAME one of {names}".format(names=", ".join(VARIABLE))
            )
        parts = rest.split(":")
        try:
            start, stop = float(parts[0]), float(parts[1])
            count = int(parts[2])
            if len(parts) != 3:
                raise ValueError
        except (ValueError, IndexError):
            raise InputError(
                f"--vary {name}: expected START:STOP:COUNT (two numbers in SI units and a whole count)"
            ) from None
        if not (math.isfinite(start) and math.isfinite(stop) and 1 <= count <= MAX_COUNT):
            raise InputError(f"--vary {name}: START and STOP must be finite and COUNT from 1 to {MAX_COUNT}")
        return cls(name, start, stop, count)

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.count)


def designs(varies: Sequence[Vary]) -> list[dict[str, float]]:
    """The grid: one ``{name: value}`` per design, the last ``--vary`` changing fastest."""
    names = [v.name for v in varies]
    if len(set(names)) != len(names):
        raise InputError("each parameter may be varied once, got {names}".format(names=", ".join(names)))
    total = math.prod(v.count for v in varies)
    if total > MAX_DESIGNS:
        raise InputError(f"{total} designs are too many (at most {MAX_DESIGNS}): lower the counts")
    return [
        dict(zip(names, map(float, combo), strict=True)) for combo in itertools.product(*(v.values for v in varies))
    ]


def columns_for(varies: Iterable[str] = ()) -> list[str]:
    """The CSV columns of an atlas whose varied parameters are ``varies`` (varied masses after the lengths)."""
    masses = [m for m in MASSES if m in set(varies)]
    return [*PARAMETER_COLUMNS, *masses, *INDEX_COLUMNS]


def design_row(
    arrangement: str, base: dict[str, float], overrides: dict[str, float], task: tuple, settings: Settings
) -> Row:
    """One row: the parameters (``base`` updated by ``overrides``, SI) and the indices over ``task``
    (``(x0, x1, y0, y1)`` [m]). A parameter set that is not valid is an infeasible row."""
    values = {**base, **overrides}
    row: Row = {"arrangement": Arrangement.parse(arrangement).value, **values}
    try:
        indices = evaluate(Arrangement.parse(arrangement), Params(**values), Task(*task), settings)
    except TpmVizError as exc:  # a parameter set that is not valid, an area mean that does not converge
        indices = Indices(False, why=reason(exc))
    row.update(indices.row())
    row["why"] = indices.why
    return row


def run_chunk(job: tuple) -> list[Row]:
    """The rows of one chunk ``(arrangement, base, [overrides, ...], task, settings)`` (what a worker runs)."""
    arrangement, base, chunk, task, settings = job
    return [design_row(arrangement, base, overrides, task, settings) for overrides in chunk]


def chunks(items: Sequence, size: int) -> list[Sequence]:
    """``items`` cut into consecutive pieces of ``size`` (the last may be shorter)."""
    return [items[k : k + size] for k in range(0, len(items), size)]


def sweep(
    arrangement: Arrangement,
    base: Params,
    grid: Sequence[dict[str, float]],
    task: Task,
    settings: Settings = Settings(),
    workers: int | None = None,
    progress: Callable[[int, int], None] | None = None,
    chunk: int = 8,
) -> list[Row]:
    """Every design of ``grid`` (overrides of ``base``), in order, on ``workers`` processes (default: every core;
    1: in this process). ``progress(done, total)`` is called as chunks finish."""
    base_values = values_of(base)
    key = (task.x0, task.x1, task.y0, task.y1)
    jobs = [(Arrangement.parse(arrangement).value, base_values, list(c), key, settings) for c in chunks(grid, chunk)]
    workers = (os.cpu_count() or 1) if workers is None else int(workers)
    out: list[list[Row]] = []
    done = 0
    if workers <= 1:
        results: Iterable[list[Row]] = map(run_chunk, jobs)
        for rows in results:
            out.append(rows)
            done += len(rows)
            if progress is not None:
                progress(done, len(grid))
        return [row for rows in out for row in rows]
    with ProcessPoolExecutor(max_workers=workers) as pool:
        for rows in pool.map(run_chunk, jobs):
            out.append(rows)
            done += len(rows)
            if progress is not None:
                progress(done, len(grid))
    return [row for rows in out for row in rows]


def values_of(params: Params) -> dict[str, float]:
    """Every field of ``params`` as a plain ``{name: value}`` (SI), for a worker."""
    return {
        name: float(getattr(params, name)) for name in ("a", "b", "l_a", "m_a", "m_b", "m_p", "stroke", "pivot_spacing")
    }


def pareto(rows: Sequence[Row]) -> np.ndarray:
    """Whether each row is on the Pareto front of the feasible rows: no other feasible row has a GCI at least as
    high, a cycle time and a footprint area (``footprint_x * footprint_y``) at least as low, and one of them strictly
    better."""
    feasible = np.array([bool(r["feasible"]) for r in rows], dtype=bool)
    keys = np.array(
        [[-float(r["gci"]), float(r["cycle_time"]), float(r["footprint_x"]) * float(r["footprint_y"])] for r in rows]
    ).reshape(-1, 3)
    front = np.zeros(len(rows), dtype=bool)
    idx = np.flatnonzero(feasible)
    pts = keys[idx]
    for k, point in zip(idx, pts, strict=True):
        dominated = np.any(np.all(pts <= point, axis=1) & np.any(pts < point, axis=1))
        front[k] = not dominated
    return front


@dataclass(frozen=True)
class Limits:
    """Constraints of the best design: footprint width and depth [m] (None: free)."""

    footprint_x: float | None = None
    footprint_y: float | None = None

    def allows(self, row: Row) -> bool:
        if not row["feasible"]:
            return False
        fx, fy = float(row["footprint_x"]), float(row["footprint_y"])
        return (self.footprint_x is None or fx <= self.footprint_x) and (
            self.footprint_y is None or fy <= self.footprint_y
        )


def best(rows: Sequence[Row], limits: Limits = Limits()) -> int | None:
    """Index of the fastest cycle among the feasible rows within ``limits`` (None if there is none)."""
    ok = [k for k, row in enumerate(rows) if limits.allows(row)]
    return min(ok, key=lambda k: float(rows[k]["cycle_time"])) if ok else None


PENALTY = 1e3
"""Objective [s] of a design that breaks a constraint (Nelder-Mead moves away from it)."""


def optimise(
    arrangement: Arrangement,
    base: dict[str, float],
    start: dict[str, float],
    bounds: dict[str, tuple[float, float]],
    task: Task,
    settings: Settings = Settings(),
    limits: Limits = Limits(),
    max_evaluations: int = 120,
    adjust: Callable[[dict[str, float]], dict[str, float]] | None = None,
) -> Row:
    """The design with the shortest pick cycle near ``start`` (values of the names in ``bounds``, SI): Nelder-Mead on
    the parameters scaled to ``[0, 1]`` by ``bounds``, at most ``max_evaluations`` designs, a constraint broken
    costing :data:`PENALTY`. The names ``task_cx``, ``task_cy`` [m] move the task's centre (where the machine
    stands relative to the work). ``adjust`` maps a candidate's parameter values to the design's (e.g. link mass
    with its length). Returns the best row found, with the task's columns (the start's row if nothing is
    better)."""
    names = list(bounds)
    lo = np.array([bounds[n][0] for n in names])
    span = np.array([bounds[n][1] - bounds[n][0] for n in names])
    span = np.where(span > 0, span, 1.0)
    found: dict[tuple, Row] = {}

    def row_at(x: np.ndarray) -> Row:
        values = dict(zip(names, (lo + np.clip(x, 0.0, 1.0) * span).tolist(), strict=True))
        key = tuple(np.round(x, 12))
        if key not in found:
            centre = task.centre
            moved = task.centred_at(values.pop("task_cx", centre[0]), values.pop("task_cy", centre[1]))
            merged = {**base, **values}
            merged = adjust(merged) if adjust is not None else merged
            found[key] = design_row(arrangement.value, merged, {}, (moved.x0, moved.x1, moved.y0, moved.y1), settings)
            found[key].update(task_columns(moved))
        return found[key]

    def cost(x: np.ndarray) -> float:
        row = row_at(x)
        if not limits.allows(row):
            return PENALTY
        return float(row["cycle_time"])

    x0 = (np.array([start[n] for n in names]) - lo) / span
    result = minimize(
        cost,
        x0,
        method="Nelder-Mead",
        bounds=[(0.0, 1.0)] * len(names),
        options={"maxfev": int(max_evaluations), "xatol": 1e-4, "fatol": 1e-5, "initial_simplex": _simplex(x0)},
    )
    winner = row_at(result.x)
    origin = row_at(x0)
    return winner if cost(result.x) <= cost(x0) else origin


def task_columns(task: Task) -> dict[str, float]:
    """``task_x0, task_x1, task_y0, task_y1`` [m] of a row."""
    return {"task_x0": task.x0, "task_x1": task.x1, "task_y0": task.y0, "task_y1": task.y1}


def _simplex(x0: np.ndarray, step: float = 0.1) -> np.ndarray:
    """A start simplex of edges ``step`` (of the scaled range) inside ``[0, 1]``."""
    pts = [x0]
    for k in range(len(x0)):
        e = x0.copy()
        e[k] = x0[k] + step if x0[k] + step <= 1.0 else x0[k] - step
        pts.append(e)
    return np.array(pts)
