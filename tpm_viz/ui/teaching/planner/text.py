"""Text of the *Planner* tab (HTML): the live cycle-time line, the sizing table beside the paper's cubic law scaled
to the same peak force, and other robots' catalogue figures, in a tab's language (``lang``; the industry figures are
static HTML, translated on the wire). Formatting only (numbers through :func:`.text.num`:
a dash for NaN or infinity; SI converted to mm, N, W, J)."""

from __future__ import annotations

import html

from tpm_viz.app.planning import INDUSTRY, PlanResult
from tpm_viz.classroom.text import num
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, T, say

__all__ = ["industry_html", "result_html", "sizing_html"]

_STYLE = "font-size:0.85em;color:#334155;line-height:1.45"
_UNITS = {"m/s": ("mm/s", 1e3), "s": ("s", 1.0)}  # display unit and scale of SI units that change
_FORMATS = {"s": ".3f", "mm/s": ".0f", "N": ".1f", "W": ".1f", "J": ".3f"}
_QUANTITIES = {
    str(q): q
    for q in (
        T("cycle time"),
        T("motion time"),
        T("dwell"),
        T("peak force"),
        T("RMS force"),
        T("peak mechanical power"),
        T("peak driving power"),
        T("peak braking power"),
        T("mean mechanical power"),
        T("energy per cycle"),
        T("braking energy per cycle"),
        T("peak actuator speed"),
        T("peak platform speed"),
        T("motor constant"),
        T("peak copper loss"),
        T("mean copper loss"),
        T("copper loss energy per cycle"),
    )
}
"""The quantities of :meth:`~tpm_viz.app.sizing.Sizing.rows` (English names) as phrases, for the table."""


def result_html(
    result: PlanResult | None,
    force: float,
    speed: float | None,
    busy: bool,
    error: str | Phrase = "",
    lang: Lang = Lang.EN,
) -> Html:
    """The live line: cycle time and cycles (picks) per minute at the limits it was solved for."""
    esc = html.escape
    lines = []
    if error:
        lines.append(f'<span style="color:#991b1b">{esc(say(lang, error))}</span>')
    if result is None:
        if not error:
            lines.append(
                f"<i>{esc(say(lang, T('Planning…')))}</i>" if busy else say(lang, T("Choose a path and the limits."))
            )
    else:
        lim = result.plan.limits
        speed_text = (
            T("no speed limit") if lim.speed is None else Phrase("|ṗ| ≤ {speed} mm/s", speed=num(lim.speed, ".0f", 1e3))
        )
        moves = " + ".join(num(d, ".3f") for d in result.plan.move_durations)
        figures = {
            "time": f"<span data-q='cycle-time'>{num(result.cycle_time, '.3f')}</span>",
            "rate": f"<span data-q='per-minute'>{num(result.per_minute, '.0f')}</span>",
        }
        if result.kind == "pick":
            cycle = Phrase("cycle {time} s = {rate} picks/min", **figures)
        else:
            cycle = Phrase("cycle {time} s = {rate} cycles/min", **figures)
        lines.append(f"<b style='font-size:1.15em'>{say(lang, cycle)}</b>")
        optimal = Phrase(
            "time-optimal for |τ_i| ≤ {force} N, {speed}; strokes {moves} s; solved in {ms} ms",
            force=f"<span data-q='plan-force'>{num(lim.force, '.0f')}</span>",
            speed=speed_text,
            moves=moves,
            ms=f"<span data-q='solve-ms'>{num(result.seconds, '.0f', 1e3)}</span>",
        )
        lines.append(say(lang, optimal))
        cubic = Phrase(
            "the paper's cubic law with the same peak force: cycle {time} s ({ratio}× longer)",
            time=num(result.cubic.cycle_time, ".3f"),
            ratio=num(result.cubic.cycle_time / result.cycle_time, ".2f"),
        )
        lines.append(esc(say(lang, cubic)))
        if busy:
            lines.append(f"<i>{esc(say(lang, T('updating…')))}</i>")
    return Html(f'<div data-q="plan-result" style="{_STYLE}">' + "<br>".join(lines) + "</div>")


def sizing_html(result: PlanResult | None, lang: Lang = Lang.EN) -> Html:
    """The sizing table of the planned cycle beside the cubic law's (same peak force), per actuator."""
    if result is None:
        return Html("")
    esc = html.escape
    cell = "padding:1px 5px;text-align:right;font-variant-numeric:tabular-nums"
    act1, act2 = esc(say(lang, T("act. 1"))), esc(say(lang, T("act. 2")))
    head = (
        f"<tr><th></th><th></th><th colspan=2 style='{cell}'>{esc(say(lang, T('time-optimal')))}</th>"
        f"<th colspan=2 style='{cell};color:#64748b'>{esc(say(lang, T('cubic law')))}</th></tr>"
        f"<tr><th style='text-align:left'>{esc(say(lang, T('quantity')))}</th>"
        f"<th>{esc(say(lang, T('unit')))}</th>"
        + "".join(f"<th style='{cell}'>{h}</th>" for h in (act1, act2, act1, act2))
        + "</tr>"
    )
    body = []
    for (q, unit, a, b), (_q, _u, c, d) in zip(result.sizing.rows(), result.cubic.rows(), strict=False):
        shown, scale = _UNITS.get(unit, (unit, 1.0))
        fmt = _FORMATS.get(shown, ".4g")
        slug = q.replace(" ", "-")
        values = "".join(
            f"<td style='{cell}{';color:#64748b' if k > 1 else ''}' data-q='{slug}-{k}'>{num(v, fmt, scale)}</td>"
            for k, v in enumerate((a, b, c, d))
        )
        name = esc(say(lang, _QUANTITIES.get(q, q)))
        body.append(f"<tr><td>{name}</td><td>{esc(shown)}</td>{values}</tr>")
    title = esc(say(lang, T("Motor sizing, one cycle")))
    note = T(
        "Cubic law: the paper's time law s = L(3u² − 2u³) on the same strokes, slowed until its peak force equals "
        "the plan's. No dwell, no friction, horizontal plane."
    )
    return Html(
        f'<div data-q="sizing" style="{_STYLE}"><b>{title}</b>'
        f'<table style="border-collapse:collapse;margin-top:4px">{head}{"".join(body)}</table>'
        f"<div style='color:#64748b'>{esc(say(lang, note))}</div></div>"
    )


def industry_html() -> Html:
    """Other robots' catalogue values, labelled as such."""
    rows = "".join(
        f"<li>{html.escape(robot)}: {html.escape(cycle)}, {html.escape(figure)}</li>"
        for robot, cycle, figure in INDUSTRY
    )
    return Html(
        f'<div data-q="industry" style="{_STYLE}"><b>For orientation: other robots\' catalogue values</b> '
        f"(not this mechanism, not computed here)<ul style='margin:2px 0 0 16px;padding:0'>{rows}</ul></div>"
    )
