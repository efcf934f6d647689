"""One door to the computations of every answer kind: what a file may name, what it needs, what a prompt may show.

An exercise's ``answer`` names a computation of its kind (:data:`TASKS`); a mistake's ``answer`` names another of
the same kind (``number`` and ``pose`` only). :func:`usable` is the test a drawn variant must pass
(:func:`tpm_viz.app.exercises.variants.variant` draws again otherwise).
"""

from __future__ import annotations

from collections.abc import Callable, Mapping

from tpm_viz.app.exercises.gains import GAINS_TASKS, GainsTask
from tpm_viz.app.exercises.model import Exercise, Kind, Variant
from tpm_viz.app.exercises.tasks import CHOICE_TASKS, NUMBER_TASKS, POSE_TASKS, ChoiceTask, NumberTask, PoseTask

__all__ = ["TASKS", "Task", "shows", "task_of", "usable"]

Task = NumberTask | PoseTask | ChoiceTask | GainsTask
"""A computation of any kind."""

TASKS: dict[Kind, Mapping[str, Task]] = {
    Kind.NUMBER: NUMBER_TASKS,
    Kind.POSE: POSE_TASKS,
    Kind.CHOICE: CHOICE_TASKS,
    Kind.GAINS: GAINS_TASKS,
}
"""The registries by answer kind."""


def task_of(exercise: Exercise) -> Task:
    """The computation ``exercise.answer`` of its kind (the reader has checked that it exists)."""
    return TASKS[exercise.kind][exercise.answer]


def shows(task: Task) -> dict[str, Callable[[Variant], str]]:
    """The computed values a prompt of ``task`` may show, by placeholder name."""
    return dict(task.shows) if isinstance(task, NumberTask) else {}


def usable(exercise: Exercise) -> Callable[[Variant], bool]:
    """Whether a drawn variant suits ``exercise``'s computation (its pose regular, a zero-force pose exists, ...)."""
    task = task_of(exercise)
    check = task.usable
    if check is None:
        return lambda variant: True
    return check
