"""The offline lesson page: one self-contained HTML file, assembled from its parts (no viser, no network).

:func:`lesson_page` writes the page from a :class:`PageContent`: the 3D view is viser's client with the lesson's
recording (:mod:`tpm_viz.ui.takehome`) in an ``<iframe srcdoc>`` (its own document, so that viser's styles and the
page's do not meet; same origin, so the page reads the player's time slider); beside it the lesson's text, the
calculator panel (``page_calc.js`` over ``window.tpm``, the closed form as WebAssembly:
:func:`tpm_viz.exchange.c.calculator.calculator_assets`), the exercises (``page_exercises.js`` over the grader of
:mod:`tpm_viz.media.page_grader`) and the SCORM 1.2 adapter (``page_scorm.js``: a no-op outside an LMS). Everything is
inlined; the page's data is one JSON island (``<script type="application/json" id="tpm-page-data">``).

Every text is escaped (a lesson's title, text and prompts may come from a lecturer's folder); no inlined script or
JSON contains ``</`` or ``<!--`` (their ``<`` is written ``\\u003c``). The texts the page shows are rendered here in
the page's language; those its scripts fill in are :data:`PAGE_WORDS` (their Korean written into the JSON).
"""

from __future__ import annotations

import html
import importlib.metadata
import json
from dataclasses import dataclass, field
from typing import Any

from tpm_viz.app.transitions import MAX_ACCEL, MAX_POSITION, MAX_SPEED
from tpm_viz.core.words import Lang, Phrase, T, catalogue
from tpm_viz.media.page_grader import grader_script, read_script
from tpm_viz.media.page_parts import calculator_html, exercise_html, legend_html, static_words

__all__ = ["PAGE_WORDS", "PASS_PERCENT", "POLICY", "SCRIPTS", "PageContent", "lesson_page", "safe_json", "version"]

PASS_PERCENT = 80
"""Score [%] at which the SCORM adapter reports ``passed`` once every graded exercise has an attempt, when the LMS
gives no mastery score of its own (``cmi.student_data.mastery_score``)."""
SCRIPTS = ("page_calc.js", "page_exercises.js", "page_scorm.js")
"""The page's own scripts in ``tpm_viz/media/``, in the order they run (after the calculator and the grader)."""
STYLE = "page.css"
POLICY = (
    "default-src 'none'; script-src 'unsafe-inline' 'unsafe-eval' 'wasm-unsafe-eval'; style-src 'unsafe-inline'; "
    "img-src data: blob:; font-src data:; worker-src blob:; connect-src data: blob:; base-uri 'none'; "
    "form-action 'none'"
)
"""The page's Content-Security-Policy: nothing from the network, ever (scripts, styles, images, fonts, workers and
fetches only from the page itself, ``data:`` or ``blob:``; viser's client needs ``eval`` and WebAssembly). The
srcdoc 3D view inherits it."""

PAGE_WORDS: tuple[Phrase, ...] = (
    T("Score: {x} / {y}"),
    T("at t = {t} s of {T} s"),
    T("attempts left: {n}"),
    T("no attempts left"),
    T("not graded, no attempt used: {why}"),
    T("attempt {k}: score {score}; best {best}"),
    T("leg {i} is near its inverse singularity (|cos θ{i}| < {limit})"),
    T("near the direct singularity (|det J_x| < {limit})"),
)
"""The templates the page's scripts fill in (``W("...")`` in ``page_calc.js`` and ``page_exercises.js``)."""


@dataclass(frozen=True)
class PageContent:
    """What one page shows (SI units): the lesson (``number``, ``key``, ``title``, ``text``), viser's client with its
    recording (``viser_html``) and the frames' states (``frames``: ``t``, ``p``, ``dp``, ``ddp`` lists), the
    mechanism's ``params`` (the calculator's), the calculator's HTML (``calculator``), the exercises
    (:func:`tpm_viz.media.page_exercises.lesson_exercises`), the variant ``seed`` and the language."""

    lang: Lang
    seed: int
    number: int
    key: str
    title: str
    text: str
    viser_html: str
    calculator: str
    params: dict[str, float]
    frames: dict[str, list[Any]]
    exercises: list[dict[str, Any]] = field(default_factory=list)
    version: str = ""


def version() -> str:
    """The installed tpm-viz version (``"unknown"`` when it is not installed), for the page's ``generator``."""
    try:
        return importlib.metadata.version("tpm-viz")
    except importlib.metadata.PackageNotFoundError:
        return "unknown"


def safe_json(value: object) -> str:
    """``value`` as JSON that can sit in a ``<script>`` element (every ``<`` as ``\\u003c``; NaN refused)."""
    return json.dumps(value, ensure_ascii=False, allow_nan=False, sort_keys=True).replace("<", "\\u003c")


def _data(content: PageContent) -> dict[str, Any]:
    ko = catalogue(Lang.KO) if content.lang is Lang.KO else {}
    return {
        "lang": content.lang.value,
        "seed": content.seed,
        "lesson": {"number": content.number, "key": content.key, "title": content.title},
        "storage_key": f"tpm-viz:page:{content.key}:{content.seed}",
        "params": content.params,
        "frames": content.frames,
        "limits": {"p_mm": MAX_POSITION * 1e3, "dp": MAX_SPEED, "ddp": MAX_ACCEL},
        "exercises": content.exercises,
        "pass_percent": PASS_PERCENT,
        "words": {p.template: ko.get(p.template, p.template) for p in PAGE_WORDS},
    }


def _script(text: str) -> str:
    lowered = text.lower()
    assert "</script" not in lowered and "<!--" not in lowered, "an inlined script must not close its element"
    return f"<script>\n{text}</script>\n"


def _head(content: PageContent, words: dict[str, str]) -> str:
    return (
        f'<!doctype html>\n<html lang="{content.lang.value}">\n<head>\n<meta charset="utf-8">\n'
        f'<meta http-equiv="Content-Security-Policy" content="{POLICY}">\n'
        '<meta name="viewport" content="width=device-width, initial-scale=1">\n'
        f'<meta name="generator" content="tpm-viz {html.escape(content.version)}">\n'
        f"<title>{words['page_title']}</title>\n<style>\n{read_script(STYLE)}</style>\n</head>\n"
    )


def _side(content: PageContent, words: dict[str, str]) -> str:
    """The panel beside the 3D view: the title and score, the lesson, the calculator, the exercises."""
    lang = content.lang
    graded = sum(1 for entry in content.exercises if entry["graded"])
    cards = "".join(exercise_html(entry, lang) for entry in content.exercises)
    return (
        '<aside class="tpm-side">\n<header class="tpm-head">\n'
        f"<h1>{html.escape(content.title)}</h1>\n"
        f'<p class="tpm-meta"><span>{words["lesson"]}</span> · <span class="tpm-seed" data-seed="{content.seed}">'
        f'{words["seed"]}</span> · <b id="tpm-score" data-graded="{graded}"></b></p>\n'
        f'<p class="tpm-note">{words["offline"]}</p>\n<noscript><p>{words["noscript"]}</p></noscript>\n</header>\n'
        f'<section id="tpm-lesson"><h2>{words["the_lesson"]}</h2>\n'
        f'<p class="tpm-text">{html.escape(content.text)}</p>\n{legend_html(lang)}</section>\n'
        f"{calculator_html(len(content.frames['t']) > 1, lang)}"
        + (
            f'<section id="tpm-exercises"><h2>{words["exercises"]}</h2>\n'
            f'<p class="tpm-score-line" id="tpm-score-line"></p>\n<p class="tpm-note">{words["kept"]}</p>\n'
            f"{cards}</section>\n"
            if content.exercises
            else ""
        )
        + "</aside>\n"
    )


def lesson_page(content: PageContent) -> str:
    """The whole page as HTML text (module docstring). The panel and its scripts come first in the document, the 3D
    view last (drawn on the left, or above on a phone): the panel is ready before viser's client starts, which takes
    seconds on a slow machine."""
    words = static_words(content.title, content.number, content.seed, content.lang)
    view = html.escape(content.viser_html, quote=True)
    scripts = [grader_script(content.lang), *(read_script(name) for name in SCRIPTS)]
    return (
        f"{_head(content, words)}<body>\n"
        f'<div class="tpm-page" data-lesson="{content.number}" data-seed="{content.seed}">\n{_side(content, words)}'
        f'<script type="application/json" id="tpm-page-data">{safe_json(_data(content))}</script>\n'
        f"{content.calculator}" + "".join(_script(text) for text in scripts) + '<main class="tpm-view">'
        f'<iframe id="tpm-view" title="{words["view"]}" srcdoc="{view}"></iframe></main>\n</div>\n</body>\n</html>\n'
    )
