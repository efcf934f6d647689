"""Text and HTML of the panel, from a :class:`~tpm_viz.app.readouts.Readout`: formatting only, no maths.

UI units: mm, N, degrees (the readout is in SI). Every number goes through :func:`num`, which prints a dash for
``None``, NaN or infinity, so that no ``nan`` or ``inf`` ever reaches the page. Values carry ``data-q`` attributes
(used by the browser tests) and every label names its unit.
"""

from __future__ import annotations

import html
import math
from collections.abc import Iterable

import numpy as np

from tpm_viz.app.readouts import Readout
from tpm_viz.app.state import AppState
from tpm_viz.core.markup import Html
from tpm_viz.core.numbers import fixed
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.drawing.palette import hex_colour

__all__ = ["COLORS_CSS", "banner_level", "dashboard_html", "force_scale", "legend_html", "num"]

DASH = "—"

COLORS_CSS = {
    "ok": ("#ecfdf5", "#065f46", hex_colour("ok")),
    "stroke": ("#fdf2f8", "#9d174d", hex_colour("stroke")),
    "inverse": ("#fffbeb", "#92400e", hex_colour("inverse")),
    "direct": ("#fef2f2", "#991b1b", hex_colour("direct")),
}
"""Banner background (a light tint), text (a dark shade) and border (the palette colour) per level."""

TAU_POS, TAU_NEG = hex_colour("tau_pos"), hex_colour("tau_neg")


def num(x: object, fmt: str = ".1f", scale: float = 1.0) -> str:
    """``x * scale`` formatted with ``fmt``; a dash for None, NaN or infinity (:func:`tpm_viz.core.numbers.fixed`)."""
    return fixed(x, fmt, scale)


def banner_level(readout: Readout) -> str:
    """The most severe alert kind (``"direct"`` > ``"inverse"`` > ``"stroke"``), or ``"ok"``."""
    kinds = {a.kind for a in readout.alerts}
    for kind in ("direct", "inverse", "stroke"):
        if kind in kinds:
            return kind
    return "ok"


def force_scale(values: Iterable[float | None]) -> float:
    """Full scale [N] of the force bars: the next of 1-2-5 x 10^k at or above the largest ``|τ|`` (min 10 N)."""
    finite = [abs(float(v)) for v in values if v is not None and math.isfinite(float(v))]
    top = max([10.0, *finite])
    k = 10 ** math.floor(math.log10(top))
    for m in (1, 2, 5, 10):
        if m * k >= top:
            return float(m * k)
    return float(10 * k)  # pragma: no cover


def _q(name: str, text: str) -> str:
    return f'<span data-q="{name}">{html.escape(text)}</span>'


def _banner(state: AppState, readout: Readout, lang: Lang) -> str:
    level = banner_level(readout)
    bg, fg, border = COLORS_CSS[level]
    lines = [html.escape(say(lang, a.text)) for a in readout.alerts] or [
        html.escape(say(lang, T("Regular pose: clear of singularities and stroke ends")))
    ]
    note = (
        f'<div style="margin-top:3px;font-style:italic">{html.escape(say(lang, state.note))}</div>'
        if state.note
        else ""
    )
    return (
        f'<div data-q="banner" data-level="{level}" style="background:{bg};color:{fg};border-left:4px solid {border};'
        f'padding:6px 8px;border-radius:4px;font-size:0.85em;line-height:1.35">'
        f"<b>{'<br>'.join(lines)}</b>{note}</div>"
    )


def _row(label: str, values: str, unit: str) -> str:
    return (
        f'<tr><td style="padding:1px 6px 1px 0;color:#475569">{label}</td>'
        f'<td style="padding:1px 4px;text-align:right;font-variant-numeric:tabular-nums">{values}</td>'
        f'<td style="padding:1px 0;color:#64748b">{unit}</td></tr>'
    )


def _kinematics(readout: Readout, lang: Lang) -> str:
    p, d, th = readout.p, readout.d, np.degrees(readout.theta)
    mode = "+ (det J_x > 0)" if readout.mode > 0 else "− (det J_x < 0)"
    labels = [html.escape(say(lang, label)) for label in ROW_LABELS]
    rows = [
        _row(labels[0], f"({_q('p1', num(p[0], '.1f', 1e3))}, {_q('p2', num(p[1], '.1f', 1e3))})", "mm"),
        _row(labels[1], f"{_q('d1', num(d[0], '.1f', 1e3))}, {_q('d2', num(d[1], '.1f', 1e3))}", "mm"),
        _row(labels[2], f"{_q('theta1', num(th[0], '.2f'))}, {_q('theta2', num(th[1], '.2f'))}", "deg"),
        _row("det J_x = cos(θ₁+θ₂)", _q("det_jx", num(readout.det_jx, ".4f")), "eq. 12"),
        _row("det J_q = cos θ₁ cos θ₂", _q("det_jq", num(readout.det_jq, ".4f")), "eq. 11"),
        _row(labels[3], _q("cond", num(readout.cond, ".2f")), "eq. 10"),
        _row(labels[4], _q("mode", mode), ""),
    ]
    return f'<table style="font-size:0.85em;border-collapse:collapse;margin-top:6px">{"".join(rows)}</table>'


ROW_LABELS = (
    T("platform p"),
    T("actuators d₁, d₂"),
    T("leg angles θ₁, θ₂"),
    T("condition number of J"),
    T("assembly mode"),
)
"""The dashboard's row labels (the others are formulas, the same in every language)."""


def _bar(value: float | None, scale: float) -> str:
    if value is None or not math.isfinite(float(value)):
        return '<div style="height:10px"></div>'
    frac = min(abs(float(value)) / scale, 1.0) * 50.0
    left = 50.0 if value >= 0 else 50.0 - frac
    color = TAU_POS if value >= 0 else TAU_NEG
    return (
        '<div style="position:relative;height:10px;background:#f1f5f9;border-radius:2px">'
        '<div style="position:absolute;left:50%;top:0;bottom:0;width:1px;background:#94a3b8"></div>'
        f'<div style="position:absolute;left:{left:.2f}%;width:{frac:.2f}%;top:1px;bottom:1px;'
        f'background:{color};border-radius:2px"></div></div>'
    )


def _forces(state: AppState, readout: Readout, lang: Lang) -> str:
    f = readout.forces
    load = state.load
    if load.mode == "static":
        head = say(
            lang,
            Phrase(
                "Static: external load on platform f_ext = ({fx}, {fy}) N; {equation}",
                fx=num(load.f_ext[0], ".1f"),
                fy=num(load.f_ext[1], ".1f"),
                equation=html.escape(say(lang, f.equation)),
            ),
        )
    else:
        head = say(
            lang,
            Phrase(
                "Dynamic: ṗ = ({v1}, {v2}) m/s, p̈ = ({a1}, {a2}) m/s²; {equation}",
                v1=num(load.dp[0], ".3f"),
                v2=num(load.dp[1], ".3f"),
                a1=num(load.ddp[0], ".2f"),
                a2=num(load.ddp[1], ".2f"),
                equation=html.escape(say(lang, f.equation)),
            ),
        )
    tau = [None, None] if f.tau is None else list(f.tau)
    ref = [None, None] if f.tau_ref is None else list(f.tau_ref)
    diff = [None, None] if f.diff is None else list(f.diff)
    scale = force_scale(tau + ref)
    rows = []
    for i in range(2):
        rows.append(
            f'<div style="display:grid;grid-template-columns:1.6em 1fr 5.6em;gap:4px;align-items:center">'
            f"<b>τ{'₁₂'[i]}</b>{_bar(tau[i], scale)}"
            f'<span style="text-align:right;white-space:nowrap">{_q(f"tau{i + 1}", num(tau[i], ".2f"))} N</span></div>'
            f'<div style="font-size:0.9em;color:#475569;margin:0 0 3px 1.9em">'
            + say(
                lang,
                Phrase(
                    "Pinocchio {ref} N, difference {diff} N",
                    ref=_q(f"tau{i + 1}_ref", num(ref[i], ".2f")),
                    diff=_q(f"tau{i + 1}_diff", num(diff[i], ".1e")),
                ),
            )
            + "</div>"
        )
    note = f'<div style="color:#92400e">{html.escape(say(lang, f.note))}</div>' if f.note else ""
    return (
        f'<div style="font-size:0.85em;margin-top:6px"><div style="color:#334155;margin-bottom:3px">'
        f"<b>{html.escape(say(lang, T('Actuator forces')))}</b> "
        + html.escape(say(lang, Phrase("(paper's closed form; bars full scale ±{scale} N)", scale=num(scale, ".0f"))))
        + f"<br>{head}</div>"
        f"{''.join(rows)}{note}</div>"
    )


LEGEND = (
    (hex_colour("workspace"), "workspace: poses inside the stroke (eq. 4, working mode)"),
    (hex_colour("inverse"), "inverse singularity |p_j| = l_a, cos θ_i = 0 (eq. 11); a leg turns amber near it"),
    (hex_colour("direct"), "direct singularity cos(θ₁+θ₂) = 0 (eq. 12); the platform turns red near it"),
    (hex_colour("stroke"), "a slider at its stroke end turns pink"),
    (hex_colour("circle"), "leg constraint circles (radius l_a) and P′, the other assembly mode"),
    (TAU_POS, "force arrow τ_i > 0 (along +e_i)"),
    (TAU_NEG, "force arrow τ_i < 0"),
)


def legend_html() -> Html:
    """The colour legend of the 3D view."""
    rows = "".join(
        f'<div style="display:flex;gap:6px;align-items:baseline"><span style="flex:none;width:10px;height:10px;'
        f'background:{color};border-radius:2px;display:inline-block"></span><span>{html.escape(text)}</span></div>'
        for color, text in LEGEND
    )
    return Html(f'<div style="font-size:0.8em;color:#334155;line-height:1.4;padding:2px 0">{rows}</div>')


def dashboard_html(state: AppState, readout: Readout, lang: Lang = Lang.EN) -> Html:
    """The always-visible top of the panel: banner, kinematic readouts, force bars. Its messages (the alerts, the
    note of the last move, the force note) in ``lang``; its fixed words are shown in the tab's language by the
    tab's connection (:mod:`tpm_viz.ui.language`)."""
    return Html(
        f"<div>{_banner(state, readout, lang)}{_kinematics(readout, lang)}{_forces(state, readout, lang)}</div>"
    )
