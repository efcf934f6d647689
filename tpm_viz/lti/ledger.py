"""The LTI tool's records in the classroom store (schema 2 of :mod:`tpm_viz.classroom.store`).

Tables (each write one ``BEGIN IMMEDIATE`` transaction on this module's own connection, WAL, ``synchronous=FULL``):

- ``lti_users (issuer, subject) -> ident``: the server-issued identity of an LMS user (32 random hex), the same
  from every launch and device;
- ``lti_class``: the one course this server's class is bound to (the first launched; docs/lti.md, limits);
- ``lti_launches ref -> body``: each checked launch (its platform, user, role, course, what it opens, its AGS
  endpoint), and the browser (hashed cookie identity) it arrived in: how a reconnecting tab finds its user again
  and how a grade finds its line item. Bounded: :data:`MAX_LAUNCHES` (the oldest go first);
- ``lti_outbox``: scores waiting for the platform (:mod:`.grades`), ``lti_grades``: per line item and user, the best
  fraction queued and the timestamp of the last score (strictly increasing). Bounded: :data:`MAX_OUTBOX` waiting.

A launch's records are written in one transaction after every check (:meth:`Ledger.record_launch`): a refused
launch creates nothing, and a killed process leaves the last committed write.
"""

from __future__ import annotations

import hashlib
import json
import secrets
import sqlite3
import threading
import time
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from tpm_viz.classroom.store import SqliteStore
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import DEFAULT_DEPTH, loads_json
from tpm_viz.core.words import Phrase
from tpm_viz.lti.refusals import Refused, Why

__all__ = ["MAX_LAUNCHES", "MAX_OUTBOX", "Ledger", "Outgoing", "grade_key"]

MAX_LAUNCHES = 50_000
MAX_OUTBOX = 20_000
MAX_BODY = 16 << 10


def grade_key(issuer: str, client_id: str, lineitem: str, subject: str) -> str:
    """The key of one user's result in one line item (SHA-256 hex of the four, as JSON)."""
    return hashlib.sha256(json.dumps([issuer, client_id, lineitem, subject]).encode()).hexdigest()


@dataclass(frozen=True)
class Outgoing:
    """A score waiting in the outbox: its row, grade key, body (what to send) and tries so far."""

    id: int
    grade: str
    body: dict[str, Any]
    tries: int


def _load(text: Any) -> dict[str, Any] | None:
    if not isinstance(text, str) or len(text) > MAX_BODY:
        return None
    try:
        value = loads_json(text, "an LTI record", DEFAULT_DEPTH)
    except InputError:
        return None
    return value if isinstance(value, dict) else None


class Ledger:
    """The LTI records of the store at ``path`` (made and migrated if needed; thread-safe)."""

    def __init__(self, path: Path, clock: Callable[[], float] = time.time) -> None:
        SqliteStore(Path(path)).close()  # creates or migrates the schema (refuses a newer or damaged store)
        self.path, self.clock = Path(path), clock
        self._lock = threading.Lock()
        self._db = sqlite3.connect(self.path, timeout=10.0, isolation_level=None, check_same_thread=False)
        self._db.execute("PRAGMA journal_mode=WAL")
        self._db.execute("PRAGMA synchronous=FULL")

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        with self._lock:
            self._db.execute("BEGIN IMMEDIATE")
            try:
                yield self._db
            except BaseException:
                self._db.execute("ROLLBACK")
                raise
            self._db.execute("COMMIT")

    def close(self) -> None:
        with self._lock:
            self._db.close()

    # -- the class's course ------------------------------------------------------------------------------------------
    def course(self) -> dict[str, Any] | None:
        """``{"issuer", "id", "title"}`` of the course this server's class is bound to, or None."""
        with self._lock:
            row = self._db.execute("SELECT body FROM lti_class WHERE id = 1").fetchone()
        return None if row is None else _load(row[0])

    # -- launches -------------------------------------------------------------------------------------------------
    def record_launch(self, issuer: str, subject: str, course: dict[str, str], body: dict[str, Any]) -> tuple[str, str]:
        """In one transaction: bind the class to ``course`` (``issuer``, ``id``, ``title``) if it is bound to none
        (another course: :class:`Refused`, *course*), the user ``(issuer, subject)``'s identity (made on the first
        launch) and the launch record ``body``; returns ``(user identity, launch ref)``."""
        ref = secrets.token_hex(16)
        now = self.clock()
        with self._tx() as db:
            row = db.execute("SELECT body FROM lti_class WHERE id = 1").fetchone()
            bound = None if row is None else _load(row[0])
            if bound is not None and (bound.get("issuer"), bound.get("id")) != (course["issuer"], course["id"]):
                raise Refused(
                    Why.COURSE,
                    Phrase(
                        "this tpm-viz serves the course {bound}; the launch is from the course {other} (course): "
                        "serve that course with another tpm-viz (another --session and port)",
                        bound=str(bound.get("title"))[:120],
                        other=course["title"][:120],
                    ),
                )
            if bound is None or bound.get("title") != course["title"]:
                db.execute("INSERT OR REPLACE INTO lti_class VALUES (1, ?)", (json.dumps(course, sort_keys=True),))
            found = db.execute(
                "SELECT ident FROM lti_users WHERE issuer = ? AND subject = ?", (issuer, subject)
            ).fetchone()
            ident = found[0] if found is not None else secrets.token_hex(16)
            db.execute("INSERT OR REPLACE INTO lti_users VALUES (?, ?, ?, ?)", (issuer, subject, ident, now))
            text = json.dumps({**body, "user": ident}, sort_keys=True, allow_nan=False)[:MAX_BODY]
            db.execute("INSERT INTO lti_launches VALUES (?, NULL, ?, ?)", (ref, text, now))
            (count,) = db.execute("SELECT COUNT(*) FROM lti_launches").fetchone()
            if count > MAX_LAUNCHES:
                db.execute(
                    "DELETE FROM lti_launches WHERE ref IN (SELECT ref FROM lti_launches ORDER BY at LIMIT ?)",
                    (count - MAX_LAUNCHES,),
                )
        return ident, ref

    def launch(self, ref: str) -> dict[str, Any] | None:
        """The record of launch ``ref`` (with its ``user``), or None."""
        with self._lock:
            row = self._db.execute("SELECT body FROM lti_launches WHERE ref = ?", (str(ref),)).fetchone()
        body = None if row is None else _load(row[0])
        return None if body is None else {**body, "ref": str(ref)}

    def arrived(self, ref: str, browser: str) -> None:
        """Launch ``ref`` arrived in the browser ``browser`` (a hashed cookie identity)."""
        with self._tx() as db:
            db.execute("UPDATE lti_launches SET browser = NULL WHERE browser = ?", (browser,))
            db.execute("UPDATE lti_launches SET browser = ? WHERE ref = ?", (browser, ref))

    def launch_of_browser(self, browser: str) -> dict[str, Any] | None:
        """The launch the browser ``browser`` last arrived with, or None."""
        with self._lock:
            row = self._db.execute("SELECT ref FROM lti_launches WHERE browser = ?", (browser,)).fetchone()
        return None if row is None else self.launch(row[0])

    def users(self) -> int:
        with self._lock:
            return int(self._db.execute("SELECT COUNT(*) FROM lti_users").fetchone()[0])

    def counts(self) -> dict[str, int]:
        """Rows per LTI table (tests: a refused launch creates nothing)."""
        tables = ("lti_users", "lti_class", "lti_launches", "lti_outbox", "lti_grades")
        with self._lock:
            return {t: int(self._db.execute(f"SELECT COUNT(*) FROM {t}").fetchone()[0]) for t in tables}

    # -- the outbox (grades.py) ----------------------------------------------------------------------------------------
    def queue(self, grade: str, fraction: float, best: bool, body: Callable[[float, float], dict[str, Any]]) -> bool:
        """Queue the score of ``grade``: ``fraction`` (with ``best``: the best fraction queued so far, and nothing
        when it does not improve on it). ``body(fraction, time)`` is the row to keep; the time is strictly later
        than the last score's of this grade. An older waiting score of this grade is dropped: AGS keeps the latest
        per user and line item. False: nothing new to send; :class:`InputError` when the outbox is full."""
        with self._tx() as db:
            row = db.execute("SELECT best, stamp FROM lti_grades WHERE grade = ?", (grade,)).fetchone()
            top = fraction if row is None else max(fraction, float(row[0]))
            if best and row is not None and fraction <= float(row[0]):
                return False
            at = self.clock() if row is None else max(self.clock(), float(row[1]) + 0.001)
            db.execute("DELETE FROM lti_outbox WHERE grade = ? AND state = 'pending'", (grade,))
            (waiting,) = db.execute("SELECT COUNT(*) FROM lti_outbox WHERE state = 'pending'").fetchone()
            if waiting >= MAX_OUTBOX:
                raise InputError(Phrase("{n} grades are waiting for the LMS already; this one is not kept", n=waiting))
            text = json.dumps(body(top if best else fraction, at), sort_keys=True, allow_nan=False)
            db.execute(
                "INSERT INTO lti_outbox (grade, body, state, tries, due, why) VALUES (?, ?, 'pending', 0, ?, '')",
                (grade, text, self.clock()),
            )
            db.execute("INSERT OR REPLACE INTO lti_grades VALUES (?, ?, ?)", (grade, top, repr(at)))
        return True

    def due(self, limit: int = 20) -> tuple[list[Outgoing], float | None]:
        """Up to ``limit`` waiting scores due now, and when the next one is due (None: none waiting)."""
        now = self.clock()
        with self._lock:
            rows = self._db.execute(
                "SELECT id, grade, body, tries FROM lti_outbox WHERE state = 'pending' AND due <= ? ORDER BY due "
                "LIMIT ?",
                (now, limit),
            ).fetchall()
            nxt = self._db.execute("SELECT MIN(due) FROM lti_outbox WHERE state = 'pending'").fetchone()[0]
        out = [Outgoing(int(i), g, b, int(t)) for i, g, text, t in rows if (b := _load(text)) is not None]
        return out, None if nxt is None else float(nxt)

    def sent(self, row: int) -> None:
        with self._tx() as db:
            db.execute("DELETE FROM lti_outbox WHERE id = ?", (row,))

    def retry(self, row: int, due: float, why: str) -> None:
        with self._tx() as db:
            db.execute("UPDATE lti_outbox SET tries = tries + 1, due = ?, why = ? WHERE id = ?", (due, why[:300], row))

    def failed(self, row: int, why: str) -> None:
        """The platform refused the score for good: kept (never lost) as ``failed`` with its reason."""
        with self._tx() as db:
            db.execute("UPDATE lti_outbox SET state = 'failed', why = ? WHERE id = ?", (why[:300], row))

    def outbox(self) -> list[tuple[str, int, str]]:
        """``(state, tries, why)`` of every row of the outbox (tests and the docs' example)."""
        with self._lock:
            return [tuple(r) for r in self._db.execute("SELECT state, tries, why FROM lti_outbox ORDER BY id")]
