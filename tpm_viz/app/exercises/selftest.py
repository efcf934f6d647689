"""The grader grading itself (STACK's habit: the answer tests' own results, published in ``docs/exercises.md``).

For each exercise and the seeds ``0 .. N-1``: the reference answer (typed at full precision) must score 1; an
answer just outside the tolerance must score less and be read (a number 1.5 tolerances off the reference; a pose
moved along the gradient of the checked quantity until it is off by twice the tolerance; gains one grid step too
soft, :func:`tpm_viz.app.exercises.gains.just_outside`; the other option of a choice); two garbage answers (not a
number, and the wrong count of values or a unit that does not fit) must be format errors that use no attempt.
Each grading is timed from empty caches, as a first submission computes (the p95 over all gradings of the exercise,
in ms).
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.exercises.gains import just_outside
from tpm_viz.app.exercises.grading import clear_caches, grade, reference, tolerance, variant_of
from tpm_viz.app.exercises.model import Exercise, Grade, Kind, Variant
from tpm_viz.app.exercises.tasks import POSE_TASKS, pose_problem
from tpm_viz.core.errors import TpmVizError

__all__ = ["COLUMNS", "GARBAGE", "SelftestRow", "perturbed", "reference_text", "selftest"]

COLUMNS = ("id", "variants", "reference_ok", "perturbed_ok", "format_ok", "p95_ms")
"""The columns of the selftest table (the command line's CSV)."""
GARBAGE: dict[Kind, tuple[str, str]] = {
    Kind.NUMBER: ("abc", "5 kg"),
    Kind.POSE: ("abc", "1; 2; 3"),
    Kind.GAINS: ("abc", "10"),
    Kind.CHOICE: ("abc", "0"),
}
"""Answers that must be format errors, by kind."""


@dataclass(frozen=True)
class SelftestRow:
    """One exercise's results over ``variants`` seeds, and a line per failure (empty when all pass)."""

    id: str
    variants: int
    reference_ok: bool
    perturbed_ok: bool
    format_ok: bool
    p95_ms: float
    failures: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        return self.reference_ok and self.perturbed_ok and self.format_ok

    def cells(self) -> tuple[str, ...]:
        """The row as CSV cells (booleans ``true``/``false``, the p95 with two decimals)."""
        flags = (self.reference_ok, self.perturbed_ok, self.format_ok)
        return (self.id, str(self.variants), *("true" if f else "false" for f in flags), f"{self.p95_ms:.2f}")


def reference_text(exercise: Exercise, variant: Variant) -> str:
    """The reference answer as a student could type it (full precision, ``;`` between values)."""
    ref = reference(exercise, variant)
    return ref if isinstance(ref, str) else "; ".join(repr(float(x)) for x in ref)


def _pose_off(exercise: Exercise, variant: Variant, mm: tuple[float, ...]) -> str | None:
    """A readable pose near the reference where the checked quantity is off its target by twice the tolerance."""
    task = POSE_TASKS[exercise.answer]
    rtol, atol = tolerance(exercise, variant)
    p0 = np.array(mm) * 1e-3
    h = 1e-6
    q0 = task.quantity(variant, p0)
    grad = np.array([(task.quantity(variant, p0 + h * e) - q0) / h for e in np.eye(2)])
    off = 2.0 * (atol + rtol * abs(task.target))
    for sign in (1.0, -1.0):
        p = p0 + sign * off * grad / float(grad @ grad)
        for _ in range(20):  # Newton steps to |q - target| = off along the gradient
            p = p + (sign * off + task.target - task.quantity(variant, p)) * grad / float(grad @ grad)
        if pose_problem(variant.params, p) is None:
            return f"{float(p[0]) * 1e3!r}; {float(p[1]) * 1e3!r}"
    return None


def perturbed(exercise: Exercise, variant: Variant) -> str | None:
    """An answer just outside the tolerance (module docstring), or None if there is none."""
    ref = reference(exercise, variant)
    if exercise.kind is Kind.NUMBER:
        assert not isinstance(ref, str)
        rtol, atol = tolerance(exercise, variant)
        return repr(float(ref[0]) + 1.5 * (atol + rtol * abs(float(ref[0]))))
    if exercise.kind is Kind.POSE:
        assert not isinstance(ref, str)
        return _pose_off(exercise, variant, ref)
    if exercise.kind is Kind.GAINS:
        gains = just_outside(variant)
        return None if gains is None else f"{gains[0]!r}; {gains[1]!r}"
    return next(o.key for o in exercise.options if o.key != ref)


def _timed(exercise: Exercise, variant: Variant, text: str, times: list[float]) -> Grade:
    start = time.perf_counter()
    result = grade(exercise, variant, text, 1)
    times.append(time.perf_counter() - start)
    return result


def selftest(exercise: Exercise, variants: int) -> SelftestRow:
    """The grader's results on ``exercise`` for the seeds ``0 .. variants - 1`` (module docstring)."""
    times: list[float] = []
    failures: list[str] = []
    ref_ok = pert_ok = fmt_ok = True
    for seed in range(variants):
        try:
            variant = variant_of(exercise, seed)
            text, off = reference_text(exercise, variant), perturbed(exercise, variant)
        except TpmVizError as exc:
            failures.append(f"seed {seed}: {exc}")
            ref_ok = pert_ok = False
            continue
        clear_caches()  # each grading below computes what it needs, as a first submission does
        right = _timed(exercise, variant, text, times)
        if right.score != 1.0:
            ref_ok = False
            failures.append(f"seed {seed}: the reference scored {right.score} ({right.format_error or right.feedback})")
        wrong = None if off is None else _timed(exercise, variant, off, times)
        if wrong is None or wrong.score is None or wrong.score >= 1.0:
            pert_ok = False
            failures.append(f"seed {seed}: the answer just outside ({off}) got {wrong and wrong.json()}")
        for text in GARBAGE[exercise.kind]:
            bad = _timed(exercise, variant, text, times)
            if bad.format_error is None or bad.attempts_used != 0:
                fmt_ok = False
                failures.append(f"seed {seed}: {text!r} was graded ({bad.json()})")
    p95 = float(np.percentile(times, 95)) * 1e3 if times else float("nan")
    return SelftestRow(exercise.id, variants, ref_ok, pert_ok, fmt_ok, p95, tuple(failures))
