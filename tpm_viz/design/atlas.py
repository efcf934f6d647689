"""The atlas of designs: a grid over ``a, b, l_a, Δd`` (and the masses), every design's indices, the Pareto front,
and the best design under constraints by a real optimiser (``docs/design.md``).

- :class:`Vary`: ``NAME=START:STOP:COUNT`` (COUNT evenly spaced values, both ends included, SI units);
- :func:`designs`: the grid's parameter overrides, in row-major order of the ``--vary`` options;
- :func:`design_row` evaluates one design (a plain function of plain data: it runs in a process pool or on a
  Dask worker alike); :func:`sweep` runs a grid on a process pool with a progress callback;
- :func:`pareto`: the non-dominated feasible rows (GCI up, cycle time down, footprint area down);
- :func:`best`: the fastest cycle among the rows within the footprint limits (the optimiser, which improves on it,
  is :mod:`tpm_viz.design.optimum`).
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
    "pareto",
    "pool_size",
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
    arrangement: str,
    base: dict[str, float],
    overrides: dict[str, float],
    task: tuple,
    settings: Settings,
    cycle_only: bool = False,
) -> Row:
    """One row: the parameters (``base`` updated by ``overrides``, SI) and the indices over ``task``
    (``(x0, x1, y0, y1)`` [m]; ``cycle_only`` as in :func:`~tpm_viz.design.indices.evaluate`). A parameter set that
    is not valid is an infeasible row."""
    values = {**base, **overrides}
    row: Row = {"arrangement": Arrangement.parse(arrangement).value, **values}
    try:
        indices = evaluate(Arrangement.parse(arrangement), Params(**values), Task(*task), settings, cycle_only)
    except TpmVizError as exc:  # a parameter set that is not valid, an area mean that does not converge
        indices = Indices(False, why=reason(exc), shortfall=1.0)
    row.update(indices.row())
    row["why"], row["shortfall"] = indices.why, indices.shortfall
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
    """Every design of ``grid`` (overrides of ``base``), in order, on :func:`pool_size` processes (default: every
    core; never more than the chunks of ``chunk`` designs or the cores; 1: in this process). ``progress(done,
    total)`` is called as chunks finish."""
    base_values = values_of(base)
    key = (task.x0, task.x1, task.y0, task.y1)
    jobs = [(Arrangement.parse(arrangement).value, base_values, list(c), key, settings) for c in chunks(grid, chunk)]
    workers = pool_size(workers, len(jobs))
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


def cores() -> int:
    """The cores this process may run on (its CPU affinity where the system has one)."""
    try:
        return max(len(os.sched_getaffinity(0)), 1)
    except AttributeError:  # not on Linux
        return os.cpu_count() or 1


def pool_size(workers: int | None, jobs: int) -> int:
    """Processes for ``jobs`` chunks: ``workers`` (default: every core), at most one per chunk and per core."""
    wanted = cores() if workers is None else int(workers)
    return max(1, min(wanted, jobs, cores()))


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

    def excess(self, row: Row) -> float:
        """How far a feasible row's footprint exceeds the limits: the larger relative excess, at most 1."""
        out = 0.0
        for limit, key in ((self.footprint_x, "footprint_x"), (self.footprint_y, "footprint_y")):
            if limit is not None:
                out = max(out, float(row[key]) / limit - 1.0)
        return min(out, 1.0)

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


def task_columns(task: Task) -> dict[str, float]:
    """``task_x0, task_x1, task_y0, task_y1`` [m] of a row."""
    return {"task_x0": task.x0, "task_x1": task.x1, "task_y0": task.y0, "task_y1": task.y1}
