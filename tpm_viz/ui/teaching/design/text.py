"""Text of the *Design* tab (HTML, in a tab's language): the map's progress line and legend, the picked design,
and the table comparing both arrangements. Formatting only: SI rows shown in mm, N, kg, s (numbers through
:func:`~tpm_viz.classroom.text.num`); an infeasible design says so and why, never a number."""

from __future__ import annotations

import html
from collections.abc import Sequence

import numpy as np

from tpm_viz.classroom.text import num
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.design.atlas import Row
from tpm_viz.ui.teaching.design.map import INDICES, SWEPT, MapSpec, ramp, value_of

__all__ = [
    "ARRANGEMENTS",
    "HOLDS",
    "INTRO",
    "PICK_LABELS",
    "RANGE_LABELS",
    "TASK_LABELS",
    "cell_html",
    "legend_html",
    "progress_html",
    "table_html",
]

INTRO = (
    "Size the machine for a task: a map of designs over two dimensions, coloured by an index; click a cell "
    "(or type its column and row) to load the design. The map and the comparison are drawn in the Design "
    "area of the scene."
)
"""The tab's first paragraph (Markdown, translated like every widget text)."""
TASK_LABELS = {"x0": "Task x0 (mm)", "x1": "Task x1 (mm)", "y0": "Task y0 (mm)", "y1": "Task y1 (mm)"}
RANGE_LABELS = {
    "x_from": "Across: from (mm)",
    "x_to": "Across: to (mm)",
    "x_count": "Across: count",
    "y_from": "Up: from (mm)",
    "y_to": "Up: to (mm)",
    "y_count": "Up: count",
}
PICK_LABELS = {"column": "Column (1 = left)", "row": "Row (1 = bottom)"}
HOLDS = {"link": T("link length"), "footprint": T("footprint"), "mass": T("moving mass")}
"""What a comparison holds equal (``Hold.value``), as the table's title says it."""
DASH_TEXT = "—"
"""An infeasible design's index (its column says why above)."""
_STYLE = "font-size:0.85em;color:#334155;line-height:1.45"
ARRANGEMENTS = {"perpendicular": T("perpendicular"), "parallel": T("parallel")}
CASES = {"given": T("given"), "optimum": T("optimum")}
_COLUMNS = (
    ("gci", T("GCI"), ".3f", 1.0),
    ("cond_max", T("worst cond J"), ".2f", 1.0),
    ("dyn_mean", T("dyn. mean (kg)"), ".2f", 1.0),
    ("dyn_max", T("dyn. max (kg)"), ".2f", 1.0),
    ("peak_force", T("peak force (N)"), ".0f", 1.0),
    ("cycle_time", T("cycle (s)"), ".3f", 1.0),
    ("moving_mass", T("moving mass (kg)"), ".2f", 1.0),
)
"""Index columns of the tables: key, heading, format, display scale."""


def _esc(lang: Lang, what: object) -> str:
    return html.escape(say(lang, what))


def progress_html(done: int, total: int, busy: bool, lang: Lang = Lang.EN, error: object = None) -> Html:
    """The map's progress line: ``done`` of ``total`` designs, or the error that stopped it."""
    if error is not None:
        return Html(f'<div data-q="design-progress" style="{_STYLE};color:#991b1b">{_esc(lang, error)}</div>')
    if total == 0:
        return Html("")
    if busy:
        text = Phrase("Computing the map: {done} of {total} designs…", done=done, total=total)
    else:
        text = Phrase("Map computed: {total} designs (cycle time included).", total=total)
    return Html(f'<div data-q="design-progress" style="{_STYLE}">{_esc(lang, text)}</div>')


def legend_html(index: str, span: tuple[float, float] | None, feasible: int, total: int, lang: Lang = Lang.EN) -> Html:
    """The colour scale of the map (worst to best), and what grey, the ring and the cross mean."""
    info = INDICES[index]
    stops = ", ".join(f"rgb{tuple(int(c) for c in rgb)}" for rgb in ramp(np.linspace(0.0, 1.0, 5)))
    if span is None:
        scale = _esc(lang, T("No design of the map covers the task."))
    else:
        worst, best = (num(v, info.fmt, info.scale) for v in span)
        scale = (
            f'<div style="height:12px;border-radius:2px;background:linear-gradient(to right, {stops})"></div>'
            f'<div style="display:flex;justify-content:space-between">'
            f"<span>{_esc(lang, Phrase('worst {value}', value=worst))}</span>"
            f"<span>{_esc(lang, Phrase('best {value}', value=best))}</span></div>"
        )
    keys = Phrase(
        "{feasible} of {total} designs cover the task; grey: infeasible (no number). Black ring: best design; "
        "red cross: the paper's prototype.",
        feasible=feasible,
        total=total,
    )
    return Html(
        f'<div data-q="design-legend" style="{_STYLE};padding-right:16px"><b>{_esc(lang, T(info.label))}</b>{scale}'
        f'<div style="color:#64748b">{_esc(lang, keys)}</div></div>'
    )


def _mm(value: object) -> str:
    return num(value, ".1f", 1e3)


def cell_html(spec: MapSpec, k: int, row: Row | None, lang: Lang = Lang.EN) -> Html:
    """The picked design: its place on the map, its swept values (mm) and its indices, or why it is infeasible."""
    i, j = spec.cell(k)
    where = Phrase(
        "Column {column}, row {row}: {x} = {xv} mm, {y} = {yv} mm",
        column=i + 1,
        row=j + 1,
        x=SWEPT[spec.x.name],
        xv=_mm(spec.x.values[i]),
        y=SWEPT[spec.y.name],
        yv=_mm(spec.y.values[j]),
    )
    head = f'<b data-q="design-cell">{_esc(lang, where)}</b>'
    if row is None:
        body = _esc(lang, T("not computed yet"))
    elif not row.get("feasible"):
        body = f'<span style="color:#991b1b">{_esc(lang, Phrase("infeasible: {why}", why=row.get("why") or ""))}</span>'
    else:
        parts = [
            f"{_esc(lang, T(INDICES[key].label))} <span data-q='cell-{key}'>"
            f"{num(value_of(row, key), INDICES[key].fmt, INDICES[key].scale)}</span>"
            for key in INDICES
        ]
        body = "<br>".join(parts)
    return Html(f'<div style="{_STYLE}">{head}<br>{body}</div>')


def table_html(rows: Sequence[Row], hold: Phrase, lang: Lang = Lang.EN) -> Html:
    """The comparison, one column per design (arrangement and case) and one line per quantity: lengths in mm, then
    the indices in their units; an infeasible design says so (and why) instead of numbers. Cell ``data-q``:
    ``compare-<column>-<key>``."""
    if not rows:
        return Html("")
    td = "<td style='padding:0 4px;text-align:right'>"
    heads = [
        f"{_esc(lang, ARRANGEMENTS.get(str(r.get('arrangement', '')), T('perpendicular')))}<br>"
        f"{_esc(lang, CASES.get(str(r.get('case', '')), T('given')))}"
        for r in rows
    ]
    lines = ["<tr><th></th>" + "".join(f"<th style='padding:0 4px'>{h}</th>" for h in heads) + "</tr>"]
    if any(not r.get("feasible") for r in rows):
        why = [
            ""
            if r.get("feasible")
            else _esc(
                lang,
                Phrase("infeasible: {why}", why=r.get("why") or T("no design found within the limits")),
            )
            for r in rows
        ]
        lines.append("<tr><td></td>" + "".join(f"<td style='color:#991b1b'>{w}</td>" for w in why) + "</tr>")
    quantities = [(Phrase("{name} (mm)", name=symbol), name, ".1f", 1e3) for name, symbol in SWEPT.items()]
    quantities += [(T("footprint (mm)"), "footprint", "", 1e3)] + [(c[1], c[0], c[2], c[3]) for c in _COLUMNS]
    for label, key, fmt, scale in quantities:
        cells = []
        for n, r in enumerate(rows):
            if not r.get("feasible") and key not in SWEPT:
                cells.append(f"{td}{DASH_TEXT}</td>")
            elif key == "footprint":
                cells.append(f"{td}{_mm(r.get('footprint_x'))} × {_mm(r.get('footprint_y'))}</td>")
            else:
                cells.append(f"{td}<span data-q='compare-{n}-{key}'>{num(r.get(key), fmt, scale)}</span></td>")
        lines.append(f"<tr><td>{_esc(lang, label)}</td>" + "".join(cells) + "</tr>")
    title = Phrase("Holding the {hold} equal (task of the same size, centred on each home pose):", hold=hold)
    return Html(
        f'<div style="{_STYLE};overflow-x:auto"><div>{_esc(lang, title)}</div>'
        "<table style='border-collapse:collapse;font-variant-numeric:tabular-nums'>" + "".join(lines) + "</table></div>"
    )
