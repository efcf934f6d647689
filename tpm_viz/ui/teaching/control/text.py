"""Text of the *Control* tab (HTML): gains, a run's summary, the comparison table and the lesson "why computed
torque", in a tab's language (``lang``; the words are :class:`~tpm_viz.core.words.Phrase` s rendered with ``say``).
Formatting only: every number comes from the runs (through :func:`.text.num`, a dash for NaN or infinity), none is
typed in; every name is escaped."""

from __future__ import annotations

import html

from tpm_viz.app.run_names import reference_words
from tpm_viz.classroom.text import num
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.multibody.control import ControlRun
from tpm_viz.paper.control import ControllerKind, Gains

__all__ = ["LABELS", "comparison_html", "gains_html", "label_of", "lesson_html", "run_html", "setup_phrase"]

LABELS = {ControllerKind.PD: "PD", ControllerKind.PDFF: "PD + feedforward", ControllerKind.CTC: "Computed torque"}
"""The controllers' names: the options of the *Controller* dropdown (fixed texts, in the catalogue)."""
_STYLE = "font-size:0.85em;color:#334155;line-height:1.45"


def label_of(kind: ControllerKind) -> Phrase:
    """The name of a controller as a phrase (rendered from the catalogue, as the dropdown shows it)."""
    return Phrase(LABELS[kind])


def _q(name: str, text: str) -> str:
    """A number in a ``data-q`` span (for the browser tests)."""
    return f"<span data-q='{name}'>{text}</span>"


def gains_html(kind: ControllerKind, gains: Gains, masses: tuple[float, float], lang: Lang = Lang.EN) -> Html:
    """The gains of the chosen law: ``K_p = ω²``, ``K_d = 2ζω`` and, for the actuator-space loops, the stiffness."""
    text = (
        f"ω = 2π ω_n = {num(gains.omega, '.1f')} rad/s, "
        f"K_p = ω² = {_q('kp', num(gains.kp, '.0f'))} 1/s², "
        f"K_d = 2ζω = {_q('kd', num(gains.kd, '.1f'))} 1/s"
    )
    if kind is ControllerKind.CTC:
        more = T("computed torque: τ = ID(p, ṗ, p̈_ref + K_d ė + K_p e), the closed form at the measured state")
        text += "<br>" + html.escape(say(lang, more))
    else:
        m1, m2 = masses
        stiffness = Phrase(
            "per actuator: m_i = {m1}, {m2} kg (model at p = 0), stiffness m_i K_p = {k1}, {k2} N/mm",
            m1=num(m1, ".3f"),
            m2=num(m2, ".3f"),
            k1=num(m1 * gains.kp, ".1f", 1e-3),
            k2=num(m2 * gains.kp, ".1f", 1e-3),
        )
        text += "<br>" + html.escape(say(lang, stiffness))
        if kind is ControllerKind.PDFF:
            feedforward = T("plus the closed-form τ along the reference (eqs. 29-31) as feedforward")
            text += "<br>" + html.escape(say(lang, feedforward))
    return Html(f'<div data-q="gains" style="{_STYLE}">{text}</div>')


def setup_phrase(run: ControlRun) -> Phrase:
    """The setup of a run in one line (reference, gains, mismatch, limits, noise), for the comparison table."""
    s = run.setup
    limit = T("no force limit") if s.force_limit is None else Phrase("limit {limit:g} N", limit=s.force_limit)
    return Phrase(
        "{name}, ω_n {wn:g} Hz, ζ {zeta:g}, payload {payload:g} kg, mass error {error} %, {limit}, {rate:g} Hz, "
        "noise {noise:g} µm",
        name=reference_words(run.name),
        wn=s.gains.wn,
        zeta=s.gains.zeta,
        payload=s.payload,
        error=num(s.mass_error[0], "+g", 100),
        limit=limit,
        rate=s.rate,
        noise=s.noise * 1e6,
    )


def run_html(
    run: ControlRun | None,
    seconds: float | None,
    busy: str | Phrase = "",
    status: str | Phrase = "",
    lang: Lang = Lang.EN,
) -> Html:
    """The run being played: its figures, how long it took to simulate, what is computing, why it stopped."""
    esc = html.escape
    lines = []
    if busy:
        lines.append(f"<i>{esc(say(lang, busy))}</i>")
    if status:
        lines.append(f'<span style="color:#991b1b">{esc(say(lang, status))}</span>')
    if run is None:
        if not lines:
            lines.append(say(lang, T("No run yet: choose a controller and a reference, then press <b>Simulate</b>.")))
    else:
        s = run.setup
        head = Phrase(
            "<b>{controller}</b> on {name}, {t} s at {rate} Hz",
            controller=esc(say(lang, label_of(s.controller))),
            name=esc(say(lang, reference_words(run.name))),
            t=num(run.t[-1], ".3f"),
            rate=num(s.rate, ".0f"),
        )
        took = Phrase(" (simulated in {ms} ms)", ms=_q("sim-ms", num(seconds, ".0f", 1e3))) if seconds else ""
        lines.append(say(lang, head) + say(lang, took))
        figures = Phrase(
            "RMS error {rms} µm, max {max} µm, peak |τ| {peak} N, saturated {saturated} ms",
            rms=_q("run-rms", num(run.rms_error, ".2f", 1e6)),
            max=num(run.max_error, ".2f", 1e6),
            peak=num(run.peak_force, ".1f"),
            saturated=num(run.time_in_saturation, ".1f", 1e3),
        )
        lines.append(say(lang, figures))
    return Html(f'<div data-q="control-run" style="{_STYLE}">' + "<br>".join(lines) + "</div>")


_HEADS = (T("controller"), T("RMS error (µm)"), T("max error (µm)"), T("peak |τ| (N)"), T("saturated (ms)"))


def comparison_html(runs: dict[ControllerKind, ControlRun], setup: str | Phrase, lang: Lang = Lang.EN) -> Html:
    """The controllers on the same run (same reference, mechanism, mismatch, limits and noise)."""
    if not runs:
        return Html("")
    cell = "padding:2px 4px;text-align:right;font-variant-numeric:tabular-nums"
    head = "".join(f'<th style="{cell}">{html.escape(say(lang, h))}</th>' for h in _HEADS)
    body = []
    for kind in ControllerKind:
        run = runs.get(kind)
        if run is None:
            continue
        v = kind.value
        body.append(
            f'<tr><td style="padding:2px 4px">{html.escape(say(lang, label_of(kind)))}</td>'
            f'<td style="{cell}" data-q="rms-{v}">{num(run.rms_error, ".2f", 1e6)}</td>'
            f'<td style="{cell}" data-q="max-{v}">{num(run.max_error, ".2f", 1e6)}</td>'
            f'<td style="{cell}" data-q="peak-{v}">{num(run.peak_force, ".1f")}</td>'
            f'<td style="{cell}" data-q="sat-{v}">{num(run.time_in_saturation, ".1f", 1e3)}</td></tr>'
        )
    title = html.escape(say(lang, T("Same run, each controller")))
    return Html(
        f'<div data-q="control-table" style="{_STYLE}"><b>{title}</b> '
        f'<span style="color:#64748b">({html.escape(say(lang, setup))})</span>'
        f'<div style="overflow-x:auto"><table style="border-collapse:collapse;margin-top:4px">'
        f"<tr>{head}</tr>{''.join(body)}</table></div></div>"
    )


def _ratio(a: float, b: float) -> Phrase | str:
    """``a / b`` as "3.2× smaller" / "1.4× larger" (by the numbers)."""
    if not (a > 0 and b > 0):
        return "—"
    if a > b:
        return Phrase("{ratio}× smaller", ratio=num(a / b, ".2g"))
    return Phrase("{ratio}× larger", ratio=num(b / a, ".2g"))


def lesson_html(
    runs: dict[ControllerKind, ControlRun], payload: float, mass_error: float, lang: Lang = Lang.EN
) -> Html:
    """The lesson "why computed torque", its claims worded from the three runs' numbers."""
    pd, ff, ctc = (runs.get(k) for k in (ControllerKind.PD, ControllerKind.PDFF, ControllerKind.CTC))
    if pd is None or ff is None or ctc is None:
        return Html("")
    e = {k: r.rms_error for k, r in runs.items()}
    best = min(e, key=lambda k: e[k])
    payload_words = Phrase("a payload of {mass} kg the controllers do not know", mass=num(payload, ".2f"))
    error_words = Phrase("masses {error} % off in their model", error=num(mass_error, "+.0f", 100))
    if payload > 0 and mass_error:
        mismatch: Phrase = Phrase("{first} and {second}", first=payload_words, second=error_words)
    elif payload > 0:
        mismatch = payload_words
    elif mass_error:
        mismatch = error_words
    else:
        mismatch = T("an exact model (add a payload to see the difference)")
    paras = [
        Phrase("Same reference, same gains, {mismatch}.", mismatch=mismatch),
        Phrase(
            "<b>PD</b> makes force only from the error, so it must lag to push: RMS error {rms} µm, peak |τ| {peak} N.",
            rms=num(e[ControllerKind.PD], ".1f", 1e6),
            peak=num(pd.peak_force, ".1f"),
        ),
        Phrase(
            "<b>PD + feedforward</b> adds the closed-form force along the reference; the feedback is left with what "
            "the model misses: RMS {rms} µm, {ratio} than PD.",
            rms=num(e[ControllerKind.PDFF], ".1f", 1e6),
            ratio=_ratio(e[ControllerKind.PD], e[ControllerKind.PDFF]),
        ),
        Phrase(
            "<b>Computed torque</b> evaluates the model at the <i>measured</i> state and turns the feedback into an "
            "acceleration, so the error obeys ë + K_d ė + K_p e ≈ 0 whatever the pose: RMS {rms} µm, {ratio} than "
            "PD + feedforward.",
            rms=num(e[ControllerKind.CTC], ".1f", 1e6),
            ratio=_ratio(e[ControllerKind.PDFF], e[ControllerKind.CTC]),
        ),
        Phrase(
            "Smallest error here: <b>{best}</b>. The paper derived its closed form “for the real-time computed "
            "torque control” (Sections 1, 3, 5): these are the figures behind that.",
            best=html.escape(say(lang, label_of(best))),
        ),
    ]
    return Html(
        f'<div data-q="lesson" style="{_STYLE}">'
        + "".join(f"<p style='margin:0 0 4px 0'>{say(lang, p)}</p>" for p in paras)
        + "</div>"
    )
