"""Text of the *Control* tab (HTML): gains, a run's summary, the comparison table and the lesson "why computed
torque". Formatting only: every number comes from the runs (through :func:`.text.num`, a dash for NaN or infinity),
none is typed in; every name is escaped."""

from __future__ import annotations

import html

from tpm_viz.multibody.control import ControlRun
from tpm_viz.paper.control import ControllerKind, Gains
from tpm_viz.ui.text import num

__all__ = ["LABELS", "comparison_html", "gains_html", "lesson_html", "run_html"]

LABELS = {ControllerKind.PD: "PD", ControllerKind.PDFF: "PD + feedforward", ControllerKind.CTC: "Computed torque"}
_STYLE = "font-size:0.85em;color:#334155;line-height:1.45"


def gains_html(kind: ControllerKind, gains: Gains, masses: tuple[float, float]) -> str:
    """The gains of the chosen law: ``K_p = ω²``, ``K_d = 2ζω`` and, for the actuator-space loops, the stiffness."""
    text = (
        f"ω = 2π ω_n = {num(gains.omega, '.1f')} rad/s, "
        f"K_p = ω² = <span data-q='kp'>{num(gains.kp, '.0f')}</span> 1/s², "
        f"K_d = 2ζω = <span data-q='kd'>{num(gains.kd, '.1f')}</span> 1/s"
    )
    if kind is ControllerKind.CTC:
        text += "<br>computed torque: τ = ID(p, ṗ, p̈_ref + K_d ė + K_p e), the closed form at the measured state"
    else:
        m1, m2 = masses
        text += (
            f"<br>per actuator: m_i = {num(m1, '.3f')}, {num(m2, '.3f')} kg (model at p = 0), stiffness m_i K_p = "
            f"{num(m1 * gains.kp, '.1f', 1e-3)}, {num(m2 * gains.kp, '.1f', 1e-3)} N/mm"
        )
        if kind is ControllerKind.PDFF:
            text += "<br>plus the closed-form τ along the reference (eqs. 29-31) as feedforward"
    return f'<div data-q="gains" style="{_STYLE}">{text}</div>'


def _saturation(run: ControlRun) -> str:
    return f"{num(run.time_in_saturation, '.1f', 1e3)} ms"


def run_html(run: ControlRun | None, seconds: float | None, busy: str = "", status: str = "") -> str:
    """The run being played: its figures, how long it took to simulate, what is computing, why it stopped."""
    esc = html.escape
    lines = []
    if busy:
        lines.append(f"<i>{esc(busy)}</i>")
    if status:
        lines.append(f'<span style="color:#991b1b">{esc(status)}</span>')
    if run is None:
        if not lines:
            lines.append("No run yet: choose a controller and a reference, then press <b>Simulate</b>.")
    else:
        s = run.setup
        lines.append(
            f"<b>{esc(LABELS[s.controller])}</b> on {esc(run.name)}, "
            f"{num(run.t[-1], '.3f')} s at {num(s.rate, '.0f')} Hz"
            + (f" (simulated in <span data-q='sim-ms'>{num(seconds, '.0f', 1e3)}</span> ms)" if seconds else "")
        )
        lines.append(
            f"RMS error <span data-q='run-rms'>{num(run.rms_error, '.2f', 1e6)}</span> µm, max "
            f"{num(run.max_error, '.2f', 1e6)} µm, peak |τ| {num(run.peak_force, '.1f')} N, "
            f"saturated {_saturation(run)}"
        )
    return f'<div data-q="control-run" style="{_STYLE}">' + "<br>".join(lines) + "</div>"


def comparison_html(runs: dict[ControllerKind, ControlRun], setup_text: str) -> str:
    """The controllers on the same run (same reference, mechanism, mismatch, limits and noise)."""
    if not runs:
        return ""
    cell = "padding:2px 6px;text-align:right;font-variant-numeric:tabular-nums"
    head = "".join(
        f'<th style="{cell}">{h}</th>'
        for h in ("controller", "RMS error (µm)", "max error (µm)", "peak |τ| (N)", "saturated (ms)")
    )
    body = []
    for kind in ControllerKind:
        run = runs.get(kind)
        if run is None:
            continue
        v = kind.value
        body.append(
            f'<tr><td style="padding:2px 6px">{html.escape(LABELS[kind])}</td>'
            f'<td style="{cell}" data-q="rms-{v}">{num(run.rms_error, ".2f", 1e6)}</td>'
            f'<td style="{cell}" data-q="max-{v}">{num(run.max_error, ".2f", 1e6)}</td>'
            f'<td style="{cell}" data-q="peak-{v}">{num(run.peak_force, ".1f")}</td>'
            f'<td style="{cell}" data-q="sat-{v}">{num(run.time_in_saturation, ".1f", 1e3)}</td></tr>'
        )
    return (
        f'<div data-q="control-table" style="{_STYLE}"><b>Same run, each controller</b> '
        f'<span style="color:#64748b">({html.escape(setup_text)})</span>'
        f'<table style="border-collapse:collapse;margin-top:4px"><tr>{head}</tr>{"".join(body)}</table></div>'
    )


def _ratio(a: float, b: float) -> str:
    """``a / b`` as "3.2× smaller" / "1.4× larger" (by the numbers)."""
    if not (a > 0 and b > 0):
        return "—"
    return f"{num(a / b, '.2g')}× smaller" if a > b else f"{num(b / a, '.2g')}× larger"


def lesson_html(runs: dict[ControllerKind, ControlRun], payload: float, mass_error: float) -> str:
    """The lesson "why computed torque", its claims worded from the three runs' numbers."""
    pd, ff, ctc = (runs.get(k) for k in (ControllerKind.PD, ControllerKind.PDFF, ControllerKind.CTC))
    if pd is None or ff is None or ctc is None:
        return ""
    e = {k: r.rms_error for k, r in runs.items()}
    best = min(e, key=lambda k: e[k])
    parts = [f"a payload of {num(payload, '.2f')} kg the controllers do not know"] if payload > 0 else []
    if mass_error:
        parts.append(f"masses {num(mass_error, '+.0f', 100)} % off in their model")
    mismatch = " and ".join(parts) if parts else "an exact model (add a payload to see the difference)"
    paras = [
        f"Same reference, same gains, {mismatch}.",
        f"<b>PD</b> makes force only from the error, so it must lag to push: RMS error "
        f"{num(e[ControllerKind.PD], '.1f', 1e6)} µm, peak |τ| {num(pd.peak_force, '.1f')} N.",
        f"<b>PD + feedforward</b> adds the closed-form force along the reference; the feedback is left with what the "
        f"model misses: RMS {num(e[ControllerKind.PDFF], '.1f', 1e6)} µm, "
        f"{_ratio(e[ControllerKind.PD], e[ControllerKind.PDFF])} than PD.",
        f"<b>Computed torque</b> evaluates the model at the <i>measured</i> state and turns the feedback into an "
        f"acceleration, so the error obeys ë + K_d ė + K_p e ≈ 0 whatever the pose: RMS "
        f"{num(e[ControllerKind.CTC], '.1f', 1e6)} µm, {_ratio(e[ControllerKind.PDFF], e[ControllerKind.CTC])} than "
        f"PD + feedforward.",
        f"Smallest error here: <b>{html.escape(LABELS[best])}</b>. The paper derived its closed form "
        "“for the real-time computed torque control” (Sections 1, 3, 5): these are the figures behind that.",
    ]
    return (
        f'<div data-q="lesson" style="{_STYLE}">'
        + "".join(f"<p style='margin:0 0 4px 0'>{p}</p>" for p in paras)
        + "</div>"
    )
