"""The rules of the exercise results: whose numbers a student gets, which attempt an answer is, what is kept, what the
lecturer reads, and who is told of a score (no viser; the browser side is ``tpm_viz/ui/teaching/exercises/``).

- **Seeds.** A student's seed for an exercise is :func:`~tpm_viz.app.exercises.variants.student_seed` of the
  server's seed key and the identity the server issued (the stored hash of the ``tpmviz_id`` cookie,
  :func:`tpm_viz.classroom.identity.hashed`). The key is derived from the cookie secret kept beside the store
  (:meth:`~tpm_viz.classroom.identity.Keys.derive` of :data:`SEED_PURPOSE`), so a seed is the same over reconnects,
  restarts with the same store and devices of the same identity, and differs between students. The lecturer may
  fix one seed for the whole class (:meth:`Gradebook.fix`, kept in the store): every student's seed is then that one,
  for every exercise, until it is unfixed.
- **Attempts** count per student, exercise and seed (a class seed is a new question: its ladder starts afresh; back
  to their own variant, a student finds their attempts there again). An answer that cannot be read is a format
  error: not kept, no attempt used. When the ladder is used up the answer is not graded ("no attempts left").
- **Kept**: every graded answer, written through in one transaction before the student is told
  (:meth:`~tpm_viz.classroom.resultsdb.ResultRows.add`), within :class:`~tpm_viz.classroom.resultsdb.Bounds` (100
  answers per student and exercise, 1000 per student, 100 000 in all: over one, the answer is refused with one line,
  no attempt used, nothing evicted).
- **Read**: a student reads their own rows (:meth:`Gradebook.attempts`); the table of everybody's
  (:meth:`Gradebook.summary`, :meth:`Gradebook.csv`) is for the lecturer's panel only.
- **Told**: after a graded answer is kept, the listeners (the lecturer's live table) and then the
  :data:`ScoreSink` (LTI grade passback) are called.

**ScoreSink** ``sink(identity, exercise_id, best_score, latest_score)``: ``identity`` the student's stored hash,
``best_score`` the best of their attempts at this exercise and seed (the exercise's score,
:meth:`~tpm_viz.app.exercises.model.AttemptRule.best`), ``latest_score`` this attempt's; both after the ladder,
0 to 1. Called once per graded and kept answer (never for a format error or a refused one), after the row is
committed, on the grading thread (a callback thread, or the worker's for ``gains``), outside the app's lock. It
must return quickly (queue any network call); an exception it raises is logged and changes nothing for the student.
"""

from __future__ import annotations

import sqlite3
import threading
import time
from collections.abc import Callable, Iterable
from dataclasses import dataclass

import numpy as np

from tpm_viz.app.demos import Demo
from tpm_viz.app.exercises.catalogue import Listed, listed
from tpm_viz.app.exercises.grading import grade, variant_of
from tpm_viz.app.exercises.model import AttemptRule, Grade, Result
from tpm_viz.app.exercises.variants import parse_seed, student_seed
from tpm_viz.app.lessons import DEMOS
from tpm_viz.classroom.guard import report
from tpm_viz.classroom.resultsdb import Bounds, ResultRows, ResultsRefused, Row, Summary
from tpm_viz.core.csvio import format_columns
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase, T

__all__ = ["CLASS_SEED", "NO_ATTEMPTS", "SEED_PURPOSE", "Gradebook", "ScoreSink", "Submitted", "spreadsheet_safe"]

SEED_PURPOSE = "exercise seeds"
"""What the seed key is derived for (:meth:`~tpm_viz.classroom.identity.Keys.derive`)."""
CLASS_SEED = "class_seed"
"""The store's setting that holds the class-wide seed."""
NO_ATTEMPTS = T("no attempts left")
ScoreSink = Callable[[str, str, float, float], None]
"""``sink(identity_hash, exercise_id, best_score, latest_score)`` (module docstring)."""
_TURN_STRIPES = 64
"""Locks one student's answers wait on (a student's is ``hash(identity) % 64``: bounded, whatever the class)."""
CSV_COLUMNS: tuple[str, ...] = ("student", "exercise", "variant", "seed", "attempts", "best_score", "latest_score")
CSV_COLUMNS += ("last_answer", "last_time")


@dataclass(frozen=True)
class Submitted:
    """What became of one submission: its ``grade`` (None: not graded, ``refusal`` says why), and the student's
    counted attempts at this exercise and seed after it (oldest first)."""

    exercise: str
    seed: int
    grade: Grade | None
    refusal: Phrase | None
    attempts: tuple[Row, ...]


def spreadsheet_safe(text: str) -> str:
    """A cell a spreadsheet shows as text, never runs: a leading ``= + - @``, tab or return gets a ``'`` (OWASP)."""
    return "'" + text if text[:1] in ("=", "+", "-", "@", "\t", "\r") else text


class Gradebook:
    """The results of one classroom (thread-safe: the rows are)."""

    def __init__(
        self,
        rows: ResultRows,
        key: bytes,
        lessons: Iterable[Demo] = DEMOS,
        bounds: Bounds = Bounds(),
        clock: Callable[[], float] = time.time,
    ) -> None:
        self.rows, self.key, self.bounds, self.clock = rows, key, bounds, clock
        self.exercises: dict[str, Listed] = {item.exercise.id: item for item in listed(lessons)}
        self.sink: ScoreSink | None = None
        """Called after each graded answer is kept (:data:`ScoreSink`; None: nobody)."""
        self.listeners: list[Callable[[Row], None]] = []
        """Called with each kept row, before the sink (the lecturer's live table)."""
        self._turns = tuple(threading.Lock() for _ in range(_TURN_STRIPES))
        try:
            kept = rows.setting(CLASS_SEED)
            self._class_seed = None if kept is None else parse_seed(kept)
        except InputError:  # an unreadable setting: every student their own variant
            self._class_seed = None

    # -- seeds -------------------------------------------------------------------------------------------------------
    @property
    def class_seed(self) -> int | None:
        """The seed the lecturer fixed for the whole class (None: a variant per student)."""
        return self._class_seed

    def fix(self, seed: object) -> int | None:
        """Fix ``seed`` (text or an integer, :func:`~tpm_viz.app.exercises.variants.parse_seed`) for the class, or
        None to unfix; kept in the store. Returns the seed now in force."""
        value = None if seed is None else parse_seed(seed)
        self.rows.set_setting(CLASS_SEED, None if value is None else str(value))
        self._class_seed = value
        return value

    def seed(self, identity: str, exercise_id: str) -> int:
        """The seed ``identity`` answers ``exercise_id`` with now."""
        fixed = self._class_seed
        return fixed if fixed is not None else student_seed(self.key, identity, exercise_id)

    # -- a student's own ----------------------------------------------------------------------------------------------
    def attempts(self, identity: str, exercise_id: str, seed: int | None = None) -> tuple[Row, ...]:
        """``identity``'s counted attempts at ``exercise_id`` with ``seed`` (default: the one in force)."""
        return self.rows.of(identity, exercise_id, self.seed(identity, exercise_id) if seed is None else seed)

    def label(self, identity: str) -> Phrase | None:
        """``Student 7``: how the lecturer's table names ``identity`` (None before a first graded answer)."""
        number = self.rows.number(identity)
        return None if number is None else Phrase("Student {number}", number=number)

    def submit(self, identity: str, exercise_id: str, text: object) -> Submitted:
        """Grade ``text`` as ``identity``'s next attempt at ``exercise_id`` and keep it (module docstring).
        :class:`InputError` for an unknown exercise. One student's answers are graded one after another (two tabs
        answering at once get attempts 1 and 2, never both 1); other students' are graded meanwhile."""
        with self._turns[hash(identity) % _TURN_STRIPES]:
            return self._submit(identity, exercise_id, text)

    def _submit(self, identity: str, exercise_id: str, text: object) -> Submitted:
        item = self.exercises.get(exercise_id)
        if item is None:
            raise InputError(Phrase("unknown exercise {id}", id=repr(str(exercise_id)[:70])))
        exercise = item.exercise
        fixed = self._class_seed  # read once: the lecturer may fix or unfix it while this answer is graded
        seed = fixed if fixed is not None else student_seed(self.key, identity, exercise_id)
        try:
            done = self.rows.of(identity, exercise_id, seed)
        except sqlite3.Error as exc:  # a store that cannot be read now (locked, closed): said, nothing graded
            return Submitted(exercise_id, seed, None, _unkept(exc), ())
        if exercise.attempts.left(len(done)) == 0:
            return Submitted(exercise_id, seed, None, NO_ATTEMPTS, done)
        try:
            graded = grade(exercise, variant_of(exercise, seed), text, len(done) + 1)
        except InputError as exc:  # no usable variant for this seed: said, nothing kept
            return Submitted(exercise_id, seed, None, _phrase(exc), done)
        if graded.format_error is not None or graded.score is None:
            return Submitted(exercise_id, seed, graded, None, done)
        result = Result(identity, exercise_id, seed, len(done) + 1, str(text), graded.score, self.clock())
        try:
            row = self.rows.add(result, fixed is not None, self.bounds)
        except ResultsRefused as exc:
            return Submitted(exercise_id, seed, None, _phrase(exc), done)
        except sqlite3.Error as exc:  # a full disk, a locked file: not kept, so not counted (the student is told)
            return Submitted(exercise_id, seed, None, _unkept(exc), done)
        attempts = (*done, row)
        self._tell(row, attempts)
        return Submitted(exercise_id, seed, graded, None, attempts)

    def _tell(self, row: Row, attempts: tuple[Row, ...]) -> None:
        for listener in list(self.listeners):
            try:
                listener(row)
            except Exception as exc:  # a listener's bug is logged; the answer is kept
                report(exc, "a results listener")
        sink = self.sink
        if sink is None:
            return
        best = AttemptRule.best(r.score for r in attempts)
        try:
            sink(row.identity, row.exercise, row.score if best is None else best, row.score)
        except Exception as exc:  # the score sink's bug is logged; the answer is kept
            report(exc, "the score sink")

    # -- the lecturer's ----------------------------------------------------------------------------------------------
    def summary(self, limit: int | None = None) -> tuple[Summary, ...]:
        """Everybody's attempts, one line per student, exercise and seed, latest first (the lecturer's only)."""
        return self.rows.summary(limit)

    def csv(self) -> str:
        """:meth:`summary` as CSV (:data:`CSV_COLUMNS`; answers made safe for a spreadsheet, times in UTC)."""
        lines = self.summary()
        text = [
            [
                line.label,
                line.exercise,
                "class" if line.shared else "own",
                str(line.seed),
                str(line.attempts),
                f"{line.best:.4g}",
                f"{line.latest:.4g}",
                spreadsheet_safe(line.answer),
                time.strftime("%Y-%m-%dT%H:%M:%SZ", time.gmtime(line.time)),
            ]
            for line in lines
        ]
        columns = {name: np.array([row[i] for row in text], dtype=object) for i, name in enumerate(CSV_COLUMNS)}
        return format_columns(columns)


def _unkept(exc: sqlite3.Error) -> Phrase:
    why = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
    return Phrase("the answer could not be kept ({why}); submit it again in a moment", why=why)


def _phrase(exc: InputError) -> Phrase:
    return (
        exc.args[0]
        if exc.args and isinstance(exc.args[0], Phrase)
        else Phrase(str(exc).replace("{", "{{").replace("}", "}}"))
    )
