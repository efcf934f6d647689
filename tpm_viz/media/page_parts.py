"""The parts of the offline lesson page that are written once, in the page's language (:mod:`.page_html`).

Every text here is a phrase with its Korean in ``assets/words/ko.toml``, rendered and then escaped; the scripts find
their elements by ``id`` and ``data-`` attributes (:func:`calculator_html`: ``data-q`` of each field and each number;
:func:`exercise_html`: one ``<section class="tpm-exercise" data-exercise=ID data-seed=S data-kind=K>`` per exercise).
"""

from __future__ import annotations

import html
from typing import Any

from tpm_viz.core.words import Lang, Phrase, T
from tpm_viz.drawing.palette import PALETTE

__all__ = ["calculator_html", "exercise_html", "legend_html", "static_words"]


def _say(lang: Lang, phrase: Phrase) -> str:
    return html.escape(phrase.render(lang))


def static_words(title: str, number: int, seed: int, lang: Lang) -> dict[str, str]:
    """The page's fixed texts in ``lang`` for lesson ``number`` (``title``) and variant ``seed``, escaped, by slot."""
    words = {
        "page_title": Phrase("{title} · tpm-viz offline page", title=title),
        "view": T("The lesson's motion in 3D (viser's player: play, pause, time slider)"),
        "lesson": Phrase("Lesson {n}", n=number),
        "seed": Phrase("Variant (seed) {seed}", seed=seed),
        "offline": T("Works offline: this page makes no network request."),
        "noscript": T("This page needs JavaScript for the 3D view, the calculator and the exercises."),
        "the_lesson": T("The lesson"),
        "exercises": T("Exercises"),
        "kept": T(
            "Your attempts and score are kept in this browser (and reported to the LMS when the page runs in one). "
            "A format error uses no attempt."
        ),
    }
    return {slot: _say(lang, phrase) for slot, phrase in words.items()}


def _hex(rgb: tuple[int, int, int]) -> str:
    return "#{:02x}{:02x}{:02x}".format(*(int(c) for c in rgb))


def legend_html(lang: Lang) -> str:
    """The colours of the 3D view, as the app names them."""
    items = (
        ("workspace", T("workspace")),
        ("locus_inverse", T("inverse singularity")),
        ("locus_direct", T("direct singularity")),
        ("stroke", T("stroke end")),
        ("circle", T("other assembly mode P′")),
        ("tau_pos", T("actuator force τ > 0")),
        ("tau_neg", T("actuator force τ < 0")),
    )
    chips = "".join(
        f'<span class="tpm-chip"><i style="background:{_hex(PALETTE[key])}"></i>{_say(lang, word)}</span>'
        for key, word in items
    )
    path = f'<span class="tpm-chip"><i style="background:#eab308"></i>{_say(lang, T("path of P"))}</span>'
    return f'<p class="tpm-legend">{chips}{path}</p>\n'


_NAMES = {
    "p1": "p1 (mm)",
    "p2": "p2 (mm)",
    "dp1": "ṗ1 (m/s)",
    "dp2": "ṗ2 (m/s)",
    "ddp1": "p̈1 (m/s²)",
    "ddp2": "p̈2 (m/s²)",
}


def _field(key: str) -> str:
    return (
        f'<input data-q="{key}" aria-label="{_NAMES[key]}" type="text" inputmode="decimal" autocomplete="off" '
        'spellcheck="false" size="8">'
    )


def _row(label: str, keys: tuple[str, ...], unit: str) -> str:
    cells = ", ".join(f'<output data-q="{k}">—</output>' for k in keys)
    return f"<tr><th>{label}</th><td>{cells}</td><td>{unit}</td></tr>"


def calculator_html(moving: bool, lang: Lang) -> str:
    """The calculator panel: six typed fields (p [mm], ṗ [m/s], p̈ [m/s²]), the player's time (``moving``: the lesson
    has a motion), the refusal line and the numbers of ``window.tpm.evaluate`` as the app's dashboard shows them."""
    follow = (
        f'<label class="tpm-follow"><input type="checkbox" id="tpm-follow" checked> '
        f'{_say(lang, T("Follow the player"))} <span id="tpm-time"></span></label>\n'
        if moving
        else ""
    )
    groups = (
        (T("Platform p (mm)"), ("p1", "p2")),
        (T("Velocity ṗ (m/s)"), ("dp1", "dp2")),
        (T("Acceleration p̈ (m/s²)"), ("ddp1", "ddp2")),
    )
    fields = "".join(
        f'<label class="tpm-pair"><span>{_say(lang, label)}</span>{_field(a)}{_field(b)}</label>'
        for label, (a, b) in groups
    )
    rows = (
        _row(_say(lang, T("actuators d₁, d₂")), ("d1", "d2"), "mm"),
        _row(_say(lang, T("leg angles θ₁, θ₂")), ("theta1", "theta2"), "deg"),
        _row("det J_x = cos(θ₁+θ₂)", ("det_jx",), "eq. 12"),
        _row("det J_q = cos θ₁ cos θ₂", ("det_jq",), "eq. 11"),
        _row(_say(lang, T("condition number of J")), ("cond",), "eq. 10"),
        _row(_say(lang, T("assembly mode")), ("mode",), ""),
        _row(_say(lang, T("Actuator forces")) + " τ₁, τ₂", ("tau1", "tau2"), "N"),
    )
    hint = T(
        "The paper's closed form, computed in this page (the generated C as WebAssembly): type a pose and a motion "
        "(units and decimal commas work), or let the fields follow the player."
    )
    return (
        f'<section id="tpm-calculator"><h2>{_say(lang, T("Calculator"))}</h2>\n'
        f'<p class="tpm-note">{_say(lang, hint)}</p>\n{follow}'
        f'<div class="tpm-fields">{fields}</div>\n'
        '<p class="tpm-refusal" id="tpm-refusal" aria-live="polite"></p>\n'
        '<p class="tpm-warning" id="tpm-warning" aria-live="polite"></p>\n'
        f'<table class="tpm-readout">{"".join(rows)}</table>\n</section>\n'
    )


def _attempts(entry: dict[str, Any], lang: Lang) -> str:
    ladder = entry["ladder"]
    if ladder is None:
        return _say(lang, T("Homework: as many attempts as you like; the best counts."))
    worth = " / ".join(f"{x:g}" for x in ladder)
    return _say(
        lang,
        Phrase("Exam: {n} attempts worth at most {worth} of the score; the best counts.", n=len(ladder), worth=worth),
    )


def exercise_html(entry: dict[str, Any], lang: Lang) -> str:
    """One exercise (an entry of :func:`tpm_viz.media.page_exercises.exercise_entry`): its title, its prompt (the
    seed's), the answer box and the feedback line; a ``gains`` exercise says that it needs the app."""
    ident, seed = html.escape(entry["id"]), entry["seed"]
    head = (
        f'<section class="tpm-exercise" id="ex-{ident}" data-exercise="{ident}" data-seed="{seed}" '
        f'data-kind="{entry["kind"]}">\n<h3>{html.escape(entry["title"])}</h3>\n'
        f'<p class="tpm-prompt">{html.escape(entry["prompt"])}</p>\n'
    )
    if not entry["graded"]:
        needs = Phrase(
            "This answer needs the app: grading it simulates the closed loop. Answer it in the lecture app, or "
            "with tpm-viz exercise grade {id} --seed {seed}.",
            id=entry["id"],
            seed=seed,
        )
        return f'{head}<p class="tpm-needs-app">{_say(lang, needs)}</p>\n</section>\n'
    if entry["kind"] == "choice":
        box = "".join(
            f'<label class="tpm-option"><input type="radio" name="choice-{ident}" value="{n}"> '
            f"{html.escape(option['label'])}</label>"
            for n, option in enumerate(entry["options"], 1)
        )
    else:
        unit = html.escape(entry["unit"])
        box = (
            f'<label class="tpm-answer"><span>{_say(lang, T("Your answer"))}</span>'
            f'<input type="text" class="tpm-answer-text" autocomplete="off" spellcheck="false" maxlength="400">'
            f"<span>{unit}</span></label>"
        )
        if entry["kind"] == "pose":
            use = _say(lang, T("Use the calculator's pose"))
            box += f'<button type="button" class="tpm-use-pose">{use}</button>'
    return (
        f'{head}<div class="tpm-answer-row">{box}<button type="button" class="tpm-check">{_say(lang, T("Check"))}'
        f'</button></div>\n<p class="tpm-feedback" aria-live="polite"></p>\n'
        f'<p class="tpm-attempts">{_attempts(entry, lang)} <span class="tpm-left"></span></p>\n</section>\n'
    )
