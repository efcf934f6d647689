"""The paper's claim put to a test: the perpendicular and the parallel 2-PPa compared, holding one thing equal
(``docs/design.md``).

Both arrangements get the same task rectangle (its size; each machine stands where the task is centred on its
own home pose, :func:`tpm_viz.paper.arrangement.home`), the same platform offset ``b`` and masses, and:

- :attr:`Hold.LINK`: the same link length ``l_a``;
- :attr:`Hold.FOOTPRINT`: a footprint within the perpendicular design's (width and depth);
- :attr:`Hold.MASS`: a moving mass at most the given design's, the links' mass following their length (the
  given ``m_b / l_a`` per metre).

Rows: each arrangement at the given dimensions (``case = given``), then at its own optimum (``case = optimum``):
the shortest cycle of the standard pick at the force limit over ``a``, the stroke, ``l_a`` (unless held) and where
the machine stands, found by differential evolution polished by Nelder-Mead (:func:`tpm_viz.design.optimum.search`,
the given design in its first population).
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import T
from tpm_viz.design.atlas import PARAMETER_COLUMNS, Limits, Row, design_row, task_columns, values_of
from tpm_viz.design.indices import INDEX_COLUMNS, Settings, Task
from tpm_viz.design.optimum import Evaluate, Search, population, search
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

__all__ = ["COMPARE_COLUMNS", "NONE_FOUND", "Hold", "compare", "populations"]

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
NONE_FOUND = T("no design found within the limits")
"""Why an arrangement has no optimum: no design the search met is feasible within the hold."""


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


@dataclass(frozen=True)
class _LinkMass:
    """Link mass following link length at ``density`` [kg/m] (picklable, unlike a closure)."""

    density: float

    def __call__(self, values: dict[str, float]) -> dict[str, float]:
        return {**values, "m_b": self.density * values["l_a"]}


def populations(params: Params, hold: Hold, how: Search = Search()) -> list[int]:
    """The population of each of :func:`compare`'s searches, in order (perpendicular, parallel): what
    :class:`~tpm_viz.design.tally.Tally` counts with."""
    return [population(how, len(_bounds(a, params, hold))) for a in Arrangement]


def compare(
    params: Params,
    task: Task,
    hold: Hold,
    settings: Settings = Settings(),
    how: Search = Search(),
    evaluate: Evaluate | None = None,
) -> list[Row]:
    """Four rows: each arrangement at ``params`` (task centred on its home), then each at its own optimum under
    ``hold`` (see the module docstring; ``how``: the search's seed and budget; ``evaluate``: how its batches of
    designs run, :func:`tpm_viz.design.optimum.search`). Every row is evaluated with ``settings``; an arrangement
    with no feasible design within the hold has a row with ``feasible`` 0."""
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
    adjust = _LinkMass(params.m_b / params.l_a) if hold is Hold.MASS else None
    base = values_of(params)
    rows = list(given)
    for arrangement, start in zip(Arrangement, given, strict=True):
        bounds = _bounds(arrangement, params, hold)
        known = {name: float(start[name]) for name in bounds if name in start}
        centre = (start["task_x0"] + start["task_x1"]) / 2, (start["task_y0"] + start["task_y1"]) / 2
        known.update(task_cx=float(centre[0]), task_cy=float(centre[1]))
        found = search(arrangement, base, bounds, task, settings, limits, adjust, how, [known], evaluate)
        row = found if found is not None else {"arrangement": arrangement.value, "feasible": 0.0, "why": NONE_FOUND}
        row["case"] = "optimum"
        rows.append(row)
    return rows
