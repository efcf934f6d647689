"""The classroom store (tpm_viz.classroom.store, .records): blobs by content, bounds, records skipped not fatal,
stores it cannot read moved aside (never overwritten), the one-time import of a real old JSON session file."""

from __future__ import annotations

import hashlib
import io
import json
import shutil
import sqlite3
from contextlib import redirect_stderr
from pathlib import Path

import numpy as np
import pytest

from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState
from tpm_viz.classroom.records import Records
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.classroom.store import SCHEMA, Copy, Limits, SqliteStore, open_store
from tpm_viz.core.params import Params
from tpm_viz.paper.trajectories import Trajectory
from tpm_viz.ui.continuity import lecture_store as Store

OLD = Path(__file__).resolve().parents[1] / "fixtures" / "session-v1.json"
"""A session file written by tpm-viz before the store (a real server: lecture with an uploaded CSV and lesson step
2, and one browser's own copy with l_a = 280 mm)."""


def _csv(n: int = 11) -> Source:
    t = np.linspace(0.0, 0.5, n)
    p = np.column_stack([0.04 * np.sin(4 * t), 0.02 * np.cos(4 * t)])
    return Source.from_trajectory(Trajectory("upload", t, p, np.zeros_like(p), np.zeros_like(p)))


def test_a_blob_is_kept_once_under_its_sha256(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3")
    data = b"t,p1,p2\n0,0,0\n"
    digest = store.put_blob(data)
    assert digest == hashlib.sha256(data).hexdigest() and store.put_blob(data) == digest
    assert store.get_blob(digest) == data and store.get_blob("0" * 64) is None and store.get_blob("x") is None
    assert sqlite3.connect(tmp_path / "s.sqlite3").execute("SELECT COUNT(*) FROM blobs").fetchone()[0] == 1


@pytest.mark.slow
def test_nine_students_with_one_upload_keep_it_once_and_everything_reads_back(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3")
    records, source = Records(store), _csv(20_000)
    mine = Saved(AppState.initial(Params.paper(l_a=0.28)), source, 0.1)
    tabs = {f"c:{k:064x}": [{"private": True, "saved": mine, "left_at": 1e9, "address": "10.0.0.9"}] for k in range(9)}
    doc = Document(Saved(AppState.initial(), source), lesson_step=3, tabs=tabs)
    store.save(records.lecture(doc), records.copies(doc), ())
    store.close()
    again = SqliteStore(tmp_path / "s.sqlite3")
    contents = again.load()
    shared, step = Records(again).read_lecture(contents.lecture)
    back, skipped = Records(again).read_copies(contents.copies, now=1e9 + 1)
    assert step == 3 and skipped == 0 and len(back) == 9
    np.testing.assert_allclose(shared.source.knots[1], source.knots[1])
    (record,) = back[f"c:{0:064x}"]
    assert record["private"] and record["address"] == "10.0.0.9" and record["saved"].state.params.l_a == 0.28
    count = sqlite3.connect(tmp_path / "s.sqlite3").execute("SELECT COUNT(*) FROM blobs").fetchone()[0]
    assert count == 1  # ten mechanisms, one trajectory
    assert (tmp_path / "s.sqlite3").stat().st_size < 2 * 20_000 * 3 * 25  # not ten copies of it


def test_sizes_are_bounded_and_the_lecture_is_never_evicted(tmp_path):
    store = SqliteStore(tmp_path / "s.sqlite3", Limits(copy_bytes=2000, copies_bytes=5000))
    store.save({"lecture": "x" * 3000}, {}, ())
    body = {"tabs": ["y" * 1000]}
    store.save(None, {f"k{i}": Copy("10.0.0.1", float(i), body) for i in range(8)}, ())
    store.save(None, {"huge": Copy("10.0.0.2", 99.0, {"tabs": ["z" * 5000]})}, ())  # over one record's size
    contents = store.load()
    assert sorted(contents.copies) == ["k4", "k5", "k6", "k7"]  # the oldest went, ~1 kB each under 5 kB
    assert contents.lecture == {"lecture": "x" * 3000}


@pytest.mark.parametrize("bad", ["[" * 200_000, "{not json", '"a string"', "1e999999"])
def test_a_bad_record_is_skipped_and_the_rest_load(tmp_path, bad):
    path = tmp_path / "s.sqlite3"
    store, records = SqliteStore(path), None
    records = Records(store)
    good = Document(
        Saved(AppState.initial()),
        tabs={"c:good": [{"private": True, "saved": Saved(AppState.initial()), "left_at": 1e9, "address": "a"}]},
    )
    store.save(records.lecture(good), records.copies(good), ())
    db = sqlite3.connect(path)
    db.execute("INSERT INTO copies VALUES ('c:bad', 'a', 1.0, ?, ?)", (len(bad), bad))
    db.execute(
        "INSERT INTO copies VALUES ('c:params', 'a', 1.0, 10, ?)",
        (json.dumps({"tabs": [{"left_at": 1e9, "saved": {"params": {"l_a": -1}}}]}),),
    )
    db.commit()
    contents = store.load()
    tabs, skipped = records.read_copies(contents.copies, now=1e9 + 1)
    assert list(tabs) == ["c:good"] and contents.skipped + skipped == 2


def _stores(tmp_path: Path) -> dict[str, Path]:
    """Store files it cannot read, each made as the attack that found it."""
    real = tmp_path / "real.sqlite3"
    store = SqliteStore(real)
    store.save({"lecture": 1}, {"c:a": Copy("a", 1.0, {"tabs": ["p" * 50_000]})}, ())
    store.close()
    made = {}
    made["truncated"] = tmp_path / "truncated.sqlite3"
    made["truncated"].write_bytes(real.read_bytes()[: real.stat().st_size // 2])
    made["newer"] = tmp_path / "newer.sqlite3"
    shutil.copy(real, made["newer"])
    db = sqlite3.connect(made["newer"])
    db.execute(f"PRAGMA user_version = {SCHEMA + 1}")
    db.close()
    made["brackets"] = tmp_path / "brackets.sqlite3"
    made["brackets"].write_text("[" * 200_000)
    made["oversized"] = tmp_path / "oversized.sqlite3"
    shutil.copy(real, made["oversized"])
    return made


@pytest.mark.parametrize("kind", ["truncated", "newer", "brackets", "oversized"])
def test_a_store_it_cannot_read_is_moved_aside_with_the_time_never_overwritten(tmp_path, kind):
    path = _stores(tmp_path)[kind]
    before = path.read_bytes()
    limits = Limits(file_bytes=64 << 10) if kind == "oversized" else Limits()
    store, notice = open_store(path, limits)
    aside = [p for p in tmp_path.iterdir() if p.name.startswith(path.name + ".unreadable-")]
    assert len(aside) == 1 and aside[0].read_bytes() == before  # every byte kept
    assert notice is not None and "\n" not in notice and str(aside[0]) in notice and str(path) in notice
    assert store.load().lecture is None  # a new, empty store in its place, and it works
    store.save({"lecture": 2}, {}, ())
    assert SqliteStore(path).load().lecture == {"lecture": 2}


def test_the_app_says_so_in_one_line_and_starts(tmp_path):
    path = _stores(tmp_path)["brackets"]
    err = io.StringIO()
    with redirect_stderr(err):
        store = Store(path)
        assert store.load() == (None, {})
        store.stop()
    assert err.getvalue().count("\n") == 1 and "moved to" in err.getvalue() and "Traceback" not in err.getvalue()
    assert store.notices == [err.getvalue().removeprefix("warning: ").strip()]


def test_an_old_json_session_file_is_imported_once_and_left_as_it_is(tmp_path):
    path = tmp_path / "session.json"
    shutil.copy(OLD, path)
    raw = json.loads(OLD.read_text())  # read independently of the app
    err = io.StringIO()
    with redirect_stderr(err):
        store = Store(path)
        doc, tabs = store.load()
        store.stop()
    assert "imported the lecture" in err.getvalue() and "1 remembered tab(s)" in err.getvalue()
    assert doc is not None and doc.lesson_step == raw["lesson_step"] == 2 and tabs == {}
    assert doc.shared.state.params.l_a == pytest.approx(raw["shared"]["params"]["l_a"])
    np.testing.assert_allclose(doc.shared.source.knots[0], raw["shared"]["trajectory"]["t"])
    np.testing.assert_allclose(doc.shared.source.knots[1], raw["shared"]["trajectory"]["p"])
    assert path.read_bytes() == OLD.read_bytes()
    lecture = tmp_path / "session.json.sqlite3"
    db = sqlite3.connect(lecture)
    body = json.loads(db.execute("SELECT body FROM lecture").fetchone()[0])
    body["lesson_step"] = 1  # the lecture goes on in the store ...
    db.execute("UPDATE lecture SET body = ?", (json.dumps(body),))
    db.commit()
    db.close()
    err = io.StringIO()
    with redirect_stderr(err):
        store = Store(path)
        doc, _ = store.load()  # ... and a restart with the same file does not import it again
        store.stop()
    assert doc.lesson_step == 1 and err.getvalue() == ""


def test_fresh_sets_the_store_aside_rather_than_overwriting_it(tmp_path):
    path = tmp_path / "s.sqlite3"
    store = SqliteStore(path)
    store.save({"lecture": 1}, {}, ())
    store.close()
    before = path.read_bytes()
    new, notice = open_store(path, fresh=True)
    aside = [p for p in tmp_path.iterdir() if ".before-fresh-" in p.name and not p.name.endswith(("-wal", "-shm"))]
    assert new.load().lecture is None and len(aside) == 1 and str(aside[0]) in notice
    assert SqliteStore(aside[0]).load().lecture == {"lecture": 1} and len(aside[0].read_bytes()) >= len(before) - 1


def test_an_unwritable_store_path_is_one_line_and_the_lesson_goes_on_unsaved(tmp_path):
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the store's folder should be")
    err = io.StringIO()
    with redirect_stderr(err):
        store = Store(blocker / "classroom.sqlite3")
        assert store.load() == (None, {})
        store.start(lambda: None, lambda line, problem: None)  # nothing to save to: no thread, no traceback
        store.stop()
    assert err.getvalue().count("\n") == 1 and "nothing will be saved" in err.getvalue()
    assert str(blocker) in err.getvalue() and "Traceback" not in err.getvalue()
    assert blocker.read_text().startswith("a file")
