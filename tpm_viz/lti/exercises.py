"""The exercises the deep-linking picker offers: every exercise of the app's lessons, graded, out of
:data:`POINTS` points.

An item's ``id`` is the exercise's id (``custom`` ``exercise=ID`` of the link it becomes), its titles are the
lesson file's (English, and Korean when the file has it), ``score_maximum`` the line item's maximum the link asks
the LMS for. A student's score is a fraction 0..1 (:class:`~tpm_viz.app.exercises.model.Grade`, after the attempt
ladder); the score sent is that fraction x the line item's maximum (:mod:`.grades`).
"""

from __future__ import annotations

from collections.abc import Sequence

from tpm_viz.app.demos import Demo
from tpm_viz.app.exercises.catalogue import listed
from tpm_viz.core.words import Lang
from tpm_viz.lti.deeplinking import Catalogue, Item

__all__ = ["POINTS", "exercises_catalogue"]

POINTS = 10.0
"""The maximum score of an exercise's line item [points] (an exam ladder's 10, 7, 5 points: PrairieLearn's)."""


def exercises_catalogue(lessons: Sequence[Demo]) -> Catalogue:
    """The exercises of ``lessons`` in tour order, each a graded :class:`~.deeplinking.Item`."""
    items = [
        Item(
            "exercise",
            entry.exercise.id,
            f"{entry.lesson_number}. {entry.exercise.title.get(Lang.EN)}",
            f"{entry.lesson_number}. {entry.exercise.title.get(Lang.KO)}",
            graded=True,
            score_maximum=POINTS,
        )
        for entry in listed(lessons)
    ]
    return lambda: list(items)
