"""The exercise results (tpm_viz.classroom.results, .resultsdb): one row per graded answer in the store, written in
one transaction; the bounds (refused, never evicted); an old store (schema 1) migrated; the seeds from the cookie
secret kept beside the store; the class seed kept; the score sink; the CSV.

Expected values come from the rules as the docs state them: a seed is HMAC-SHA256 computed here from the secret file's
bytes (``docs/exercises.md``), a score from the lesson file's ladder, the best score the maximum of the scores the
student got."""

from __future__ import annotations

import csv
import hashlib
import hmac
import io
import sqlite3
import threading

import pytest

from tpm_viz.app.exercises.catalogue import by_id
from tpm_viz.app.exercises.grading import reference, variant_of
from tpm_viz.classroom.identity import SECRET_FILE, Keys
from tpm_viz.classroom.results import CSV_COLUMNS, SEED_PURPOSE, Gradebook, spreadsheet_safe
from tpm_viz.classroom.resultsdb import Bounds, ResultRows
from tpm_viz.classroom.store import SCHEMA, SqliteStore

KEY = bytes(range(32))
EXAM = "force-at-pose"  # attempts = [1.0, 0.7, 0.5]
HOMEWORK = "actuator-position"  # attempts = "homework"

SCHEMA_1 = (  # the tables of a store written before the results (tpm-viz at the exercise engine's merge)
    "CREATE TABLE lecture (id INTEGER PRIMARY KEY CHECK (id = 1), body TEXT NOT NULL, saved REAL)",
    "CREATE TABLE copies (ident TEXT PRIMARY KEY, address TEXT NOT NULL, updated REAL NOT NULL, "
    "size INTEGER NOT NULL, body TEXT NOT NULL)",
    "CREATE TABLE blobs (digest TEXT PRIMARY KEY, data BLOB NOT NULL, size INTEGER NOT NULL, used REAL NOT NULL)",
    "CREATE TABLE imports (digest TEXT PRIMARY KEY, source TEXT NOT NULL, at REAL NOT NULL)",
)


def _right(book: Gradebook, identity: str, ident: str) -> str:
    exercise = book.exercises[ident].exercise
    return f"{reference(exercise, variant_of(exercise, book.seed(identity, ident)))[0]:.4f}"


def _doc_seed(key: bytes, identity: str, ident: str) -> int:
    """``docs/exercises.md``: HMAC-SHA256(key, identity ␟ exercise id), its first 8 bytes big-endian >> 11."""
    digest = hmac.new(key, f"{identity}\x1f{ident}".encode(), hashlib.sha256).digest()
    return int.from_bytes(digest[:8], "big") >> 11


def test_an_answer_is_one_row_in_the_store_and_the_ladder_scores_later_attempts_less(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3")
    book = Gradebook(store.results, KEY, clock=lambda: 1_700_000_000.0)
    ladder = by_id(EXAM).exercise.attempts.ladder
    assert book.submit("c:ann", EXAM, "not a number").grade.format_error is not None  # no attempt used
    first = book.submit("c:ann", EXAM, "0")
    second = book.submit("c:ann", EXAM, _right(book, "c:ann", EXAM))
    assert first.grade.score == 0.0 and second.grade.score == pytest.approx(ladder[1])
    store.close()
    again = SqliteStore(tmp_path / "s.sqlite3")  # what a restart reads
    rows = again.results.of("c:ann")
    assert [(r.attempt, r.answer, r.score, r.label) for r in rows] == [
        (1, "0", 0.0, "Student 1"),
        (2, second.attempts[-1].answer, pytest.approx(ladder[1]), "Student 1"),
    ]
    assert rows[0].seed == _doc_seed(KEY, "c:ann", EXAM) and rows[0].time == 1_700_000_000.0
    third = Gradebook(again.results, KEY).submit("c:ann", EXAM, "1")
    assert third.grade.attempts_left == 0 and len(third.attempts) == 3
    refused = Gradebook(again.results, KEY).submit("c:ann", EXAM, _right(book, "c:ann", EXAM))
    assert refused.grade is None and str(refused.refusal) == "no attempts left" and len(again.results.of("c:ann")) == 3


def test_an_old_store_gets_the_results_tables_and_keeps_everything_else(tmp_path):
    path = tmp_path / "old.sqlite3"
    db = sqlite3.connect(path)
    for statement in SCHEMA_1:
        db.execute(statement)
    db.execute("INSERT INTO lecture VALUES (1, ?, 0)", ('{"lesson_step": 2}',))
    db.execute("INSERT INTO imports VALUES ('ab', 'x.json', 1.0)")
    db.execute("PRAGMA user_version = 1")
    db.commit()
    db.close()
    store = SqliteStore(path)
    assert store.load().lecture == {"lesson_step": 2} and store.imported("ab")
    assert Gradebook(store.results, KEY).submit("c:bo", HOMEWORK, "1").grade.score is not None
    store.close()
    db = sqlite3.connect(path)
    assert db.execute("PRAGMA user_version").fetchone()[0] == SCHEMA  # through every migration (LTI, results)
    assert db.execute("SELECT identity, attempt FROM results").fetchall() == [("c:bo", 1)]
    db.close()


@pytest.mark.parametrize(
    ("bounds", "who", "ident", "line"),
    [
        (Bounds(per_exercise=3), "c:cy", HOMEWORK, "no attempts left: 3 answers to one exercise are kept"),
        (Bounds(per_student=3), "c:cy", "leg-angle", "no attempts left: 3 answers per student are kept"),
        (Bounds(total=3), "c:dee", "leg-angle", "the results store is full (3 answers): tell the lecturer"),
    ],
)
def test_at_a_bound_an_answer_is_refused_with_one_line_and_nothing_is_evicted(bounds, who, ident, line):
    rows = ResultRows.memory()
    book = Gradebook(rows, KEY, bounds=bounds)
    kept = [book.submit("c:cy", HOMEWORK, text).grade.score for text in ("1", "2", "3")]  # homework: unlimited
    assert all(score is not None for score in kept) and rows.count() == 3
    refused = book.submit(who, ident, "1")
    assert refused.grade is None and str(refused.refusal) == line and rows.count() == 3
    assert [r.answer for r in rows.of("c:cy")] == ["1", "2", "3"]  # the first ones stay
    assert book.submit(who, ident, "kg").grade.format_error is not None  # a format error is still said


def test_two_tabs_of_one_student_answering_at_once_never_share_an_attempt():
    rows = ResultRows.memory()
    book = Gradebook(rows, KEY)
    start = threading.Barrier(6)
    out = []

    def answer() -> None:
        start.wait()
        out.append(book.submit("c:eve", EXAM, "0"))

    threads = [threading.Thread(target=answer) for _ in range(6)]
    for t in threads:
        t.start()
    for t in threads:
        t.join(timeout=60)
    attempts = [r.attempt for r in rows.of("c:eve")]
    assert attempts == [1, 2, 3]  # the ladder's three, each once
    refused = [s for s in out if s.grade is None]
    assert len(refused) == 3 and all(s.refusal is not None for s in refused)


def test_the_score_sink_hears_each_kept_answer_once_after_it_is_kept():
    rows = ResultRows.memory()
    book = Gradebook(rows, KEY)
    heard = []

    def sink(identity, exercise, best, latest):
        heard.append((identity, exercise, best, latest, rows.count()))
        raise RuntimeError("the LMS is down")  # logged; the answer stays kept

    book.sink = sink
    book.submit("c:fay", EXAM, "?")  # a format error: not heard
    got = [book.submit("c:fay", EXAM, text).grade.score for text in ("0", _right(book, "c:fay", EXAM), "0")]
    book.submit("c:fay", EXAM, "0")  # no attempts left: not heard
    best = [max(got[: k + 1]) for k in range(3)]
    assert heard == [("c:fay", EXAM, best[k], got[k], k + 1) for k in range(3)]
    assert rows.count() == 3


def test_the_seed_key_comes_from_the_cookie_secret_and_survives_a_restart(tmp_path):
    keys, notice = Keys.in_folder(tmp_path)
    assert notice is None
    secret = (tmp_path / SECRET_FILE).read_bytes()
    key = hmac.new(secret, f"tpm-viz derive: {SEED_PURPOSE}".encode(), hashlib.sha256).digest()
    assert keys.derive(SEED_PURPOSE) == key == Keys.in_folder(tmp_path)[0].derive(SEED_PURPOSE)
    book = Gradebook(ResultRows.memory(), key)
    assert book.seed("c:gus", EXAM) == _doc_seed(key, "c:gus", EXAM) != book.seed("c:hal", EXAM)
    other = Keys.in_folder(tmp_path / "another-server")[0].derive(SEED_PURPOSE)
    assert Gradebook(ResultRows.memory(), other).seed("c:gus", EXAM) != book.seed("c:gus", EXAM)


def test_the_class_seed_is_everybody_s_until_unfixed_and_is_kept(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3")
    book = Gradebook(store.results, KEY)
    assert book.fix("  1234 ") == 1234
    assert {book.seed(who, ident) for who in ("c:a", "c:b") for ident in (EXAM, HOMEWORK)} == {1234}
    row = book.submit("c:a", EXAM, "0").attempts[-1]
    assert (row.seed, row.shared) == (1234, True)
    with pytest.raises(Exception, match="whole number"):
        book.fix("-3")
    assert Gradebook(store.results, KEY).class_seed == 1234  # kept: a restart keeps the exam on the wall
    book.fix(None)
    assert book.seed("c:a", EXAM) == _doc_seed(KEY, "c:a", EXAM) and Gradebook(store.results, KEY).class_seed is None
    assert book.attempts("c:a", EXAM) == ()  # the own variant's ladder: untouched by the class seed's attempt
    store.results.set_setting("class_seed", "garbage")
    assert Gradebook(store.results, KEY).class_seed is None
    store.close()


def test_the_csv_has_a_line_per_student_exercise_and_variant_and_no_formula():
    rows = ResultRows.memory()
    book = Gradebook(rows, KEY, clock=lambda: 0.0)
    book.submit("c:ivy", HOMEWORK, "=HYPERLINK(1)")  # not a number: a format error, not kept
    book.submit("c:ivy", HOMEWORK, "-1")
    book.submit("c:ivy", HOMEWORK, "+2")
    book.submit("c:jo", EXAM, "0")
    lines = list(csv.reader(io.StringIO(book.csv())))
    assert tuple(lines[0]) == CSV_COLUMNS
    body = {(r[0], r[1]): r for r in lines[1:]}
    assert set(body) == {("Student 1", HOMEWORK), ("Student 2", EXAM)}
    ivy = body[("Student 1", HOMEWORK)]
    assert ivy[2:5] == ["own", str(_doc_seed(KEY, "c:ivy", HOMEWORK)), "2"] and ivy[7:] == [
        "'+2",
        "1970-01-01T00:00:00Z",
    ]
    assert spreadsheet_safe("=1+1") == "'=1+1" and spreadsheet_safe("@x") == "'@x" and spreadsheet_safe("12") == "12"
