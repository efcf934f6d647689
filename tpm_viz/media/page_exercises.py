"""A lesson's exercises as the offline page grades them: one JSON-ready entry per exercise.

A static page has no identity: its variant is the seed it was made with (``tpm-viz page --seed S``), the same for
every exercise, so its prompts are those of ``tpm-viz exercise show ID --seed S`` (:func:`shown_prompt`). What depends
only on the variant is computed here by the library, once, and carried by the page; what depends on the answer is
computed in the page by ``page_grader.js`` (:mod:`tpm_viz.media.page_grader`):

- ``number``: the reference in the exercise's unit, ``rtol`` and ``atol``, and each declared mistake in file order
  (a ``factor``, or the value of its ``answer`` computation in the exercise's unit) with its score and feedback, and
  the generic line of a wrong answer;
- ``pose``: the variant's parameters (SI) and ``p̈`` (the page computes τ at the typed pose with the calculator,
  eqs. 28-31), ``l_a²`` and ``a - b`` as the library computes them (so that the page's pose rules round as the
  library's do), the app's warning thresholds, which ``τ_i`` is checked against which target and the mistakes (a
  ``factor``, or the other force);
- ``choice``: the options (key, labels in both languages, feedback), the right key;
- ``gains``: only the prompt (grading simulates the closed loop: the page says it needs the app).

Every text is rendered in the page's language; the ladder is the exercise's attempt rule.
"""

from __future__ import annotations

from typing import Any

from tpm_viz.app.exercises.grading import _incorrect, prompt, reference, shown_values, to_unit, tolerance, variant_of
from tpm_viz.app.exercises.model import Exercise, Kind, Texts, Variant
from tpm_viz.app.exercises.tasks import CHOICE_TASKS, NUMBER_TASKS, POSE_TASKS
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import PARAM_INFO
from tpm_viz.core.words import Lang, Phrase, T
from tpm_viz.paper.status import WARN

__all__ = ["GRADED_KINDS", "exercise_entry", "lesson_exercises", "shown_prompt"]

GRADED_KINDS = (Kind.NUMBER, Kind.POSE, Kind.CHOICE)
"""The answer kinds the page grades itself (``gains`` needs the app's simulation)."""


def shown_prompt(exercise: Exercise, variant: Variant, lang: Lang) -> str:
    """The prompt exactly as ``tpm-viz exercise show`` prints it (a choice's options listed after it)."""
    text = prompt(exercise, variant).render(lang)
    if exercise.options:
        listed = ", ".join(f"{n} = {o.label.get(lang)}" for n, o in enumerate(exercise.options, 1))
        text = f"{text} {Phrase('Options: {options}.', options=listed).render(lang)}"
    return text


def _feedback(exercise: Exercise, variant: Variant, texts: Texts | None, lang: Lang) -> str | None:
    return None if texts is None else texts.phrase(**shown_values(exercise, variant)).render(lang)


def _number(exercise: Exercise, variant: Variant, lang: Lang) -> dict[str, Any]:
    rtol, atol = tolerance(exercise, variant)
    quantity = NUMBER_TASKS[exercise.answer].quantity
    mistakes = []
    for m in exercise.mistakes:
        value = None
        if m.answer is not None:
            value = to_unit(NUMBER_TASKS[m.answer].value(variant), exercise.unit, quantity)
        mistakes.append(
            {
                "score": m.score,
                "factor": m.factor,
                "value": value,
                "feedback": _feedback(exercise, variant, m.feedback, lang),
            }
        )
    ref = reference(exercise, variant)
    assert not isinstance(ref, str)
    return {
        "ref": ref[0],
        "rtol": rtol,
        "atol": atol,
        "mistakes": mistakes,
        "incorrect": _incorrect(exercise, rtol, atol).render(lang),
    }


def _force_index(task_name: str) -> int:
    """Which ``τ_i`` (0-based) a pose task checks: the index its symbol names (``τ₁`` -> 0)."""
    return "₁₂".index(POSE_TASKS[task_name].symbol[-1])


def _pose(exercise: Exercise, variant: Variant, lang: Lang) -> dict[str, Any]:
    rtol, atol = tolerance(exercise, variant)
    task = POSE_TASKS[exercise.answer]
    params = variant.params
    mistakes = []
    for m in exercise.mistakes:
        other = None if m.answer is None else POSE_TASKS[m.answer]
        mistakes.append(
            {
                "score": m.score,
                "factor": m.factor,
                "index": None if m.answer is None else _force_index(m.answer),
                "target": None if other is None else other.target,
                "feedback": _feedback(exercise, variant, m.feedback, lang),
            }
        )
    return {
        "params": {name: float(getattr(params, name)) for name in PARAM_INFO},
        "la2": params.l_a**2,
        "offset": params.offset,
        "warn": {"inverse": WARN.inverse, "direct": WARN.direct},
        "ddp": [variant["ddp1"], variant["ddp2"]],
        "rtol": rtol,
        "atol": atol,
        "index": _force_index(exercise.answer),
        "target": task.target,
        "symbol": task.symbol,
        "task_unit": task.unit,
        "target_text": fixed(task.target, "g"),
        "tol_text": fixed(atol + rtol * abs(task.target), "g"),
        "mistakes": mistakes,
    }


def _choice(exercise: Exercise, variant: Variant, lang: Lang) -> dict[str, Any]:
    listed = Texts(*(", ".join(f"{n} ({o.label.get(lg)})" for n, o in enumerate(exercise.options, 1)) for lg in Lang))
    return {
        "options": [
            {
                "key": o.key,
                "en": o.label.en,
                "ko": o.label.ko,
                "label": o.label.get(lang),
                "feedback": _feedback(exercise, variant, o.feedback, lang),
            }
            for o in exercise.options
        ],
        "options_text": listed.get(lang),
        "right": CHOICE_TASKS[exercise.answer].value(variant),
    }


_KINDS = {Kind.NUMBER: _number, Kind.POSE: _pose, Kind.CHOICE: _choice}


def exercise_entry(exercise: Exercise, seed: int, lang: Lang) -> dict[str, Any]:
    """One exercise of the page for variant ``seed`` in ``lang`` (module docstring); JSON-ready, every number
    finite. :class:`~tpm_viz.core.errors.InputError` if the exercise has no usable variant for the seed."""
    variant = variant_of(exercise, seed)
    ladder = exercise.attempts.ladder
    entry: dict[str, Any] = {
        "id": exercise.id,
        "kind": exercise.kind.value,
        "unit": exercise.unit,
        "title": exercise.title.get(lang),
        "prompt": shown_prompt(exercise, variant, lang),
        "seed": seed,
        "ladder": None if ladder is None else list(ladder),
        "graded": exercise.kind in GRADED_KINDS,
        "correct": T("correct").render(lang),
    }
    if exercise.kind in _KINDS:
        entry.update(_KINDS[exercise.kind](exercise, variant, lang))
    return entry


def lesson_exercises(exercises: tuple[Exercise, ...], seed: int, lang: Lang) -> list[dict[str, Any]]:
    """Every exercise of a lesson, in file order (:func:`exercise_entry`)."""
    return [exercise_entry(exercise, seed, lang) for exercise in exercises]
