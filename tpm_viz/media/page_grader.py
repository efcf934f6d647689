"""The exercise grader of the offline lesson page: ``page_grader.js`` and the configuration written into it.

``page_grader.js`` (in this folder, package data) ports the reading and grading rules of
:mod:`tpm_viz.app.exercises` for ``number``, ``pose`` and ``choice`` answers (``docs/exercises.md``, "What a JavaScript
port needs"); ``docs/takehome.md`` says which rules it covers. What the script cannot know from the language alone is
written in by :func:`grader_script`, from the library itself, so that the two never drift:

- the page's language and the Korean template of every phrase it renders (:data:`WORDS`, each one the library's own:
  :mod:`tpm_viz.core.numbers`, :mod:`tpm_viz.app.exercises.answers`, :mod:`~tpm_viz.app.exercises.tasks`,
  :mod:`~tpm_viz.app.exercises.grading`; a test checks that the script's ``P("...")`` literals are exactly these);
- Python's character classes the reader relies on: ``str.isspace`` (``strip``, ``split``, ``\\s``), the Unicode
  decimal digits ``float()`` reads (as the first code point of each run of ten) and the other ``str.isdigit``
  characters (``²``);
- the units table (:data:`tpm_viz.core.numbers.UNITS`, their SI units and quantity words).
"""

from __future__ import annotations

import functools
import json
import sys
import unicodedata
from importlib import resources

from tpm_viz.core import numbers
from tpm_viz.core.words import Lang, Phrase, T, catalogue

__all__ = ["SCRIPT", "WORDS", "grader_config", "grader_script", "read_script"]

SCRIPT = "page_grader.js"
"""The script's file name in ``tpm_viz/media/``."""
_SLOT = "/*@tpm-grader-config@*/ null"

WORDS: tuple[Phrase, ...] = (
    # tpm_viz.core.numbers: parse_number, parse_quantity, unit_factor
    T("{name} [{unit}]"),
    T("{label} is empty: type a number such as 0.25, 0,25 or 2.5e-1"),
    T("{label}: {text} is too long for a number ({n} characters; at most {most})"),
    T(
        "{label}: {text} mixes separators; write the number without thousands separators, with one decimal point "
        "or comma (1234.5 or 1234,5)"
    ),
    T("{label}: {text} is not a number (examples: 0.25, 0,25, -1.5e-3)"),
    T("{label}: {text} is too large (beyond ±1.8e308)"),
    T("{label}: {text} is not finite; type a finite number"),
    T("{label}: {unit} does not fit: type the number alone"),
    T("{label} has an unknown unit {unit} (use {si})"),
    T("{label} has an unknown unit {unit}"),
    T("{label} has an unknown unit {unit} (use {si} or {alt})"),
    T("{label}: {unit} is a {kind} unit, but {name} takes no unit"),
    T("{label}: {unit} is a {kind} unit, but {name} is a {quantity} in {si}"),
    # tpm_viz.app.exercises.answers
    T("the answer"),
    T("the answer must be text, got {got}"),
    T("the answer is too long ({n} characters; at most {most})"),
    T("the answer is empty: type it in the box"),
    T("type {n} numbers separated by ';' (for example {example})"),
    T("type the number of an option: {options}"),
    # tpm_viz.app.exercises.tasks: the pose rules
    T("({x}, {y}) mm is out of reach: each |p_j| must be below l_a = {l_a} mm"),
    T("at ({x}, {y}) mm actuator {i} would be at d{i} = {d} mm, outside the stroke 0 to {stroke} mm"),
    T(
        "({x}, {y}) mm is in the other assembly mode (det J_x = {det}, beyond the red arc): give a pose of the "
        "working mode"
    ),
    T("({x}, {y}) mm is near the inverse singularity (cos θ{i} = {cos}, below {limit}): choose a pose clear of it"),
    T("({x}, {y}) mm is near the direct singularity (det J_x = {det}, below {limit}): choose a pose clear of it"),
    # tpm_viz.app.exercises.grading
    T("correct"),
    T("incorrect"),
    T("correct: {symbol} = {value} {unit} at ({p1}, {p2}) mm"),
    T("{symbol} = {value} {unit} at ({p1}, {p2}) mm; it must be {target} within {tol} {unit}"),
    # tpm_viz.ui.widgets.typed.Quantity.read: a typed vector's bounds (the page's calculator, page_calc.js)
    T("{name}: {value}{unit} is out of range; type a value from {lo} to {hi}{unit}"),
)
"""Every template ``page_grader.js`` renders (``P("...")`` in the script, and ``tpmGrader.P("...")`` in the
calculator panel's ``page_calc.js``), besides the quantity words of :data:`tpm_viz.core.numbers.UNITS` (``length``,
``force``, ...) that it takes from its configuration."""


@functools.cache
def _characters() -> tuple[str, list[int], str]:
    """Python's whitespace, the starts of the runs of decimal digits, the other digits (this Python's Unicode)."""
    spaces, starts, digitish = [], [], []
    for cp in range(sys.maxunicode + 1):
        ch = chr(cp)
        if ch.isspace():
            spaces.append(ch)
        if unicodedata.decimal(ch, -1) == 0:
            assert all(unicodedata.decimal(chr(cp + k), -1) == k for k in range(10)), hex(cp)
            starts.append(cp)
        elif ch.isdigit() and not ch.isdecimal():
            digitish.append(ch)
    return "".join(spaces), starts, "".join(digitish)


def grader_config(lang: Lang) -> dict[str, object]:
    """The configuration ``page_grader.js`` needs (module docstring), for a page in ``lang``."""
    spaces, starts, digitish = _characters()
    quantities = {q: word.template for q, word in numbers._QUANTITY.items()}
    ko = catalogue(Lang.KO)
    templates = [p.template for p in WORDS] + list(quantities.values())
    return {
        "lang": lang.value,
        "ko": {t: ko[t] for t in templates if t in ko} if lang is Lang.KO else {},
        "spaces": spaces,
        "decimal_starts": starts,
        "digitish": digitish,
        "units": {key: list(entry) for key, entry in numbers.UNITS.items()},
        "si": dict(numbers._SI),
        "alt": dict(numbers._ALT),
        "quantities": quantities,
    }


def read_script(name: str) -> str:
    """A script or style of the page (``tpm_viz/media/<name>``, package data)."""
    return (resources.files("tpm_viz.media") / name).read_text(encoding="utf-8")


def grader_script(lang: Lang) -> str:
    """``page_grader.js`` with :func:`grader_config` written in (ASCII JSON, so no text can close the page's
    ``<script>``)."""
    source = read_script(SCRIPT)
    assert source.count(_SLOT) == 1, f"{SCRIPT}: one configuration slot {_SLOT!r}"
    config = json.dumps(grader_config(lang), ensure_ascii=True, sort_keys=True).replace("<", "\\u003c")
    return source.replace(_SLOT, config)
