"""Text of the player's summary line (HTML): formatting only, every number through :func:`.text.num` (a dash
for NaN or infinity), every name escaped."""

from __future__ import annotations

import html

from tpm_viz.ui.text import num

__all__ = ["summary_html"]


def summary_html(ps, run, t) -> str:
    """The player's summary: what is loaded or computing, its peak force and Pinocchio difference, the
    previous run's peak, and where the playback is (``t`` [s], None when the platform left the path)."""
    esc = html.escape
    lines = []
    if ps.loading is not None:
        lines.append(f"<i>Computing {esc(ps.loading.label)} (closed form and Pinocchio)…</i>")
    if ps.status:
        lines.append(f'<span style="color:#991b1b">{esc(ps.status)}</span>')
    if run is None:
        if not lines:
            lines.append("No trajectory loaded: choose one above or upload a CSV.")
    else:
        diff = run.max_diff
        lines.append(
            f"<b>{esc(run.source.label)}</b>: peak |τ| = <span data-q='run-peak'>{num(run.peak, '.1f')}</span> N "
            "(closed form)"
        )
        lines.append(
            "Pinocchio − paper: max |Δτ| = "
            + (f"<span data-q='run-diff'>{num(diff, '.1e')}</span> N" if diff is not None else esc(run.ref_note))
        )
        if ps.previous is not None:
            label, peak = ps.previous
            ratio = f" (this / previous = {num(run.peak / peak, '.3f')})" if peak > 0 else ""
            lines.append(f"Previous run: {esc(label)}, peak {num(peak, '.1f')} N{ratio}")
        if ps.playing:
            where = "playing"
        elif t is None:
            where = "not on the path (moved by hand): press Play or move the time slider"
        else:
            where = "paused"
        t_text = num(t, ".3f") if t is not None else "—"
        lines.append(f"t = <span data-q='player-t'>{t_text}</span> s of {num(run.duration, '.3f')} s, {where}")
    return '<div style="font-size:0.85em;color:#334155;line-height:1.45">' + "<br>".join(lines) + "</div>"
