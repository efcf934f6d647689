"""The classroom's store and identities against a live server, each with the attack that found it: a replayed
presenter cookie from another address, a forged cookie, a failing save shown to the lecturer, a server killed
mid-lesson, and 100 own-copy tabs reconnecting at once (every copy back; the timing is benchmarks/bench_reconnect.py).

Every server listens on 127.0.0.1 (the other device: a connection from 127.0.0.2).
"""

from __future__ import annotations

import asyncio
import io
import os
import signal
import sqlite3
import time
from contextlib import redirect_stderr

import pytest

from tests.support.pages import TOKEN, Page, classroom_app, views_of
from tests.support.protocol import ServerProcess, wait_for
from tests.support.stores import page_cookie, stored_tabs
from tests.support.storm import storm
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import Classroom
from tpm_viz.ui.continuity import lecture_store as Store

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

__all__ = ["classroom_app"]  # the fixture, imported


def test_a_replayed_presenter_cookie_from_another_address_is_a_student(classroom_app):
    app = classroom_app
    lecturer = Page(app.port)  # "this computer"
    views_of(app, 1)
    cookie = page_cookie(app.port)
    tablet = Page(app.port, cookie=cookie)  # the lecturer's tablet logs in
    tv = next(v for v in views_of(app, 2) if not app.access.is_presenter(v))
    tablet.set("Presenter token", TOKEN)
    tablet.set("Log in as presenter", True)
    wait_for(lambda: app.access.is_presenter(tv), what="the login")
    tablet.close()
    wait_for(lambda: len(app.views) == 1, what="the tablet gone")
    thief = Page(app.port, cookie=cookie, source="127.0.0.2")  # the same cookie, another device
    views = views_of(app, 2)
    (tv,) = [v for v in views if v.address == "127.0.0.2"]
    assert not app.access.is_presenter_tab(tv) and "welcome back" not in tv.login.status.content
    for page in (thief, lecturer):
        page.close()


def test_a_forged_cookie_owns_nothing(classroom_app):
    app = classroom_app
    cookie = page_cookie(app.port)
    page = Page(app.port, cookie=cookie, origin=f"http://127.0.0.1:{app.port}")
    (view,) = views_of(app, 1)
    page.set("Work on my own copy", True)
    wait_for(lambda: not view.session.shared, what="own copy")
    page.close()
    wait_for(lambda: not app.views, what="gone")
    ident = cookie.split("=", 1)[1].split(".")[0]
    forged = Page(app.port, cookie=f"tpmviz_id={ident}.{'0' * 32}")  # the id guessed, the signature not
    (fv,) = views_of(app, 1)
    with app.hub.lock:
        assert fv.session.shared and not fv.panel.restore.visible
    forged.close()
    wait_for(lambda: not app.views, what="gone")
    back = Page(app.port, cookie=cookie)  # the real browser still gets its copy
    (bv,) = views_of(app, 1)
    wait_for(lambda: not bv.session.shared, what="the copy back")
    back.close()


def test_a_failing_save_is_said_once_to_the_terminal_and_the_lecturers_panel(tmp_path, monkeypatch):
    store = Store(tmp_path / "classroom.sqlite3")
    with redirect_stderr(io.StringIO()):
        store.open()
    room = Classroom(addresses=lambda: ["192.0.2.7"], presenter_address=lambda host: True, token=TOKEN)
    app = TpmApp(build_server("127.0.0.1", 0), classroom=room, store=store)
    try:
        page = Page(app.port)
        (view,) = views_of(app, 1)
        panel = app.room._lecturers[view]

        def full(*args):
            raise sqlite3.OperationalError("database or disk is full")

        saver = store._saver
        err = io.StringIO()
        with redirect_stderr(err):
            monkeypatch.setattr(store.store, "save", full)
            for _ in range(3):
                saver.tick()  # the thread's ticks, at once
                saver._written.clear()  # something to save each time
            wait_for(lambda: panel.notice.visible, what="the lecturer told")
            assert "disk is full" in panel.notice.content and "retrying" in panel.notice.content
            monkeypatch.undo()
            saver.tick()
        lines = err.getvalue().splitlines()
        assert len(lines) == 2 and "disk is full" in lines[0] and "saved again" in lines[1], lines
        assert "saved again" in panel.notice.content and "Traceback" not in err.getvalue()
        page.close()
    finally:
        app.stop()


def test_a_server_killed_mid_lesson_gives_every_acknowledged_copy_back(tmp_path):
    path = tmp_path / "classroom.sqlite3"
    first = ServerProcess(session=path)
    try:
        cookie = page_cookie(first.port)
        page = Page(first.port, cookie=cookie, origin=f"http://127.0.0.1:{first.port}")
        page.set("Work on my own copy", True)
        wait_for(lambda: any(r["private"] for t in stored_tabs(path, time.time()).values() for r in t), timeout=20)
        os.kill(first.pid, signal.SIGKILL)  # no last save, no goodbye
        page.close()
    finally:
        first.stop()
    second = ServerProcess(session=path)
    try:
        back = Page(second.port, cookie=cookie, origin=f"http://127.0.0.1:{second.port}")
        wait_for(lambda: back.value("Work on my own copy") is True, timeout=30, what="the copy back")
        back.close()
    finally:
        second.stop()
    assert not second.log_problems() and not list(tmp_path.glob("*.unreadable-*"))


@pytest.mark.slow
def test_100_own_copy_tabs_reconnecting_at_once_all_get_their_copies_back():
    server = ServerProcess()

    async def settle() -> None:  # the server parked them all: its CPU is quiet
        for _ in range(60):
            before = server.cpu_seconds()
            await asyncio.sleep(0.5)
            if server.cpu_seconds() - before < 0.1:
                return

    try:
        times = asyncio.run(storm(server.port, 100, settle, timeout=300))
    finally:
        server.stop()
    assert None not in times, f"{times.count(None)} of 100 copies not back"
    assert not server.log_problems()
