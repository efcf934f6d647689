"""Text of the *Planner* tab (HTML): the live cycle-time line, the sizing table beside the paper's cubic law scaled
to the same peak force, and other robots' catalogue figures. Formatting only (numbers through :func:`.text.num`:
a dash for NaN or infinity; SI converted to mm, N, W, J)."""

from __future__ import annotations

import html

from tpm_viz.app.planning import INDUSTRY, PlanResult
from tpm_viz.ui.text import num

__all__ = ["industry_html", "result_html", "sizing_html"]

_STYLE = "font-size:0.85em;color:#334155;line-height:1.45"
_UNITS = {"m/s": ("mm/s", 1e3), "s": ("s", 1.0)}  # display unit and scale of SI units that change
_FORMATS = {"s": ".3f", "mm/s": ".0f", "N": ".1f", "W": ".1f", "J": ".3f"}


def result_html(result: PlanResult | None, force: float, speed: float | None, busy: bool, error: str = "") -> str:
    """The live line: cycle time and cycles (picks) per minute at the limits it was solved for."""
    esc = html.escape
    lines = []
    if error:
        lines.append(f'<span style="color:#991b1b">{esc(error)}</span>')
    if result is None:
        if not error:
            lines.append("<i>Planning…</i>" if busy else "Choose a path and the limits.")
    else:
        lim = result.plan.limits
        speed_text = "no speed limit" if lim.speed is None else f"|ṗ| ≤ {num(lim.speed, '.0f', 1e3)} mm/s"
        moves = " + ".join(num(d, ".3f") for d in result.plan.move_durations)
        what = "picks" if result.kind == "pick" else "cycles"
        lines.append(
            f"<b style='font-size:1.15em'>cycle <span data-q='cycle-time'>{num(result.cycle_time, '.3f')}</span> s"
            f" = <span data-q='per-minute'>{num(result.per_minute, '.0f')}</span> {what}/min</b>"
        )
        lines.append(
            f"time-optimal for |τ_i| ≤ <span data-q='plan-force'>{num(lim.force, '.0f')}</span> N, {speed_text}; "
            f"strokes {moves} s; solved in <span data-q='solve-ms'>{num(result.seconds, '.0f', 1e3)}</span> ms"
        )
        lines.append(
            f"the paper's cubic law with the same peak force: cycle {num(result.cubic.cycle_time, '.3f')} s "
            f"({num(result.cubic.cycle_time / result.cycle_time, '.2f')}× longer)"
        )
        if busy:
            lines.append("<i>updating…</i>")
    return f'<div data-q="plan-result" style="{_STYLE}">' + "<br>".join(lines) + "</div>"


def sizing_html(result: PlanResult | None) -> str:
    """The sizing table of the planned cycle beside the cubic law's (same peak force), per actuator."""
    if result is None:
        return ""
    cell = "padding:1px 5px;text-align:right;font-variant-numeric:tabular-nums"
    head = (
        f"<tr><th></th><th></th><th colspan=2 style='{cell}'>time-optimal</th>"
        f"<th colspan=2 style='{cell};color:#64748b'>cubic law</th></tr>"
        f"<tr><th style='text-align:left'>quantity</th><th>unit</th>"
        + "".join(f"<th style='{cell}'>{h}</th>" for h in ("act. 1", "act. 2", "act. 1", "act. 2"))
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
        body.append(f"<tr><td>{html.escape(q)}</td><td>{html.escape(shown)}</td>{values}</tr>")
    return (
        f'<div data-q="sizing" style="{_STYLE}"><b>Motor sizing, one cycle</b>'
        f'<table style="border-collapse:collapse;margin-top:4px">{head}{"".join(body)}</table>'
        "<div style='color:#64748b'>Cubic law: the paper's time law s = L(3u² − 2u³) on the same strokes, slowed "
        "until its peak force equals the plan's. No dwell, no friction, horizontal plane.</div></div>"
    )


def industry_html() -> str:
    """Other robots' catalogue values, labelled as such."""
    rows = "".join(
        f"<li>{html.escape(robot)}: {html.escape(cycle)}, {html.escape(figure)}</li>"
        for robot, cycle, figure in INDUSTRY
    )
    return (
        f'<div data-q="industry" style="{_STYLE}"><b>For orientation: other robots\' catalogue values</b> '
        f"(not this mechanism, not computed here)<ul style='margin:2px 0 0 16px;padding:0'>{rows}</ul></div>"
    )
