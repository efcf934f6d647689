"""Answers as students type them: the text of an answer box -> numbers in the exercise's unit, or a format error.

A format error (:class:`FormatError`) is an answer that cannot be read; it is one line saying what to change and
uses no attempt (PrairieLearn's rule). The rules (a JavaScript port needs exactly these; ``docs/exercises.md``):

1. At most :data:`~tpm_viz.app.exercises.model.MAX_ANSWER` characters.
2. One number: :func:`tpm_viz.core.numbers.parse_quantity` in the exercise's unit: surrounding spaces, ``+``/``-``, the
   Unicode minus, ``1e-3``, a decimal comma (``0,25``), digit groups of three (``1 000``), and any unit of the same
   quantity after the number (``0.15 m`` in mm is 150; ``0,2 kN`` in N is 200; ``30°`` in rad). A unit of another
   quantity, an unknown unit, or a unit where the answer has none, is a format error.
3. Several numbers (``pose``: ``p1, p2`` in mm; ``gains``: ``ω_n`` in Hz, ``ζ`` without unit): one pair of
   enclosing brackets ``( )`` or ``[ ]`` is dropped; then the first of these splits that gives exactly the count
   is used: on ``;``; on ``,``; on ``,`` followed by spaces; on spaces (a unit after a number joins it). So
   ``-35, 20``, ``(-35; 20)``, ``-35 20``, ``-35,5; 20,25``, ``-35,5, 20,25`` and ``-0.035 m, 0.02 m`` all read.
   Each part is read by rule 2; the wrong count is a format error.
4. A pose must be within reach, inside the stroke and in the working assembly mode (``det J_x > 0``), else it is a
   format error (:func:`~tpm_viz.app.exercises.tasks.pose_problem`). Gains: ``0 < ω_n <= 10 000`` Hz,
   ``0 <= ζ <= 100``.
5. A choice: an option's key, its number (1, 2, ...) or its label in either language, ignoring case and
   surrounding spaces.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.exercises.model import MAX_ANSWER, Exercise, Kind, Texts, Variant
from tpm_viz.app.exercises.tasks import pose_problem
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed, parse_quantity
from tpm_viz.core.words import Lang, Phrase, T

__all__ = ["Answer", "FormatError", "read_answer", "split_values"]

MAX_WN = 1e4
"""Largest natural frequency read [Hz]."""
MAX_ZETA = 100.0
"""Largest damping ratio read."""
_BRACKETS = {"(": ")", "[": "]"}
_UNIT_START = re.compile(r"[^0-9+\-\u2212\uff0d.,]")


class FormatError(InputError):
    """An answer that cannot be read: one line saying what to change (no attempt used)."""


@dataclass(frozen=True)
class Answer:
    """An answer as read: ``values`` in the exercise's unit(s), or the ``choice`` (an option key)."""

    values: tuple[float, ...] = ()
    choice: str = ""


def _by_spaces(text: str) -> list[str]:
    """Space-separated parts, a unit joined to the number before it (``-35 mm 20 mm`` -> ``-35 mm``, ``20 mm``)."""
    parts: list[str] = []
    for token in text.split():
        if parts and _UNIT_START.match(token):
            parts[-1] = f"{parts[-1]} {token}"
        else:
            parts.append(token)
    return parts


def split_values(text: str, count: int) -> list[str]:
    """The ``count`` parts of ``text`` by rule 3 of the module docstring, else :class:`FormatError`."""
    s = text.strip()
    if len(s) >= 2 and _BRACKETS.get(s[0]) == s[-1]:
        s = s[1:-1].strip()
    for parts in (s.split(";"), s.split(","), re.split(r",\s+", s), _by_spaces(s)):
        parts = [p.strip() for p in parts]
        if len(parts) == count and all(parts):
            return parts
    example = "-35; 20" if count == 2 else "; ".join(["1"] * count)
    raise FormatError(Phrase("type {n} numbers separated by ';' (for example {example})", n=count, example=example))


def _parse(text: str, name: str | Phrase, unit: str) -> float:
    try:
        return parse_quantity(text, name, unit)
    except InputError as exc:
        raise FormatError(exc.args[0]) from None


def _choice(exercise: Exercise, text: str) -> str:
    typed = text.strip().casefold()
    for number, option in enumerate(exercise.options, 1):
        names = {option.key.casefold(), str(number), option.label.en.strip().casefold()}
        if option.label.ko:
            names.add(option.label.ko.strip().casefold())
        if typed in names:
            return option.key
    listed = Texts(
        *(", ".join(f"{n} ({o.label.get(lang)})" for n, o in enumerate(exercise.options, 1)) for lang in Lang)
    )
    raise FormatError(Phrase("type the number of an option: {options}", options=listed.phrase()))


def read_answer(exercise: Exercise, variant: Variant, text: object) -> Answer:
    """The answer ``text`` as numbers in ``exercise``'s unit(s) (rules in the module docstring), or
    :class:`FormatError` (one line)."""
    if not isinstance(text, str):
        raise FormatError(Phrase("the answer must be text, got {got}", got=type(text).__name__))
    if len(text) > MAX_ANSWER:
        raise FormatError(
            Phrase("the answer is too long ({n} characters; at most {most})", n=len(text), most=MAX_ANSWER)
        )
    if not text.strip():
        raise FormatError(T("the answer is empty: type it in the box"))
    if exercise.kind is Kind.CHOICE:
        return Answer(choice=_choice(exercise, text))
    if exercise.kind is Kind.NUMBER:
        return Answer((_parse(text, T("the answer"), exercise.unit),))
    if exercise.kind is Kind.POSE:
        x, y = (_parse(part, name, "mm") for part, name in zip(split_values(text, 2), ("p1", "p2"), strict=True))
        problem = pose_problem(variant.params, np.array([x, y]) * 1e-3)
        if problem is not None:
            raise FormatError(problem)
        return Answer((x, y))
    wn_text, zeta_text = split_values(text, 2)
    wn, zeta = _parse(wn_text, "ω_n", "Hz"), _parse(zeta_text, "ζ", "")
    if not 0.0 < wn <= MAX_WN:
        raise FormatError(
            Phrase(
                "ω_n must be more than 0 and at most {most} Hz, got {got} Hz",
                most=fixed(MAX_WN, ".0f"),
                got=fixed(wn, "g"),
            )
        )
    if not 0.0 <= zeta <= MAX_ZETA:
        raise FormatError(
            Phrase("ζ must be from 0 to {most}, got {got}", most=fixed(MAX_ZETA, ".0f"), got=fixed(zeta, "g"))
        )
    return Answer((wn, zeta))


def option_label(exercise: Exercise, key: str, lang: Lang) -> str:
    """The label of option ``key`` in ``lang`` (the key itself if unknown)."""
    for option in exercise.options:
        if option.key == key:
            return option.label.get(lang)
    return key
