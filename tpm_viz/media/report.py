"""The lab report of a run: one self-contained HTML file.

Nothing in it needs the network: the style is inline CSS, the path an inline SVG (axes in mm with ticks, one scale on
both: :func:`nice_ticks`), the force plot the
inline SVG of :func:`tpm_viz.drawing.figures.force_plot_svg` (the style of the paper's Figs. 4-5: closed form solid,
Pinocchio dotted, their difference below), the procedure (a)-(e) MathML (:func:`tpm_viz.app.equations.
procedure_html`) and the run's CSV a ``data:`` link. It prints to PDF from a browser (a print style sheet: no
link colours, no figure split across pages).

Contents: the parameters with their units, the path, the force plot, the peak force and the largest difference
between the closed form (eq. 31) and the Pinocchio model, the procedure (a)-(e) at the peak-force instant, the
results of the control lab or the planner when there are any (:class:`Section`), the errata the numbers depend on,
tpm-viz's version and the date. Headings, labels and notes in the report's language (:mod:`tpm_viz.core.words`); the
procedure's sentences are the app's (English). Every number shown is also in a ``data-value`` attribute at full
precision (SI units), so that a program can read the report.
"""

from __future__ import annotations

import base64
import dataclasses
import datetime
import html
import importlib.metadata
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.equations import errata_html, procedure_html
from tpm_viz.app.run_names import label_words
from tpm_viz.app.runs import Run
from tpm_viz.core.csvio import format_columns
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.drawing.figures import force_plot_svg
from tpm_viz.paper.dynamics import inverse_dynamics_detail
from tpm_viz.paper.jacobians import jacobians

__all__ = ["PARAM_WORDS", "Section", "peak_instant", "report_html", "version"]

MAX_SECTION_ROWS = 40
"""Most rows of one extra section (control lab, planner)."""

_STYLE = """
body{font:15px/1.45 system-ui,-apple-system,"Segoe UI","Noto Sans KR","NanumGothic",sans-serif;color:#111;
max-width:60rem;margin:1.5rem auto;padding:0 1rem}
h1{font-size:1.5rem;margin:0 0 .2rem}h2{font-size:1.15rem;margin:1.6rem 0 .5rem;border-bottom:1px solid #ccc}
table{border-collapse:collapse;margin:.4rem 0}td,th{border:1px solid #ccc;padding:.2rem .55rem;text-align:left}
td.num{text-align:right;font-variant-numeric:tabular-nums}.meta{color:#555}figure{margin:.5rem 0;
break-inside:avoid}figure svg{max-width:100%;height:auto}figcaption{color:#444;font-size:.9rem}
.tpm-equations{break-inside:avoid-page}
@media print{body{margin:0;max-width:none;font-size:11pt}a{color:#000}h2{break-after:avoid}}
@page{margin:16mm}
"""


@dataclass(frozen=True)
class Section:
    """An extra part of the report (the control lab's or the planner's results): a title and rows of
    ``(label, value, unit)``; ``value`` a number [the unit's] or a text."""

    title: str | Phrase
    rows: tuple[tuple[str | Phrase, float | str | Phrase, str], ...]


def version() -> str:
    """The installed tpm-viz version (``"unknown"`` when it is not installed)."""
    try:
        return importlib.metadata.version("tpm-viz")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def peak_instant(run: Run) -> int:
    """Index of the sample with the largest ``|τ_i|`` (closed form, eq. 31)."""
    return int(np.argmax(np.max(np.abs(run.tau), axis=1)))


def _esc(text: object) -> str:
    return html.escape(str(text), quote=True)


def _number(value: float, fmt: str, unit: str = "") -> str:
    """A table cell with ``value`` shown with ``fmt`` (in the unit shown) and at full precision in data-value."""
    value = float(value)
    shown = format(value, fmt) if math.isfinite(value) else "—"
    shown = shown.replace("-", "−") if shown.startswith("-") else shown
    return f'<td class="num" data-value="{value!r}">{_esc(shown)}</td><td>{_esc(unit)}</td>'


PARAM_WORDS = {
    "a": T("total size a (Table 1): rail i starts at -a e_i"),
    "b": T("platform offset b (Table 1): B_i = P - b e_i"),
    "l_a": T("link length l_a (Table 1)"),
    "m_a": T("slider mass m_a (Table 2)"),
    "m_b": T("mass of both links of one parallelogram m_b (Table 2)"),
    "m_p": T("platform mass m_p (Table 2)"),
    "stroke": T("actuator stroke Δd (Table 1): 0 <= d_i <= Δd"),
    "pivot_spacing": T("pivot spacing of the two parallelogram links"),
}
"""Each parameter's description (its ``doc`` in :class:`~tpm_viz.core.params.Params`) as a phrase, for the table."""


def _parameters(params: Params, lang: Lang) -> str:
    rows = []
    for f in dataclasses.fields(params):
        meta = f.metadata
        rows.append(
            f'<tr data-key="{f.name}"><td>{_esc(f.name)}</td>'
            + _number(getattr(params, f.name) * meta["ui_scale"], ".4g", meta["ui_unit"])
            + f"<td>{_esc(say(lang, PARAM_WORDS.get(f.name, meta['doc'])))}</td></tr>"
        )
    head = f"<tr><th>{say(lang, T('name'))}</th><th colspan=2>{say(lang, T('value'))}</th><th></th></tr>"
    return "<table>" + head + "".join(rows) + "</table>"


PLOT_PX = 400
"""Side of the path plot [px]; its margins (left, right, top, bottom) hold the axes' numbers and names."""
PLOT_MARGINS = (58, 14, 14, 44)


def nice_ticks(lo: float, hi: float, count: int = 5) -> list[float]:
    """Round values (1, 2 or 5 times a power of ten apart) inside ``[lo, hi]``, about ``count`` of them."""
    span = max(hi - lo, 1e-9)
    raw = span / max(count - 1, 1)
    power = 10.0 ** math.floor(math.log10(raw))
    step = min((m * power for m in (1.0, 2.0, 5.0, 10.0)), key=lambda v: abs(math.log(v / raw)))
    first = math.ceil(lo / step - 1e-9) * step
    return [round(first + k * step, 10) for k in range(int((hi - first) / step + 1e-9) + 1)]


def _path_svg(run: Run, lang: Lang) -> str:
    """The platform's path [mm] as an inline SVG: axes p₁ and p₂ in mm with ticks and numbers, the same scale on
    both (the path's true shape), y up, start (circle) and end (square) marked."""
    p = run.p * 1e3
    lo, hi = p.min(axis=0), p.max(axis=0)
    span = float(max(hi[0] - lo[0], hi[1] - lo[1], 1.0))
    mid = (lo + hi) / 2
    half = 0.56 * span  # the path and a little room around it, in mm
    (x_lo, x_hi), (y_lo, y_hi) = ((float(c - half), float(c + half)) for c in mid)
    left, right, top, bottom = PLOT_MARGINS
    side = PLOT_PX - max(left + right, top + bottom)  # a square plot: one scale for p1 and p2
    scale = side / (2 * half)  # px per mm

    def px(x: float, y: float) -> tuple[float, float]:
        return left + (x - x_lo) * scale, top + (y_hi - y) * scale

    points = " ".join("{:.2f},{:.2f}".format(*px(x, y)) for x, y in p)
    (sx, sy), (ex, ey) = px(*p[0]), px(*p[-1])
    ticks = []
    for v in nice_ticks(x_lo, x_hi):
        x, _ = px(v, y_lo)
        ticks.append(
            f'<line x1="{x:.2f}" y1="{top + side}" x2="{x:.2f}" y2="{top + side + 5}" stroke="#444"/>'
            f'<text x="{x:.2f}" y="{top + side + 18}" text-anchor="middle" data-axis="x" data-mm="{v:g}">{v:g}</text>'
        )
    for v in nice_ticks(y_lo, y_hi):
        _, y = px(x_lo, v)
        ticks.append(
            f'<line x1="{left - 5}" y1="{y:.2f}" x2="{left}" y2="{y:.2f}" stroke="#444"/>'
            f'<text x="{left - 8}" y="{y + 4:.2f}" text-anchor="end" data-axis="y" data-mm="{v:g}">{v:g}</text>'
        )
    label = say(
        lang,
        Phrase(
            "path of P from {start} (circle) to {end} (square), mm",
            start=f"({p[0][0]:.1f}, {p[0][1]:.1f})",
            end=f"({p[-1][0]:.1f}, {p[-1][1]:.1f})",
        ),
    )
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" role="img" width="{PLOT_PX}" height="{PLOT_PX}" '
        f'viewBox="0 0 {PLOT_PX} {PLOT_PX}" font-family="sans-serif" font-size="12" fill="#333">'
        f"<title>{_esc(label)}</title>"
        f'<rect x="{left}" y="{top}" width="{side}" height="{side}" fill="#fafafa" stroke="#444"/>'
        + "".join(ticks)
        + f'<text x="{left + side / 2:.1f}" y="{top + side + 36}" text-anchor="middle">p1 (mm)</text>'
        f'<text transform="translate(14 {top + side / 2:.1f}) rotate(-90)" text-anchor="middle">p2 (mm)</text>'
        f'<polyline points="{points}" fill="none" stroke="#ca8a04" stroke-width="2"/>'
        f'<circle cx="{sx:.2f}" cy="{sy:.2f}" r="5" fill="#15803d"/>'
        f'<rect x="{ex - 5:.2f}" y="{ey - 5:.2f}" width="10" height="10" fill="#b91c1c"/></svg>'
    )


def _inline_svg(data: bytes) -> str:
    """matplotlib's SVG without its XML prologue and its metadata (which carries the time it was drawn)."""
    text = data.decode("utf-8")
    text = text[text.index("<svg") :]
    start, end = text.find("<metadata>"), text.find("</metadata>")
    return text[:start] + text[end + len("</metadata>") :] if 0 <= start < end else text


def _results(run: Run, k: int, lang: Lang) -> str:
    tau = run.tau
    rows = [
        (T("peak actuator force |τ| (eq. 31)"), "peak", _number(run.peak, ".2f", "N")),
        (T("at time t"), "peak_t", _number(run.t[k], ".4f", "s")),
        (T("τ1 at that time"), "peak_tau1", _number(tau[k, 0], ".2f", "N")),
        (T("τ2 at that time"), "peak_tau2", _number(tau[k, 1], ".2f", "N")),
    ]
    if run.tau_ref is not None:
        diff = np.abs(run.tau_ref - tau)
        j = int(np.argmax(np.max(diff, axis=1)))
        rel = float(np.max(diff / (1.0 + np.abs(tau))))
        rows += [
            (T("largest difference |τ Pinocchio − τ paper|"), "max_diff", _number(float(diff.max()), ".2e", "N")),
            (T("at time t"), "max_diff_t", _number(run.t[j], ".4f", "s")),
            (T("largest relative difference |Δτ| / (1 N + |τ|)"), "max_rel", _number(rel, ".2e", "")),
        ]
    else:
        note = say(lang, run.ref_note or T("no reference model"))
        rows.append((T("Pinocchio model"), "ref_note", f"<td colspan=2>{_esc(note)}</td>"))
    body = "".join(f'<tr data-key="{key}"><td>{_esc(say(lang, label))}</td>{cell}</tr>' for label, key, cell in rows)
    return "<table>" + body + "</table>"


def _section(section: Section, lang: Lang) -> str:
    rows = []
    for label, value, unit in section.rows[:MAX_SECTION_ROWS]:
        if isinstance(value, int | float) and not isinstance(value, bool):
            cell = _number(value, ".4g", unit)
        else:
            cell = f"<td colspan=2>{_esc(say(lang, value))}</td>"
        rows.append(f"<tr><td>{_esc(say(lang, label))}</td>{cell}</tr>")
    return f"<h2>{_esc(say(lang, section.title))}</h2><table>" + "".join(rows) + "</table>"


def _procedure(run: Run, k: int, lang: Lang) -> str:
    res = inverse_dynamics_detail(run.params, run.p[k], run.dp[k], run.ddp[k], d=run.d[k])
    jac = jacobians(run.params, run.p[k], run.d[k])
    return procedure_html(run.params, res, jac, lang=lang)


def report_html(
    run: Run,
    lang: Lang | str = Lang.EN,
    date: datetime.date | None = None,
    sections: Sequence[Section] = (),
) -> str:
    """The report of ``run`` (see the module docstring) in ``lang``, dated ``date`` (today, UTC, by default)."""
    lang = Lang.parse(lang) if not isinstance(lang, Lang) else lang
    date = date or datetime.datetime.now(datetime.UTC).date()
    k = peak_instant(run)
    label = label_words(run.source.label)
    title = say(lang, Phrase("Lab report: {run}", run=label))
    figure = force_plot_svg(run.t, run.tau, run.tau_ref, title=f"Actuator forces: {run.source.label}")  # no Hangul font
    csv_text = format_columns(run.columns())
    csv_link = "data:text/csv;charset=utf-8;base64," + base64.b64encode(csv_text.encode("utf-8")).decode("ascii")
    name = f"tpm-run-{run.source.kind}-T{run.duration:g}s.csv"
    parts = [
        f'<!DOCTYPE html><html lang="{lang.value}"><head><meta charset="utf-8">',
        '<meta name="viewport" content="width=device-width, initial-scale=1">',
        f"<title>{_esc(title)}</title><style>{_STYLE}</style></head><body>",
        f"<h1>{_esc(title)}</h1>",
        f'<p class="meta" id="meta" data-version="{_esc(version())}" data-date="{date.isoformat()}">'
        + _esc(say(lang, Phrase("tpm-viz {version}, {date}", version=version(), date=date.isoformat())))
        + " · "
        + _esc(say(lang, T("2-PPa planar translational parallel manipulator (Pham & Kim 2013)")))
        + "</p>",
        f"<h2>{say(lang, T('Parameters'))}</h2>",
        _parameters(run.params, lang),
        f"<h2>{say(lang, T('The path'))}</h2><figure>{_path_svg(run, lang)}<figcaption>",
        _esc(say(lang, Phrase("{label}: {n} samples, uniform in time", label=label, n=len(run.t)))),
        f"</figcaption></figure><h2>{say(lang, T('Actuator forces'))}</h2>",
        f'<figure id="forces">{_inline_svg(figure)}<figcaption>',
        _esc(say(lang, T("The paper's closed form (solid) and the Pinocchio model (dotted), as in Figs. 4-5"))),
        "</figcaption></figure>",
        f'<section id="results">{_results(run, k, lang)}</section>',
        f"<h2>{_esc(say(lang, Phrase('The procedure (a)-(e) at the peak force, t = {t} s', t=f'{run.t[k]:.4f}')))}"
        "</h2>",
        f'<section id="procedure" data-t="{float(run.t[k])!r}">{_procedure(run, k, lang)}</section>',
        *(_section(s, lang) for s in sections),
        f"<h2>{say(lang, T('Errata the numbers depend on'))}</h2>",
        errata_html(lang),
        f"<h2>{say(lang, T('Data'))}</h2><p>",
        f'<a id="csv" download="{_esc(name)}" href="{csv_link}">{_esc(say(lang, T("Download the run (CSV)")))}</a> ',
        _esc(say(lang, Phrase("({rows} rows; columns in SI units: s, m, m/s, m/s², N)", rows=len(run.t)))),
        "</p></body></html>\n",
    ]
    return "".join(parts)
