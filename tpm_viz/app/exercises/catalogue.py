"""The exercises of a tour of lessons, numbered as the tour is (the packaged one by default).

A lesson's number is its place in the tour (file-name order: ``01-direct.toml`` is lesson 1). Exercise ids are
unique in a folder (:func:`tpm_viz.app.lesson_files.load_lessons` refuses a file that reuses one).
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

from tpm_viz.app.demos import Demo
from tpm_viz.app.exercises.model import Exercise
from tpm_viz.app.lessons import DEMOS
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["Listed", "by_id", "listed"]


@dataclass(frozen=True)
class Listed:
    """An exercise with its lesson and the lesson's number in the tour (1-based)."""

    lesson_number: int
    lesson: Demo
    exercise: Exercise


def listed(lessons: Iterable[Demo] = DEMOS, lesson: int | None = None) -> tuple[Listed, ...]:
    """Every exercise of ``lessons`` in tour order (only lesson number ``lesson`` if given)."""
    out = []
    for number, demo in enumerate(lessons, 1):
        if lesson is None or number == lesson:
            out += [Listed(number, demo, exercise) for exercise in demo.exercises]
    return tuple(out)


def by_id(ident: str, lessons: Iterable[Demo] = DEMOS) -> Listed:
    """The exercise ``ident``, else :class:`InputError` naming the known ids."""
    everything = listed(lessons)
    for item in everything:
        if item.exercise.id == ident:
            return item
    known = ", ".join(item.exercise.id for item in everything)
    raise InputError(Phrase("unknown exercise {id}; known: {known}", id=repr(str(ident)[:70]), known=known))
