"""The paper's claim put to a test: the perpendicular and the parallel 2-PPa compared, holding one thing equal
(``docs/design.md``).

Both arrangements get the same task rectangle (its size; each machine stands where the task is centred on its
own home pose, :func:`tpm_viz.paper.arrangement.home`), the same platform offset ``b`` and masses, and:

- :attr:`Hold.LINK`: the same link length ``l_a``;
- :attr:`Hold.FOOTPRINT`: a footprint within the perpendicular design's (width and depth);
- :attr:`Hold.MASS`: a moving mass at most the given design's, the links' mass following their length (the
  given ``m_b / l_a`` per metre).

Rows: each arrangement at the given dimensions (``case = given``), then at its own optimum (``case = optimum``):
the shortest cycle of the standard pick at the force limit found by Nelder-Mead over ``a``, the stroke, ``l_a``
(unless held) and where the machine stands, started from the best point of a small grid (:data:`SEARCH_GRID`)
(:func:`tpm_viz.design.atlas.optimise`).
"""

from __future__ import annotations

import enum
import itertools
from collections.abc import Callable
from dataclasses import replace

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.design.atlas import PARAMETER_COLUMNS, Limits, Row, design_row, optimise, task_columns, values_of
from tpm_viz.design.indices import INDEX_COLUMNS, Settings, Task
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["COMPARE_COLUMNS", "Hold", "compare"]

COMPARE_COLUMNS = (
    "case",
    *PARAMETER_COLUMNS,
    "m_b",
    *INDEX_COLUMNS,
    "task_x0",
    "task_x1",
    "task_y0",
    "task_y1",
)
"""Columns of ``tpm-viz compare`` (SI units)."""
SEARCH_GRID = (3, 5)
"""Values per free variable of the start grid of each optimum (``3^k`` designs; ``5^k`` when none of those is
feasible within the limits)."""


class Hold(enum.Enum):
    """What the comparison holds equal (``value``: the command-line word)."""

    LINK = "link"
    FOOTPRINT = "footprint"
    MASS = "mass"

    @classmethod
    def parse(cls, text: object) -> Hold:
        for hold in cls:
            if str(text).strip().lower() == hold.value:
                return hold
        raise InputError(f"--hold must be link, footprint or mass, got {str(text)[:40]!r}")


def _given(arrangement: Arrangement, params: Params, task: Task, settings: Settings) -> Row:
    home = arr.home(arrangement, params)
    placed = task.centred_at(float(home[0]), float(home[1]))
    row = design_row(arrangement.value, values_of(params), {}, (placed.x0, placed.x1, placed.y0, placed.y1), settings)
    row.update(task_columns(placed))
    return row


def _bounds(arrangement: Arrangement, params: Params, hold: Hold) -> dict[str, tuple[float, float]]:
    """The free variables and their ranges: ``a`` and the stroke from half to 1.5 times the given, ``l_a`` the same
    (at most the given when the mass is held; fixed when the link is held), the task's centre within ``l_a / 2`` of
    the arrangement's home pose."""
    out = {
        "a": (max(0.5 * params.a, params.b + 1e-3), 1.5 * params.a),
        "stroke": (0.5 * params.stroke, 1.5 * params.stroke),
    }
    if hold is Hold.FOOTPRINT:
        out["l_a"] = (0.5 * params.l_a, 1.5 * params.l_a)
    elif hold is Hold.MASS:
        out["l_a"] = (0.5 * params.l_a, params.l_a)
    home = arr.home(arrangement, params)
    out["task_cx"] = (float(home[0]) - params.l_a / 2, float(home[0]) + params.l_a / 2)
    out["task_cy"] = (float(home[1]) - params.l_a / 2, float(home[1]) + params.l_a / 2)
    return out


def _start(
    arrangement: Arrangement,
    base: dict[str, float],
    bounds: dict[str, tuple[float, float]],
    task: Task,
    settings: Settings,
    limits: Limits,
    adjust: Callable[[dict[str, float]], dict[str, float]],
    count: int,
) -> dict[str, float] | None:
    """The fastest feasible point of a ``count``-per-variable grid over ``bounds`` (None if none)."""
    best: tuple[float, dict[str, float]] | None = None
    axes = [np.linspace(lo, hi, count) for lo, hi in bounds.values()]
    for combo in itertools.product(*axes):
        values = dict(zip(bounds, map(float, combo), strict=True))
        moved = task.centred_at(values.pop("task_cx"), values.pop("task_cy"))
        merged = adjust({**base, **values})
        row = design_row(arrangement.value, merged, {}, (moved.x0, moved.x1, moved.y0, moved.y1), settings)
        if limits.allows(row) and (best is None or float(row["cycle_time"]) < best[0]):
            best = (float(row["cycle_time"]), dict(zip(bounds, map(float, combo), strict=True)))
    return None if best is None else best[1]


def compare(
    params: Params, task: Task, hold: Hold, settings: Settings = Settings(), max_evaluations: int = 80
) -> list[Row]:
    """Four rows: each arrangement at ``params`` (task centred on its home), then each at its own optimum under
    ``hold`` (see the module docstring). The search runs with a 100-point planner grid; every reported row is
    evaluated with ``settings``."""
    given = [_given(a, params, task, settings) for a in Arrangement]
    for row in given:
        row["case"] = "given"
    limits = Limits()
    if hold is Hold.FOOTPRINT:
        ref = given[0]
        if not ref["feasible"]:
            raise InputError(
                "--hold footprint needs the perpendicular design to cover the task at the given dimensions"
            )
        limits = Limits(float(ref["footprint_x"]), float(ref["footprint_y"]))
    density = params.m_b / params.l_a

    def adjust(values: dict[str, float]) -> dict[str, float]:
        return {**values, "m_b": density * values["l_a"]} if hold is Hold.MASS else values

    search = replace(settings, planner_grid=min(settings.planner_grid, 100))
    base = values_of(params)
    rows = list(given)
    for arrangement in Arrangement:
        bounds = _bounds(arrangement, params, hold)
        for count in SEARCH_GRID:
            start = _start(arrangement, base, bounds, task, search, limits, adjust, count)
            if start is not None:
                break
        if start is None:
            row = {"arrangement": arrangement.value, "feasible": 0.0}
        else:
            found = optimise(arrangement, base, start, bounds, task, search, limits, max_evaluations, adjust)
            placed = Task(*(float(found[k]) for k in ("task_x0", "task_x1", "task_y0", "task_y1")))
            values = {k: float(found[k]) for k in base}
            row = design_row(arrangement.value, values, {}, (placed.x0, placed.x1, placed.y0, placed.y1), settings)
            row.update(task_columns(placed))
        row["case"] = "optimum"
        rows.append(row)
    return rows
