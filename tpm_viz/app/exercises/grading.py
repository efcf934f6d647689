"""Grading with PrairieLearn's semantics, and the texts a student reads (the prompt with the variant's numbers).

:func:`grade` ``(exercise, variant, text, attempt)`` -> :class:`~tpm_viz.app.exercises.model.Grade`:

- an answer that cannot be read (:mod:`.answers`: not a number, the wrong count, a unit that does not fit, a pose
  out of reach, outside the stroke or in the other assembly mode) is a *format error*: one line saying what to
  change, no score, no attempt used;
- a readable answer gets a score in [0, 1] and one feedback line: 1 and "correct" when it is right; else the first
  declared mistake it matches (its score and feedback); else 0 and why. The score is then multiplied by the
  attempt ladder's factor for attempt ``k`` (:class:`~tpm_viz.app.exercises.model.AttemptRule`).

Right means, by kind: ``number``: PrairieLearn's relabs rule ``|x - ref| <= atol + rtol |ref|`` in the exercise's
unit (:func:`close`); ``pose``: clear of both singularities by the app's warning thresholds and the checked
quantity (``τ₁`` at the pose, ``ṗ = 0``) within the tolerance of its target (every such pose, not a stored one);
``gains``: the closed loop tracks within 1 mm RMS without exceeding the force limit (:mod:`.gains`); ``choice``:
the computed option. A mistake matches when the answer divided by its ``factor`` is right (a number, a pose, or
``ω_n`` of gains: the slip undone), or when the answer is right for its other computation ``answer`` (the same
tolerance).

Deterministic: the same exercise, variant, text and attempt always give the same grade.
"""

from __future__ import annotations

import functools
import math

import numpy as np

from tpm_viz.app.exercises.answers import Answer, FormatError, read_answer
from tpm_viz.app.exercises.gains import reference as gains_reference
from tpm_viz.app.exercises.gains import verdict
from tpm_viz.app.exercises.model import (
    SIGNED,
    Draw,
    Exercise,
    FileText,
    Grade,
    Kind,
    Texts,
    Variant,
    decimals_of,
    shown_unit,
)
from tpm_viz.app.exercises.registry import shows, task_of
from tpm_viz.app.exercises.registry import usable as usable_for
from tpm_viz.app.exercises.tasks import (
    CHOICE_TASKS,
    NUMBER_TASKS,
    POSE_TASKS,
    circle_peak,
    pose_problem,
    pose_warning,
    zero_pose,
)
from tpm_viz.app.exercises.variants import variant as draw_variant
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed, unit_factor
from tpm_viz.core.words import Phrase, T

__all__ = [
    "clear_caches",
    "close",
    "grade",
    "prompt",
    "reference",
    "shown_values",
    "to_unit",
    "tolerance",
    "variant_of",
]


Judged = tuple[float, Phrase | Texts]
"""A raw score and its feedback: a phrase, or a file's text to fill with the variant's numbers."""


def close(x: float, ref: float, rtol: float, atol: float) -> bool:
    """PrairieLearn's relabs rule: ``|x - ref| <= atol + rtol |ref|``."""
    return abs(x - ref) <= atol + rtol * abs(ref)


def to_unit(si: float, unit: str, quantity: str | None) -> float:
    """``si`` [SI] in ``unit`` of ``quantity`` (``""``: as it is)."""
    mul, div = unit_factor(unit, quantity, unit, "the answer")
    return si * div / mul


@functools.lru_cache(maxsize=1024)
def variant_of(exercise: Exercise, seed: int) -> Variant:
    """The variant of ``exercise`` for ``seed`` whose numbers suit its computation (see :mod:`.variants`)."""
    return draw_variant(exercise, seed, usable_for(exercise))


def clear_caches() -> None:
    """Forget every cached computation (simulations, reference poses, peaks): the next grade computes afresh (what
    the selftest and the benchmark time)."""
    verdict.cache_clear()
    gains_reference.cache_clear()
    zero_pose.cache_clear()
    circle_peak.cache_clear()


def tolerance(exercise: Exercise, variant: Variant) -> tuple[float, float]:
    """``(rtol, atol)``; ``atol`` in the answer's unit (pose: the checked quantity's), taken from the variant when
    the file names an input (``atol = "tol"``)."""
    atol = variant[exercise.atol] if isinstance(exercise.atol, str) else exercise.atol
    return exercise.rtol, atol


def shown_values(exercise: Exercise, variant: Variant) -> dict[str, str]:
    """Every placeholder a prompt or a feedback line of ``exercise`` may use, as text: the parameters and the
    drawn inputs in the units a prompt shows (mm, kg, m/s², N, %, s) and the computation's shown values."""
    draws: dict[str, Draw] = {d.name: d for d in exercise.draws}
    out: dict[str, str] = {}
    for name, value in variant.values().items():
        scale = shown_unit(name)[1]
        shown = value * scale
        decimals = draws[name].decimals if name in draws else decimals_of(shown)
        out[name] = fixed(shown, f"{'+' if name in SIGNED else ''}.{decimals}f")
    for name, compute in shows(task_of(exercise)).items():
        out[name] = compute(variant)
    return out


def prompt(exercise: Exercise, variant: Variant) -> FileText:
    """The prompt with the variant's numbers (``.render(lang)``: English or Korean)."""
    return exercise.prompt.phrase(**shown_values(exercise, variant))


def reference(exercise: Exercise, variant: Variant) -> tuple[float, ...] | str:
    """The reference answer in the exercise's unit: ``(x,)``; a pose ``(p1, p2)`` in mm that passes; gains
    ``(ω_n [Hz], ζ)``; a choice's option key. :class:`InputError` if the computation finds none."""
    if exercise.kind is Kind.NUMBER:
        return (to_unit(NUMBER_TASKS[exercise.answer].value(variant), exercise.unit, _quantity(exercise)),)
    if exercise.kind is Kind.POSE:
        pose = POSE_TASKS[exercise.answer].reference(variant)
        if pose is None:
            raise InputError(Phrase("exercise {id}: no pose passes for this variant", id=exercise.id))
        return tuple(float(f"{x * 1e3:.10g}") for x in pose)
    if exercise.kind is Kind.GAINS:
        gains = gains_reference(variant)
        if gains is None:
            raise InputError(Phrase("exercise {id}: no gains pass for this variant", id=exercise.id))
        return gains
    return CHOICE_TASKS[exercise.answer].value(variant)


def _quantity(exercise: Exercise) -> str | None:
    return NUMBER_TASKS[exercise.answer].quantity


def _number(exercise: Exercise, variant: Variant, x: float) -> Judged:
    rtol, atol = tolerance(exercise, variant)
    q = _quantity(exercise)
    ref = to_unit(NUMBER_TASKS[exercise.answer].value(variant), exercise.unit, q)
    if close(x, ref, rtol, atol):
        return 1.0, T("correct")
    for mistake in exercise.mistakes:
        if mistake.factor is not None:  # the answer read back through the slip is right
            hit = close(x / mistake.factor, ref, rtol, atol)
        else:
            assert mistake.answer is not None
            hit = close(x, to_unit(NUMBER_TASKS[mistake.answer].value(variant), exercise.unit, q), rtol, atol)
        if hit:
            return mistake.score, mistake.feedback
    return 0.0, _incorrect(exercise, rtol, atol)


def _incorrect(exercise: Exercise, rtol: float, atol: float) -> Phrase:
    unit = f" {exercise.unit}" if exercise.unit else ""
    return Phrase(
        "incorrect: not within the tolerance (relative {rtol}, absolute {atol}{unit})",
        rtol=fixed(rtol, "g"),
        atol=fixed(atol, "g"),
        unit=unit,
    )


def _passes(exercise: Exercise, variant: Variant, name: str, p: np.ndarray) -> tuple[bool, float]:
    task = POSE_TASKS[name]
    rtol, atol = tolerance(exercise, variant)
    value = task.quantity(variant, p)
    return close(value, task.target, rtol, atol), value


def _pose(exercise: Exercise, variant: Variant, mm: tuple[float, ...]) -> Judged:
    p = np.array(mm) * 1e-3
    warning = pose_warning(variant.params, p)
    if warning is not None:
        return 0.0, warning
    ok, value = _passes(exercise, variant, exercise.answer, p)
    task = POSE_TASKS[exercise.answer]
    where = {"p1": fixed(mm[0], ".1f"), "p2": fixed(mm[1], ".1f"), "symbol": task.symbol, "unit": task.unit}
    if ok:
        return 1.0, Phrase("correct: {symbol} = {value} {unit} at ({p1}, {p2}) mm", value=fixed(value, ".2f"), **where)
    for mistake in exercise.mistakes:
        if mistake.factor is not None:
            other = p / mistake.factor
            fits = pose_problem(variant.params, other) is None and pose_warning(variant.params, other) is None
            hit = fits and _passes(exercise, variant, exercise.answer, other)[0]
        else:
            assert mistake.answer is not None
            hit = _passes(exercise, variant, mistake.answer, p)[0]
        if hit:
            return mistake.score, mistake.feedback
    rtol, atol = tolerance(exercise, variant)
    return (
        0.0,
        Phrase(
            "{symbol} = {value} {unit} at ({p1}, {p2}) mm; it must be {target} within {tol} {unit}",
            value=fixed(value, ".2f"),
            target=fixed(task.target, "g"),
            tol=fixed(atol + rtol * abs(task.target), "g"),
            **where,
        ),
    )


def _gains(exercise: Exercise, variant: Variant, values: tuple[float, ...]) -> Judged:
    wn, zeta = values
    outcome = verdict(variant, wn, zeta)
    if outcome.ok:
        return 1.0, outcome.why()
    for mistake in exercise.mistakes:
        if mistake.factor is not None and verdict(variant, wn / mistake.factor, zeta).ok:
            return mistake.score, mistake.feedback
    return 0.0, outcome.why()


def _choice(exercise: Exercise, variant: Variant, key: str) -> Judged:
    if key == CHOICE_TASKS[exercise.answer].value(variant):
        return 1.0, T("correct")
    option = next(o for o in exercise.options if o.key == key)
    return 0.0, (option.feedback if option.feedback is not None else T("incorrect"))


def grade(exercise: Exercise, variant: Variant, text: object, attempt: int = 1) -> Grade:
    """Grade ``text`` as attempt ``attempt`` (1-based, counted attempts) of ``exercise`` for ``variant`` (module
    docstring). :class:`InputError` only for an attempt the rule does not allow."""
    factor = exercise.attempts.factor(attempt)
    try:
        answer: Answer = read_answer(exercise, variant, text)
    except FormatError as exc:
        why = exc.args[0] if exc.args and isinstance(exc.args[0], Phrase) else T("the answer cannot be read")
        return Grade(None, None, why, None, 0, exercise.attempts.left(attempt - 1))
    if exercise.kind is Kind.NUMBER:
        raw, said = _number(exercise, variant, answer.values[0])
    elif exercise.kind is Kind.POSE:
        raw, said = _pose(exercise, variant, answer.values)
    elif exercise.kind is Kind.GAINS:
        raw, said = _gains(exercise, variant, answer.values)
    else:
        raw, said = _choice(exercise, variant, answer.choice)
    feedback = said.phrase(**shown_values(exercise, variant)) if isinstance(said, Texts) else said
    score = round(raw * factor, 9)
    if not (math.isfinite(score) and 0.0 <= score <= 1.0):  # never: scores and factors are in [0, 1]
        raise InputError(Phrase("a score must be from 0 to 1, got {got}", got=repr(score)))
    return Grade(
        score=score,
        raw=raw,
        format_error=None,
        feedback=feedback,
        attempts_used=1,
        attempts_left=exercise.attempts.left(attempt),
        values=answer.values,
        choice=answer.choice,
    )
