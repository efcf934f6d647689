"""The classroom store: records behind a small interface (:class:`Store`), kept in SQLite (:class:`SqliteStore`).

Records: the lecture (one row, never evicted), one row per remembered browser (its tabs that left, with the source
address they came from), the uploaded trajectories once each by SHA-256 of their bytes (:meth:`Store.put_blob`), and
(schema 2) the exercise results, written through one transaction per graded answer (:attr:`Store.results`,
:mod:`.resultsdb`).
A record's body is JSON text; one that cannot be read is skipped (:attr:`Contents.skipped`), the rest load.
Schema 2 adds the LTI tool's tables (``lti_*``), read and written by :mod:`tpm_viz.lti.ledger` (docs/lti.md §9).

:func:`open_store` never destroys what it cannot read: a file that is not a SQLite database, is damaged
(``PRAGMA quick_check``), was written by a newer schema (``PRAGMA user_version``) or is larger than
:attr:`Limits.file_bytes` is renamed aside (``<name>.unreadable-<UTC time>``, with its ``-wal`` and ``-shm``), and
a new store is made in its place; the returned notice says so in one line, naming where it went.

SQLite in WAL mode with ``synchronous=FULL``: a save is one transaction, so a kill at any moment leaves the last
committed save (what :meth:`Store.save` returned from). A later deployment over several processes can implement
:class:`Store` over a server database with the same records.
"""

from __future__ import annotations

import hashlib
import json
import os
import re
import sqlite3
import threading
import time
from collections.abc import Callable, Iterable, Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Protocol

from tpm_viz.classroom.resultsdb import TABLES as RESULT_TABLES
from tpm_viz.classroom.resultsdb import ResultRows
from tpm_viz.core.errors import InputError
from tpm_viz.core.files import DEFAULT_DEPTH, loads_json

__all__ = [
    "SCHEMA",
    "Contents",
    "Copy",
    "Limits",
    "SqliteStore",
    "Store",
    "StoreUnreadable",
    "is_sqlite",
    "move_aside",
    "open_store",
]

SCHEMA = 3
"""Schema version (``PRAGMA user_version``); a store of a higher one is moved aside, never half-read. 1: the lecture,
browsers, blobs, imports; 2: and the LTI tables (``tpm_viz.lti``); 3: and the exercise results (:mod:`.resultsdb`)."""
_HEADER = b"SQLite format 3\x00"
_TABLES = (
    "CREATE TABLE IF NOT EXISTS lecture (id INTEGER PRIMARY KEY CHECK (id = 1), body TEXT NOT NULL, saved REAL)",
    "CREATE TABLE IF NOT EXISTS copies (ident TEXT PRIMARY KEY, address TEXT NOT NULL, updated REAL NOT NULL, "
    "size INTEGER NOT NULL, body TEXT NOT NULL)",
    "CREATE TABLE IF NOT EXISTS blobs (digest TEXT PRIMARY KEY, data BLOB NOT NULL, size INTEGER NOT NULL, "
    "used REAL NOT NULL)",
    "CREATE TABLE IF NOT EXISTS imports (digest TEXT PRIMARY KEY, source TEXT NOT NULL, at REAL NOT NULL)",
)
_LTI_TABLES = (  # schema 2: the LTI tool's records (tpm_viz/lti/ledger.py, docs/lti.md)
    "CREATE TABLE IF NOT EXISTS lti_users (issuer TEXT NOT NULL, subject TEXT NOT NULL, ident TEXT NOT NULL UNIQUE, "
    "seen REAL NOT NULL, PRIMARY KEY (issuer, subject))",
    "CREATE TABLE IF NOT EXISTS lti_class (id INTEGER PRIMARY KEY CHECK (id = 1), body TEXT NOT NULL)",
    "CREATE TABLE IF NOT EXISTS lti_launches (ref TEXT PRIMARY KEY, browser TEXT, body TEXT NOT NULL, "
    "at REAL NOT NULL)",
    "CREATE TABLE IF NOT EXISTS lti_outbox (id INTEGER PRIMARY KEY AUTOINCREMENT, grade TEXT NOT NULL, "
    "body TEXT NOT NULL, state TEXT NOT NULL, tries INTEGER NOT NULL, due REAL NOT NULL, why TEXT NOT NULL)",
    "CREATE TABLE IF NOT EXISTS lti_grades (grade TEXT PRIMARY KEY, best REAL NOT NULL, stamp TEXT NOT NULL)",
)
_HEX64 = re.compile(r"[0-9a-f]{64}")
MIGRATIONS: dict[int, tuple[str, ...]] = {0: _TABLES, 1: _LTI_TABLES, 2: RESULT_TABLES}
"""Statements that take a store of schema ``n`` to ``n + 1`` (0: a new, empty database)."""


class StoreUnreadable(InputError):
    """The store file cannot be used (not SQLite, damaged, newer schema, too large): it is moved aside."""


@dataclass(frozen=True)
class Limits:
    """Sizes [bytes] the store keeps to: one browser's record, all browsers' records, one blob, all blobs, the
    file itself when it is opened."""

    copy_bytes: int = 256 << 10
    copies_bytes: int = 32 << 20
    blob_bytes: int = 4 << 20
    blobs_bytes: int = 256 << 20
    file_bytes: int = 512 << 20


@dataclass(frozen=True)
class Copy:
    """A remembered browser's record: the address its tabs came from, when it last changed (wall clock [s]) and
    its body (JSON-ready: :mod:`.records`)."""

    address: str
    updated: float
    body: Any


@dataclass
class Contents:
    """What a store holds: the lecture's body (or None), the browsers' records, and how many records could not be
    read (skipped)."""

    lecture: Any = None
    copies: dict[str, Copy] = field(default_factory=dict)
    skipped: int = 0


class Store(Protocol):
    """The records of one classroom (thread-safe)."""

    @property
    def results(self) -> ResultRows:
        """The exercise results (:mod:`.resultsdb`): one graded answer per transaction, never by :meth:`save`."""

    def load(self) -> Contents:
        """Every record that can be read."""

    def save(self, lecture: Any, copies: Mapping[str, Copy], gone: Iterable[str]) -> None:
        """In one transaction: the lecture (None: unchanged), the given browsers' records, and ``gone`` removed.
        Records over :attr:`Limits.copy_bytes` are not written; the oldest go when all exceed the total."""

    def put_blob(self, data: bytes) -> str:
        """Keep ``data`` (at most :attr:`Limits.blob_bytes`) once; returns its SHA-256 (hex)."""

    def get_blob(self, digest: str) -> bytes | None:
        """The bytes kept under ``digest``, or None."""

    def imported(self, digest: str) -> bool:
        """Whether a file with this SHA-256 was imported already."""

    def mark_imported(self, digest: str, source: str) -> None:
        """Remember that the file ``source`` with this SHA-256 was imported."""

    def close(self) -> None:
        """Release the store."""


def is_sqlite(path: Path) -> bool:
    """Whether ``path`` starts with SQLite's header."""
    try:
        with open(path, "rb") as handle:
            return handle.read(len(_HEADER)) == _HEADER
    except OSError:
        return False


def move_aside(path: Path, why: str = "unreadable", clock: Callable[[], float] = time.time) -> Path:
    """Rename ``path`` (and its ``-wal``, ``-shm``) to ``<name>.<why>-<UTC time>``; returns the new path."""
    stamp = time.strftime("%Y%m%dT%H%M%SZ", time.gmtime(clock()))
    aside = path.with_name(f"{path.name}.{why}-{stamp}")
    n = 1
    while aside.exists():
        n += 1
        aside = path.with_name(f"{path.name}.{why}-{stamp}-{n}")
    os.replace(path, aside)
    for suffix in ("-wal", "-shm"):
        extra = path.with_name(path.name + suffix)
        if extra.exists():
            os.replace(extra, aside.with_name(aside.name + suffix))
    return aside


def open_store(path: Path, limits: Limits = Limits(), fresh: bool = False) -> tuple[SqliteStore, str | None]:
    """The store at ``path`` and a one-line notice (or None). A store that cannot be read, or any store when
    ``fresh`` (start clean), is moved aside first and a new one made."""
    path = Path(path)
    notice = None
    if path.exists() and (fresh or path.stat().st_size > 0):
        try:
            if fresh:
                raise StoreUnreadable("--fresh: starting clean")
            return SqliteStore(path, limits), None
        except (StoreUnreadable, sqlite3.Error, OSError) as exc:
            why = str(exc).splitlines()[0][:160] if str(exc) else type(exc).__name__
            aside = move_aside(path, "before-fresh" if fresh else "unreadable")
            notice = (
                f"the session store {path} was set aside as {aside} (--fresh)"
                if fresh
                else f"the session store {path} could not be read ({why}); it was moved to {aside}, starting with "
                "the defaults"
            )
    return SqliteStore(path, limits), notice


class SqliteStore:
    """:class:`Store` in one SQLite file (see the module docstring). Raises :class:`StoreUnreadable` (or an
    ``sqlite3`` / ``OSError``) when the file cannot be used."""

    def __init__(self, path: Path, limits: Limits = Limits()) -> None:
        self.path, self.limits = Path(path), limits
        self._lock = threading.Lock()
        if self.path.exists() and self.path.stat().st_size > 0:
            if not is_sqlite(self.path):
                raise StoreUnreadable("not a tpm-viz store")
            if self.path.stat().st_size > limits.file_bytes:
                raise StoreUnreadable(f"larger than {limits.file_bytes >> 20} MiB")
        self.path.parent.mkdir(parents=True, exist_ok=True)
        self._db = sqlite3.connect(self.path, timeout=10.0, isolation_level=None, check_same_thread=False)
        try:
            self._db.execute("PRAGMA journal_mode=WAL")
            self._db.execute("PRAGMA synchronous=FULL")
            check = self._db.execute("PRAGMA quick_check").fetchone()
            if check is None or check[0] != "ok":
                raise StoreUnreadable("damaged")
            self._migrate()
            self._results = ResultRows(self._db, self._lock, self._transaction)
        except BaseException:
            self._db.close()
            raise

    def _migrate(self) -> None:
        version = int(self._db.execute("PRAGMA user_version").fetchone()[0])
        if version > SCHEMA:
            raise StoreUnreadable(f"written by a newer tpm-viz (schema {version}; this one reads {SCHEMA})")
        while version < SCHEMA:
            with self._transaction():
                for statement in MIGRATIONS[version]:
                    self._db.execute(statement)
                version += 1
                self._db.execute(f"PRAGMA user_version = {version}")

    def _transaction(self) -> Any:
        return _Transaction(self._db)

    @property
    def results(self) -> ResultRows:
        return self._results

    # -- records ------------------------------------------------------------------------------------------------
    def load(self) -> Contents:
        out = Contents()
        with self._lock:
            row = self._db.execute("SELECT body FROM lecture WHERE id = 1").fetchone()
            rows = self._db.execute("SELECT ident, address, updated, body FROM copies ORDER BY updated").fetchall()
        if row is not None:
            out.lecture = _body(row[0], self.limits.copies_bytes)
            out.skipped += out.lecture is None
        for ident, address, updated, text in rows:
            body = _body(text, self.limits.copy_bytes)
            if body is None or not isinstance(ident, str) or not isinstance(address, str):
                out.skipped += 1
                continue
            out.copies[ident] = Copy(address, float(updated), body)
        return out

    def save(self, lecture: Any, copies: Mapping[str, Copy], gone: Iterable[str]) -> None:
        rows = []
        for ident, copy in copies.items():
            text = json.dumps(copy.body, sort_keys=True, allow_nan=False)
            if len(text) <= self.limits.copy_bytes:
                rows.append((ident, copy.address, copy.updated, len(text), text))
        lecture_text = None if lecture is None else json.dumps(lecture, sort_keys=True, allow_nan=False)
        with self._lock, self._transaction():
            if lecture_text is not None:
                self._db.execute(
                    "INSERT OR REPLACE INTO lecture (id, body, saved) VALUES (1, ?, ?)", (lecture_text, time.time())
                )
            self._db.executemany("DELETE FROM copies WHERE ident = ?", [(g,) for g in gone])
            self._db.executemany("INSERT OR REPLACE INTO copies VALUES (?, ?, ?, ?, ?)", rows)
            total = self._db.execute("SELECT COALESCE(SUM(size), 0) FROM copies").fetchone()[0]
            while total > self.limits.copies_bytes:  # the oldest browsers go; the lecture's row never does
                oldest = self._db.execute("SELECT ident, size FROM copies ORDER BY updated LIMIT 1").fetchone()
                self._db.execute("DELETE FROM copies WHERE ident = ?", (oldest[0],))
                total -= oldest[1]

    # -- blobs --------------------------------------------------------------------------------------------------
    def put_blob(self, data: bytes) -> str:
        if len(data) > self.limits.blob_bytes:
            raise InputError(f"larger than {self.limits.blob_bytes >> 20} MiB: not kept")
        digest = hashlib.sha256(data).hexdigest()
        with self._lock, self._transaction():
            now = time.time()
            if self._db.execute("UPDATE blobs SET used = ? WHERE digest = ?", (now, digest)).rowcount:
                return digest
            self._db.execute("INSERT INTO blobs VALUES (?, ?, ?, ?)", (digest, data, len(data), now))
            total = self._db.execute("SELECT SUM(size) FROM blobs").fetchone()[0]
            keep = self._lecture_blobs() | {digest}
            for old, size in self._db.execute("SELECT digest, size FROM blobs ORDER BY used").fetchall():
                if total <= self.limits.blobs_bytes:
                    break
                if old not in keep:  # least recently used first; never the lecture's
                    self._db.execute("DELETE FROM blobs WHERE digest = ?", (old,))
                    total -= size
        return digest

    def _lecture_blobs(self) -> set[str]:
        row = self._db.execute("SELECT body FROM lecture WHERE id = 1").fetchone()
        return set() if row is None else set(_HEX64.findall(row[0]))

    def get_blob(self, digest: str) -> bytes | None:
        if not (isinstance(digest, str) and _HEX64.fullmatch(digest)):
            return None
        with self._lock:
            row = self._db.execute("SELECT data FROM blobs WHERE digest = ?", (digest,)).fetchone()
        return None if row is None else bytes(row[0])

    # -- imports ------------------------------------------------------------------------------------------------
    def imported(self, digest: str) -> bool:
        with self._lock:
            return self._db.execute("SELECT 1 FROM imports WHERE digest = ?", (digest,)).fetchone() is not None

    def mark_imported(self, digest: str, source: str) -> None:
        with self._lock, self._transaction():
            self._db.execute("INSERT OR REPLACE INTO imports VALUES (?, ?, ?)", (digest, source[:500], time.time()))

    def close(self) -> None:
        with self._lock:
            self._db.close()


class _Transaction:
    """``BEGIN IMMEDIATE`` ... ``COMMIT`` (``ROLLBACK`` on any exception) on an autocommit connection."""

    def __init__(self, db: sqlite3.Connection) -> None:
        self._db = db

    def __enter__(self) -> None:
        self._db.execute("BEGIN IMMEDIATE")

    def __exit__(self, kind: Any, exc: Any, tb: Any) -> None:
        if kind is None:
            self._db.execute("COMMIT")
        elif self._db.in_transaction:
            self._db.execute("ROLLBACK")


def _body(text: Any, limit: int) -> Any:
    """A record's JSON body, or None if it is not text, too large, not JSON or nested too deep."""
    if not isinstance(text, str) or len(text) > limit:
        return None
    try:
        return loads_json(text, "a store record", DEFAULT_DEPTH)
    except InputError:
        return None
