"""Text of the player's summary line (HTML): formatting only, every number through :func:`.text.num` (a dash
for NaN or infinity), every name escaped, every word a :class:`~tpm_viz.core.words.Phrase` rendered in the tab's
language. Forces are per actuator: the peak is ``max_i |τ_i|`` over the run, written ``|τ_i|`` (never a norm)."""

from __future__ import annotations

import html

from tpm_viz.app.run_names import label_words
from tpm_viz.classroom.text import num
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, Phrase, T, say

__all__ = ["summary_html"]

_WHERE = {
    "playing": T("playing"),
    "off": T("not on the path (moved by hand): press Play or move the time slider"),
    "paused": T("paused"),
}


def summary_html(ps, run, t, lang: Lang = Lang.EN) -> Html:
    """The player's summary: what is loaded or computing, its peak force and Pinocchio difference, the
    previous run's peak, and where the playback is (``t`` [s], None when the platform left the path)."""
    esc = html.escape
    lines = []
    if ps.loading is not None:
        computing = Phrase("Computing {name} (closed form and Pinocchio)…", name=label_words(ps.loading.label))
        lines.append(f"<i>{esc(say(lang, computing))}</i>")
    if ps.status:
        lines.append(f'<span style="color:#991b1b">{esc(say(lang, ps.status))}</span>')
    if run is None:
        if not lines:
            lines.append(esc(say(lang, T("No trajectory loaded: choose one above or upload a CSV."))))
    else:
        diff = run.max_diff
        peak = f"<span data-q='run-peak'>{num(run.peak, '.1f')}</span>"
        name = f"<b>{esc(say(lang, label_words(run.source.label)))}</b>"
        lines.append(say(lang, Phrase("{name}: peak |τ_i| = {peak} N (closed form)", name=name, peak=peak)))
        gap = (
            f"<span data-q='run-diff'>{num(diff, '.1e')}</span> N" if diff is not None else esc(say(lang, run.ref_note))
        )
        lines.append(say(lang, Phrase("Pinocchio − paper: max |Δτ_i| = {gap}", gap=gap)))
        if ps.previous is not None:
            label, before = ps.previous
            previous = Phrase(
                "Previous run: {name}, peak {peak} N", name=esc(say(lang, label_words(label))), peak=num(before, ".1f")
            )
            text = say(lang, previous)
            if before > 0:
                text += say(lang, Phrase(" (this / previous = {ratio})", ratio=num(run.peak / before, ".3f")))
            lines.append(text)
        where = "playing" if ps.playing else "off" if t is None else "paused"
        t_text = f"<span data-q='player-t'>{num(t, '.3f') if t is not None else '—'}</span>"
        lines.append(
            say(
                lang,
                Phrase(
                    "t = {t} s of {duration} s, {where}",
                    t=t_text,
                    duration=num(run.duration, ".3f"),
                    where=say(lang, _WHERE[where]),
                ),
            )
        )
    return Html('<div style="font-size:0.85em;color:#334155;line-height:1.45">' + "<br>".join(lines) + "</div>")
