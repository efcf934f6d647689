"""The first visit's guide remembers browsers (tpm_viz/ui/guide.py): in memory, bounded, and in the lecture's store
across a restart; a store that fails to write or read costs only the memory's view, never an exception."""

from __future__ import annotations

import hashlib
import sqlite3
from types import SimpleNamespace

import pytest

from tpm_viz.classroom.store import SqliteStore
from tpm_viz.ui import guide
from tpm_viz.ui.guide import Guides, entry


def test_a_browser_is_remembered_and_another_is_not():
    guides = Guides()
    assert not guides.seen("c:one") and not guides.seen(None)
    guides.remember("c:one")
    guides.remember(None)  # not a browser: nothing to remember
    assert guides.seen("c:one") and not guides.seen("c:two") and not guides.seen(None)


def test_memory_is_bounded_oldest_first(monkeypatch):
    monkeypatch.setattr(guide, "REMEMBERED", 3)
    guides = Guides()
    for name in ("a", "b", "c"):
        guides.remember(name)
    assert guides.seen("a")  # seen again: now the newest
    guides.remember("d")  # over the bound: "b", the oldest, goes
    assert [guides.seen(n) for n in ("a", "b", "c", "d")] == [True, False, True, True]


def test_the_store_keeps_it_across_a_restart(tmp_path):
    path = tmp_path / "lecture.sqlite3"
    store = SqliteStore(path)
    Guides(SimpleNamespace(store=store)).remember("c:browser")
    store.close()
    again = SqliteStore(path)  # a restart: a new app, its memory empty
    try:
        assert Guides(SimpleNamespace(store=again)).seen("c:browser")
        assert not Guides(SimpleNamespace(store=again)).seen("c:other")
    finally:
        again.close()
    with sqlite3.connect(path) as db:  # what is kept: a hash, never the identity itself
        keys = [row[0] for row in db.execute("SELECT digest FROM imports")]
    assert keys == [hashlib.sha256(b"guide:c:browser").hexdigest()] == [entry("c:browser")]


class _Broken:
    def imported(self, digest):
        raise sqlite3.OperationalError("disk I/O error")

    def mark_imported(self, digest, source):
        raise sqlite3.OperationalError("database or disk is full")


def test_a_failing_store_costs_only_itself():
    guides = Guides(SimpleNamespace(store=_Broken()))
    assert not guides.seen("c:x")  # unreadable: the guide is shown rather than the page failing
    guides.remember("c:x")  # a full disk: remembered in memory all the same
    assert guides.seen("c:x")


@pytest.mark.parametrize("identity", ["c:" + "0" * 64, "a:" + "f" * 64])
def test_entries_are_hex_digests(identity):
    assert len(entry(identity)) == 64 and int(entry(identity), 16) >= 0
