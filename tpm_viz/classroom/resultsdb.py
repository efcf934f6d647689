"""The exercise results in SQLite: one row per graded submission, a number per student, the class-wide seed.

Tables (schema 2 of the classroom store; :data:`TABLES` takes a store of schema 1 to 2, adding them and touching
nothing else):

- ``results``: ``identity`` (the student's stored hash, :func:`tpm_viz.classroom.identity.hashed`), ``label``
  (``Student 7``: what the lecturer reads), ``exercise``, ``seed``, ``attempt`` (1-based, counted attempts of that
  identity, exercise and seed), ``answer`` (as typed, at most 200 characters), ``score`` (0 to 1, after the
  ladder), ``at`` (seconds since the epoch), ``shared`` (1: graded under the class-wide seed); one row per
  ``(identity, exercise, seed, attempt)``.
- ``students``: ``identity`` -> ``number`` (1, 2, ... in the order of their first graded answer: the label).
- ``settings``: ``name`` -> ``value`` (``class_seed``).

:meth:`ResultRows.add` writes one graded submission in one transaction (``BEGIN IMMEDIATE`` ... ``COMMIT``: with
the store's WAL and ``synchronous=FULL`` it is on disk when it returns, and a kill leaves it or nothing) after
checking, in the same transaction, that the attempt is the next one (another tab of the same student may have
submitted meanwhile) and the :class:`Bounds`. Over a bound nothing is written and :class:`ResultsRefused` says
which (the rows are never evicted: a grade is not dropped to make room).

:meth:`ResultRows.memory` is the same table in memory, for an app without a store (``--session`` not kept).
"""

from __future__ import annotations

import sqlite3
import threading
from collections.abc import Callable
from contextlib import AbstractContextManager
from dataclasses import dataclass
from typing import Any

from tpm_viz.app.exercises.model import Result
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Phrase

__all__ = ["TABLES", "Bounds", "ResultRows", "ResultsRefused", "Row", "Summary"]

TABLES = (
    "CREATE TABLE IF NOT EXISTS results (id INTEGER PRIMARY KEY AUTOINCREMENT, identity TEXT NOT NULL, "
    "label TEXT NOT NULL, exercise TEXT NOT NULL, seed INTEGER NOT NULL, attempt INTEGER NOT NULL, "
    "answer TEXT NOT NULL, score REAL NOT NULL, at REAL NOT NULL, shared INTEGER NOT NULL DEFAULT 0, "
    "UNIQUE (identity, exercise, seed, attempt))",
    "CREATE TABLE IF NOT EXISTS students (identity TEXT PRIMARY KEY, number INTEGER NOT NULL UNIQUE, "
    "first REAL NOT NULL)",
    "CREATE TABLE IF NOT EXISTS settings (name TEXT PRIMARY KEY, value TEXT NOT NULL)",
)
"""The statements that add the results to a store (the migration from schema 1 to 2; idempotent)."""
_COLUMNS = "identity, label, exercise, seed, attempt, answer, score, at, shared"


@dataclass(frozen=True)
class Bounds:
    """How many graded submissions are kept: per student and exercise (homework's "unlimited"), per student, and in
    all. At a bound the next submission is refused with one line (no attempt used) and nothing is evicted."""

    per_exercise: int = 100
    per_student: int = 1000
    total: int = 100_000


class ResultsRefused(InputError):
    """A graded submission that is not kept: over a :class:`Bounds`, or its attempt was taken meanwhile."""


@dataclass(frozen=True)
class Row:
    """One graded submission as kept (:class:`~tpm_viz.app.exercises.model.Result` with its label and whether it
    was graded under the class-wide seed)."""

    identity: str
    label: str
    exercise: str
    seed: int
    attempt: int
    answer: str
    score: float
    time: float
    shared: bool = False


@dataclass(frozen=True)
class Summary:
    """One line of the lecturer's table: a student's attempts at one exercise and variant (seed)."""

    number: int  # the student's number (the label's)
    label: str
    exercise: str
    seed: int
    shared: bool
    attempts: int
    best: float
    latest: float
    answer: str  # the last answer
    time: float  # of the last answer


class ResultRows:
    """The results of one store over its SQLite connection ``db`` (autocommit), guarded by ``lock`` (the store's),
    each write in ``transaction()``. Thread-safe."""

    def __init__(
        self, db: sqlite3.Connection, lock: threading.Lock, transaction: Callable[[], AbstractContextManager[Any]]
    ) -> None:
        self._db, self._lock, self._transaction = db, lock, transaction

    @classmethod
    def memory(cls) -> ResultRows:
        """The results in memory (lost when the app stops): for an app without a store."""
        db = sqlite3.connect(":memory:", isolation_level=None, check_same_thread=False)
        for statement in TABLES:
            db.execute(statement)
        return cls(db, threading.Lock(), lambda: _Immediate(db))

    # -- writing ---------------------------------------------------------------------------------------------------
    def add(self, result: Result, shared: bool, bounds: Bounds, label: str = "Student {number}") -> Row:
        """Keep ``result`` (one transaction; see the module docstring); the row as kept. :class:`ResultsRefused`
        when its attempt is not the next one or a bound is reached."""
        key = (result.student, result.exercise, result.seed)
        with self._lock, self._transaction():
            done = self._one("SELECT COUNT(*) FROM results WHERE identity = ? AND exercise = ? AND seed = ?", key)
            if done != result.attempt - 1:
                raise ResultsRefused(Phrase("another tab of yours answered this exercise meanwhile: submit again"))
            if self._one("SELECT COUNT(*) FROM results WHERE identity = ? AND exercise = ?", key[:2]) >= (
                bounds.per_exercise
            ):
                raise ResultsRefused(
                    Phrase("no attempts left: {most} answers to one exercise are kept", most=bounds.per_exercise)
                )
            if self._one("SELECT COUNT(*) FROM results WHERE identity = ?", key[:1]) >= bounds.per_student:
                raise ResultsRefused(
                    Phrase("no attempts left: {most} answers per student are kept", most=bounds.per_student)
                )
            if self._one("SELECT COUNT(*) FROM results", ()) >= bounds.total:
                raise ResultsRefused(
                    Phrase("the results store is full ({most} answers): tell the lecturer", most=bounds.total)
                )
            number = self._number(result.student, result.time)
            row = Row(
                identity=result.student,
                label=label.format(number=number),
                exercise=result.exercise,
                seed=result.seed,
                attempt=result.attempt,
                answer=result.answer,
                score=result.score,
                time=result.time,
                shared=shared,
            )
            values = (row.identity, row.label, row.exercise, row.seed, row.attempt, row.answer, row.score, row.time)
            self._db.execute(
                f"INSERT INTO results ({_COLUMNS}) VALUES (?, ?, ?, ?, ?, ?, ?, ?, ?)", (*values, int(shared))
            )
        return row

    def _one(self, sql: str, args: tuple[Any, ...]) -> int:
        return int(self._db.execute(sql, args).fetchone()[0])

    def _number(self, identity: str, now: float) -> int:
        found = self._db.execute("SELECT number FROM students WHERE identity = ?", (identity,)).fetchone()
        if found is not None:
            return int(found[0])
        number = self._one("SELECT COALESCE(MAX(number), 0) + 1 FROM students", ())
        self._db.execute("INSERT INTO students VALUES (?, ?, ?)", (identity, number, now))
        return number

    def set_setting(self, name: str, value: str | None) -> None:
        """Keep ``value`` under ``name`` (None: forget it), in one transaction."""
        with self._lock, self._transaction():
            if value is None:
                self._db.execute("DELETE FROM settings WHERE name = ?", (name,))
            else:
                self._db.execute("INSERT OR REPLACE INTO settings VALUES (?, ?)", (name, value))

    # -- reading ---------------------------------------------------------------------------------------------------
    def setting(self, name: str) -> str | None:
        with self._lock:
            found = self._db.execute("SELECT value FROM settings WHERE name = ?", (name,)).fetchone()
        return None if found is None or not isinstance(found[0], str) else found[0]

    def number(self, identity: str) -> int | None:
        """The student's number (None before a first graded answer)."""
        with self._lock:
            found = self._db.execute("SELECT number FROM students WHERE identity = ?", (identity,)).fetchone()
        return None if found is None else int(found[0])

    def of(self, identity: str, exercise: str | None = None, seed: int | None = None) -> tuple[Row, ...]:
        """A student's rows (of one exercise, and one seed, if given), oldest first."""
        sql, args = f"SELECT {_COLUMNS} FROM results WHERE identity = ?", list[str | int]([identity])
        for column, value in (("exercise", exercise), ("seed", seed)):
            if value is not None:
                sql, args = f"{sql} AND {column} = ?", [*args, value]
        with self._lock:
            rows = self._db.execute(f"{sql} ORDER BY id", args).fetchall()
        return tuple(_row(r) for r in rows)

    def count(self) -> int:
        """How many rows are kept."""
        with self._lock:
            return self._one("SELECT COUNT(*) FROM results", ())

    def lines(self) -> int:
        """How many lines :meth:`summary` has (students, exercises and seeds answered)."""
        with self._lock:
            return self._one("SELECT COUNT(*) FROM (SELECT 1 FROM results GROUP BY identity, exercise, seed)", ())

    def summary(self, limit: int | None = None) -> tuple[Summary, ...]:
        """One :class:`Summary` per student, exercise and seed, the latest answered first (at most ``limit``)."""
        sql = (
            "SELECT s.number, r.label, r.exercise, r.seed, r.shared, g.n, g.best, r.score, r.answer, r.at "
            "FROM (SELECT identity, exercise, seed, COUNT(*) AS n, MAX(score) AS best, MAX(id) AS last "
            "FROM results GROUP BY identity, exercise, seed) AS g JOIN results AS r ON r.id = g.last "
            "JOIN students AS s ON s.identity = r.identity ORDER BY r.id DESC"
        )
        with self._lock:
            rows = self._db.execute(sql + ("" if limit is None else f" LIMIT {int(limit)}")).fetchall()
        return tuple(
            Summary(int(n), str(la), str(ex), int(se), bool(sh), int(k), float(b), float(sc), str(an), float(at))
            for n, la, ex, se, sh, k, b, sc, an, at in rows
        )

    def close(self) -> None:
        """Close a memory table (a store's connection is the store's to close)."""
        with self._lock:
            self._db.close()


def _row(r: tuple[Any, ...]) -> Row:
    identity, label, exercise, seed, attempt, answer, score, at, shared = r
    return Row(
        str(identity),
        str(label),
        str(exercise),
        int(seed),
        int(attempt),
        str(answer),
        float(score),
        float(at),
        bool(shared),
    )


class _Immediate:
    """``BEGIN IMMEDIATE`` ... ``COMMIT`` (``ROLLBACK`` on an exception) for the memory table."""

    def __init__(self, db: sqlite3.Connection) -> None:
        self._db = db

    def __enter__(self) -> None:
        self._db.execute("BEGIN IMMEDIATE")

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> None:
        self._db.execute("COMMIT" if kind is None else "ROLLBACK")
