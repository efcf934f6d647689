"""The *Design* view's atlas as a heat map, without viser: which designs, their rows, the colours of the cells.

A :class:`MapSpec` is one arrangement, one task (:class:`~tpm_viz.design.indices.Task`, m), the tab's mechanism as the
base design, and two of the lengths ``a, b, l_a, Δd`` swept over :class:`Axis` ranges (at most :data:`MAX_COUNT`
values each). Cell ``(column i, row j)`` is design ``k = j * nx + i`` (``x`` across, ``y`` up), evaluated by
:func:`tpm_viz.design.atlas.design_row` (:func:`tpm_viz.design.indices.evaluate`, every index, cycle time included:
about 30-50 ms a design). :func:`values` is one index per cell, NaN where the design is infeasible (drawn grey, shown as
"infeasible", never as a number); :func:`best_cell` the best feasible cell of that index; :func:`prototype_at` where the
paper's prototype (Tables 1-2) lies on the map, in cell units.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Phrase
from tpm_viz.design.atlas import Row, design_row, values_of
from tpm_viz.design.indices import Settings, Task
from tpm_viz.paper.arrangement import Arrangement

__all__ = [
    "CHUNK",
    "INDICES",
    "INFEASIBLE_COLOUR",
    "MAX_COUNT",
    "SWEPT",
    "Axis",
    "IndexInfo",
    "MapSpec",
    "best_cell",
    "colours",
    "prototype_at",
    "ramp",
    "values",
]

MAX_COUNT = 15
"""Most values of one swept parameter (15 x 15 = 225 designs, about 10 s of the tab's turns in the worker)."""
CHUNK = 8
"""Designs per job of the fair worker (about 0.3 s: other tabs' jobs run between two chunks)."""
SWEPT = {"a": "a", "b": "b", "l_a": "l_a", "stroke": "Δd"}
"""The lengths a map may sweep (mm in the panel), with their symbols in texts and in the scene."""
INFEASIBLE_COLOUR = (148, 163, 184)
"""Grey: a design that does not cover the task (or is not a valid geometry)."""
_RAMP = np.array([[68, 1, 84], [59, 82, 139], [33, 145, 140], [94, 201, 98], [253, 231, 37]], dtype=float)
"""viridis at 0, 1/4, 1/2, 3/4, 1: dark is worse, yellow better (readable in grey print and by most colour-blind
viewers)."""


@dataclass(frozen=True)
class IndexInfo:
    """One index of the map: its label (unit in it), format, display scale and whether higher is better."""

    label: str
    fmt: str
    higher_better: bool = False
    scale: float = 1.0


INDICES = {
    "gci": IndexInfo("GCI (mean 1/cond J)", ".3f", True),
    "cond_max": IndexInfo("worst cond J", ".2f"),
    "dyn_mean": IndexInfo("dynamic index, mean (kg)", ".2f"),
    "dyn_max": IndexInfo("dynamic index, max (kg)", ".2f"),
    "peak_force": IndexInfo("peak force (N)", ".0f"),
    "cycle_time": IndexInfo("cycle time (s)", ".3f"),
    "footprint": IndexInfo("footprint area (m²)", ".3f"),
}
"""The indices a map is coloured by (``footprint``: ``footprint_x * footprint_y``)."""


@dataclass(frozen=True)
class Axis:
    """``count`` evenly spaced values of parameter ``name`` from ``start`` to ``stop`` [m], both included."""

    name: str
    start: float
    stop: float
    count: int

    def __post_init__(self) -> None:
        if self.name not in SWEPT:
            raise InputError(Phrase("a map sweeps a, b, l_a or stroke, not {name}", name=self.name))
        if not (1 <= self.count <= MAX_COUNT and self.count == int(self.count)):
            raise InputError(Phrase("a count is a whole number from 1 to {most}", most=MAX_COUNT))
        if not (math.isfinite(self.start) and math.isfinite(self.stop) and 0 < self.start and 0 < self.stop):
            raise InputError(Phrase("{name}: the range must be positive lengths", name=SWEPT[self.name]))
        if self.count > 1 and not self.start < self.stop:
            raise InputError(Phrase("{name}: type a range from a smaller to a larger value", name=SWEPT[self.name]))

    @property
    def values(self) -> np.ndarray:
        return np.linspace(self.start, self.stop, self.count)

    def at(self, value: float) -> float:
        """Where ``value`` [m] lies along the axis, in cells (0 = first value; fractional between two)."""
        if self.count == 1:
            return 0.0 if math.isclose(value, self.start, rel_tol=1e-9) else math.inf
        return (value - self.start) / (self.stop - self.start) * (self.count - 1)


@dataclass(frozen=True)
class MapSpec:
    """One map: ``arrangement``, ``base`` design (the tab's mechanism), ``task``, the two axes."""

    arrangement: Arrangement
    base: Params
    task: Task
    x: Axis
    y: Axis
    settings: Settings = field(default_factory=Settings)

    def __post_init__(self) -> None:
        if self.x.name == self.y.name:
            raise InputError(
                Phrase("choose two different parameters to sweep (both are {name})", name=SWEPT[self.x.name])
            )

    @property
    def size(self) -> int:
        return self.x.count * self.y.count

    def cell(self, k: int) -> tuple[int, int]:
        """``(column, row)`` of design ``k`` (0-based)."""
        return k % self.x.count, k // self.x.count

    def index_of(self, column: int, row: int) -> int:
        """Design number of ``(column, row)`` (0-based)."""
        return row * self.x.count + column

    def overrides(self, k: int) -> dict[str, float]:
        """The swept values [m] of design ``k``."""
        i, j = self.cell(k)
        return {self.x.name: float(self.x.values[i]), self.y.name: float(self.y.values[j])}

    def rows(self, start: int, stop: int) -> list[Row]:
        """The rows of designs ``start`` to ``stop - 1`` (what one worker job computes)."""
        base = values_of(self.base)
        key = (self.task.x0, self.task.x1, self.task.y0, self.task.y1)
        return [
            design_row(self.arrangement.value, base, self.overrides(k), key, self.settings)
            for k in range(start, min(stop, self.size))
        ]


def value_of(row: Row | None, index: str) -> float:
    """The value of ``index`` in ``row`` (SI), NaN if the design is infeasible or not computed yet."""
    if row is None or not row.get("feasible"):
        return math.nan
    if index == "footprint":
        return float(row["footprint_x"]) * float(row["footprint_y"])
    return float(row[index])


def values(rows: list[Row | None], index: str) -> np.ndarray:
    """One value per design (NaN: infeasible or not computed yet)."""
    return np.array([value_of(row, index) for row in rows], dtype=float)


def ramp(t: np.ndarray) -> np.ndarray:
    """Colours ``(n, 3)`` uint8 of ``t`` in ``[0, 1]`` (0 worst, 1 best) on the viridis stops."""
    t = np.clip(np.asarray(t, dtype=float), 0.0, 1.0) * (len(_RAMP) - 1)
    lo = np.minimum(np.floor(t).astype(int), len(_RAMP) - 2)
    w = (t - lo)[:, None]
    return np.round(_RAMP[lo] * (1 - w) + _RAMP[lo + 1] * w).astype(np.uint8)


def colours(vals: np.ndarray, index: str) -> tuple[np.ndarray, tuple[float, float] | None]:
    """Cell colours ``(n, 3)`` uint8 (grey where NaN) and the range ``(worst, best)`` of the finite values."""
    out = np.tile(np.array(INFEASIBLE_COLOUR, dtype=np.uint8), (len(vals), 1))
    ok = np.isfinite(vals)
    if not ok.any():
        return out, None
    lo, hi = float(vals[ok].min()), float(vals[ok].max())
    t = np.full(len(vals), 0.5) if hi == lo else (vals - lo) / (hi - lo)
    if not INDICES[index].higher_better:
        t = 1.0 - t
    out[ok] = ramp(t[ok])
    worst, best = (lo, hi) if INDICES[index].higher_better else (hi, lo)
    return out, (worst, best)


def best_cell(vals: np.ndarray, index: str) -> int | None:
    """The design with the best finite value of ``index`` (the first of equals), or None."""
    ok = np.flatnonzero(np.isfinite(vals))
    if not ok.size:
        return None
    pick = np.argmax(vals[ok]) if INDICES[index].higher_better else np.argmin(vals[ok])
    return int(ok[pick])


def prototype_at(spec: MapSpec, prototype: Params | None = None) -> tuple[float, float] | None:
    """Where the paper's prototype lies on the map, ``(column, row)`` in cells (fractional), or None when its
    values are outside the map (by more than half a cell) or its other lengths differ from the map's base."""
    proto = Params.paper() if prototype is None else prototype
    for name in SWEPT:
        if name not in (spec.x.name, spec.y.name) and not math.isclose(
            getattr(proto, name), getattr(spec.base, name), rel_tol=1e-9
        ):
            return None
    u, v = spec.x.at(getattr(proto, spec.x.name)), spec.y.at(getattr(proto, spec.y.name))
    inside = -0.5 <= u <= spec.x.count - 0.5 and -0.5 <= v <= spec.y.count - 0.5
    return (u, v) if inside else None
