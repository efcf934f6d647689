"""``tpm-viz compare`` for people: the comparison's rows (:func:`tpm_viz.design.compare.compare`, SI) as two plain-text
tables in the UI's units (``docs/conventions.md``: mm, N, kg, s), one line per arrangement and case: the designs
(dimensions, link mass, where the task stands) and their indices. An infeasible design says why, never a number.

Formatting only; the CSV (``COMPARE_COLUMNS``, SI) stays what scripts read.
"""

from __future__ import annotations

import math
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass

from tpm_viz.core.numbers import fixed
from tpm_viz.core.words import Lang, say
from tpm_viz.design.atlas import Row
from tpm_viz.design.compare import NONE_FOUND, Hold
from tpm_viz.design.indices import Settings, Task
from tpm_viz.design.optimum import Search

__all__ = ["DESIGN_COLUMNS", "INDEX_COLUMNS", "Column", "compare_text", "number"]

DASH = "—"
"""What a value that is not a finite number shows (never NaN)."""
GAP = "  "
"""Between two columns."""
WIDTH = 100
"""Most characters of a line of the heading."""


@dataclass(frozen=True)
class Column:
    """One column: the CSV column ``key`` shown as ``format(value * scale, fmt)`` under ``name`` and ``unit``."""

    key: str
    name: str
    unit: str
    fmt: str
    scale: float = 1.0


DESIGN_COLUMNS = (
    Column("a", "a", "mm", ".1f", 1e3),
    Column("b", "b", "mm", ".1f", 1e3),
    Column("l_a", "l_a", "mm", ".1f", 1e3),
    Column("stroke", "Δd", "mm", ".1f", 1e3),
    Column("m_b", "m_b", "kg", ".3f"),
    Column("task_x0", "task x0", "mm", ".1f", 1e3),
    Column("task_x1", "task x1", "mm", ".1f", 1e3),
    Column("task_y0", "task y0", "mm", ".1f", 1e3),
    Column("task_y1", "task y1", "mm", ".1f", 1e3),
)
"""The designs table (SI columns shown in mm and kg)."""
INDEX_COLUMNS = (
    Column("gci", "GCI", "", ".3f"),
    Column("cond_max", "cond J", "worst", ".2f"),
    Column("dyn_mean", "dyn mean", "kg", ".2f"),
    Column("dyn_max", "dyn max", "kg", ".2f"),
    Column("peak_force", "peak force", "N", ".0f"),
    Column("cycle_time", "cycle", "s", ".3f"),
    Column("moving_mass", "moving mass", "kg", ".2f"),
    Column("footprint_x", "footprint x", "mm", ".1f", 1e3),
    Column("footprint_y", "footprint y", "mm", ".1f", 1e3),
)
"""The indices table (``docs/design.md``, *The indices*)."""
HOLDS = {
    Hold.LINK: "the same link length",
    Hold.FOOTPRINT: "a footprint within the perpendicular's",
    Hold.MASS: "a moving mass at most the given design's",
}
"""What the heading says a comparison holds equal."""


def number(value: object, fmt: str, scale: float = 1.0) -> str:
    """``value * scale`` formatted with ``fmt`` as people read it (:func:`tpm_viz.core.numbers.fixed`: no ``-0.0``,
    :data:`DASH` for anything that is not a finite number)."""
    return fixed(value, fmt, scale)


def _lines(heads: list[list[str]], body: list[tuple[list[str], str | None]]) -> list[str]:
    """Columns right-aligned but the first two (left-aligned); a body line with text instead of cells (``why``)
    runs on after its first two cells."""
    cells = [*heads, *(c for c, why in body if why is None)]
    widths = [max(len(line[k]) for line in cells) for k in range(len(heads[0]))]
    for line, why in body:
        if why is not None:
            widths[:2] = [max(widths[k], len(line[k])) for k in range(2)]

    def fit(line: list[str]) -> str:
        return GAP.join(c.ljust(w) if k < 2 else c.rjust(w) for k, (c, w) in enumerate(zip(line, widths, strict=False)))

    out = [fit(h).rstrip() for h in heads]
    out.append(GAP.join("-" * w for w in widths))
    for line, why in body:
        out.append(fit(line).rstrip() if why is None else (fit(line) + GAP + why).rstrip())
    return out


def _table(rows: Sequence[Row], columns: Sequence[Column], infeasible: bool) -> list[str]:
    """One table: ``infeasible`` rows get their reason instead of cells (the designs table: only rows without
    dimensions, i.e. no optimum)."""
    heads = [["arrangement", "case", *(c.name for c in columns)], ["", "", *(c.unit for c in columns)]]
    body: list[tuple[list[str], str | None]] = []
    for row in rows:
        first = [str(row.get("arrangement", "")), str(row.get("case", ""))]
        if infeasible and not row.get("feasible"):
            body.append((first, "infeasible: " + say(Lang.EN, row.get("why") or NONE_FOUND)))
        elif not infeasible and not math.isfinite(float(row.get("a", math.nan))):
            body.append((first, say(Lang.EN, row.get("why") or NONE_FOUND)))
        else:
            body.append(([*first, *(number(row.get(c.key), c.fmt, c.scale) for c in columns)], None))
    return _lines(heads, body)


def compare_text(rows: Sequence[Row], hold: Hold, task: Task, settings: Settings, how: Search) -> str:
    """The comparison for a terminal: a heading with the settings, the designs, the indices (``rows``: SI, as
    :func:`~tpm_viz.design.compare.compare` returns them)."""
    along = "across its width (x)" if settings.pick == "x" else "along its height (y)"
    plural = "" if how.generations == 1 else "s"
    heading = textwrap.wrap(
        f"Perpendicular vs parallel, each as given and at its own optimum (the shortest pick cycle), with "
        f"{HOLDS[hold]}. Task {number(task.width, '.1f', 1e3)} × {number(task.height, '.1f', 1e3)} mm centred on "
        f"each home pose, pick {along}; force limit {number(settings.force_limit, 'g')} N, planner grid "
        f"{settings.planner_grid}; search seed {how.seed}, at most {how.generations} generation{plural}.",
        WIDTH,
    )
    designs, indices = _table(rows, DESIGN_COLUMNS, False), _table(rows, INDEX_COLUMNS, True)
    return "\n".join([*heading, "", "Designs", *designs, "", "Indices", *indices])
