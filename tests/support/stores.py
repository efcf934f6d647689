"""Reading a classroom store from a test while a server writes it (SQLite in WAL mode: a reader never sees half a
save), and the cookie a browser gets from the page."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from tests.support.storm import page_cookie
from tpm_viz.classroom.records import Records
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.classroom.store import SqliteStore

__all__ = ["page_cookie", "stored_lecture", "stored_tabs"]


def stored_lecture(path: Path) -> tuple[Saved, int] | None:
    """The shared mechanism and lesson step kept in the store at ``path`` (None: none yet)."""
    store = SqliteStore(Path(path))
    try:
        contents = store.load()
        return None if contents.lecture is None else Records(store).read_lecture(contents.lecture)
    finally:
        store.close()


def stored_tabs(path: Path, now: float) -> dict[str, list[dict[str, Any]]]:
    """The remembered tabs kept in the store at ``path`` (hashed identity -> records), as of ``now``."""
    store = SqliteStore(Path(path))
    try:
        return Records(store).read_copies(store.load().copies, now)[0]
    finally:
        store.close()
