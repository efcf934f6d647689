"""The presenter's right ends when the presenter logs out or another tab logs in (issue 23: "logging out or handing
over ends it"): the tab is a student's from then on, and a presenter tab that dropped from the same address does
not come back as the presenter. Protocol tabs against an in-process app in classroom mode on 127.0.0.1."""

from __future__ import annotations

import threading

import pytest

from tests.support.pages import TOKEN, Page, classroom_app, views_of
from tests.support.protocol import wait_for
from tests.support.stores import page_cookie

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

__all__ = ["classroom_app"]  # the fixture, imported

L_A = "l_a, link length (mm)"


def _tablet_drops_as_presenter(app):
    """The lecturer's tab (this computer), and a tablet that logs in with the token and drops: ``(lecturer page,
    its view, the tablet's cookie)``."""
    lecturer = Page(app.port)
    (lv,) = views_of(app, 1)
    wait_for(lambda: lv in app.arrived, what="the lecturer's tab")
    cookie = page_cookie(app.port)
    tablet = Page(app.port, cookie=cookie)
    tv = next(v for v in views_of(app, 2) if v is not lv)
    tablet.set("Presenter token", TOKEN)
    tablet.set("Log in as presenter", True)
    wait_for(lambda: app.access.is_presenter_tab(tv), what="the tablet's login")
    tablet.close()
    wait_for(lambda: len(app.views) == 1, what="the tablet gone")
    return lecturer, lv, cookie


def test_log_out_ends_the_presenter_right_of_the_tab_and_of_a_dropped_presenter_tab(classroom_app):
    app = classroom_app
    lecturer, lv, cookie = _tablet_drops_as_presenter(app)
    assert app.access.is_presenter_tab(lv) and lv in app.room._lecturers
    before = lecturer.value(L_A)
    lecturer.set("Log out as presenter", True)
    wait_for(lambda: not app.access.is_presenter_tab(lv), what="the logout")
    wait_for(
        lambda: lv not in app.room._lecturers and "logged out as presenter" in lv.panel.message.content,
        what="the Lecturer folder gone, and the tab told (after the folder went, under the lock)",
    )
    lecturer.set(L_A, "300")  # a student's change to the shared mechanism: refused
    lecturer.set("Apply parameters", True)
    wait_for(lambda: lecturer.value(L_A) == before, what="the refused change undone in the tab")
    with app.hub.lock:
        assert app.hub.shared.state.params.l_a * 1e3 == pytest.approx(float(before))
    again = Page(app.port, cookie=cookie)  # the tablet, back from the same address within the window
    views = views_of(app, 2)
    back = next(v for v in views if v is not lv)
    wait_for(lambda: back in app.arrived, what="the tablet back")
    assert not any(app.access.is_presenter_tab(v) for v in views)  # nobody is the presenter any more
    for page in (again, lecturer):
        page.close()


def test_a_new_login_ends_the_way_back_of_a_dropped_presenter_tab(classroom_app):
    app = classroom_app
    lecturer, lv, cookie = _tablet_drops_as_presenter(app)
    student = Page(app.port)  # another device takes over with the token
    sv = next(v for v in views_of(app, 2) if v is not lv)
    student.set("Presenter token", TOKEN)
    student.set("Log in as presenter", True)
    wait_for(lambda: app.access.is_presenter_tab(sv), what="the new presenter's login")
    again = Page(app.port, cookie=cookie)
    back = next(v for v in views_of(app, 3) if v not in (lv, sv))
    wait_for(lambda: back in app.arrived, what="the tablet back")
    assert not app.access.is_presenter_tab(back)  # handed over: the tablet is a student's now
    for page in (again, student, lecturer):
        page.close()


def test_browsers_that_come_back_at_once_each_get_their_own_copy_from_the_first_draw(classroom_app, monkeypatch):
    """Five browsers, each with its own copy of another link length, drop and come back at the same moment: each
    page shows its own copy (never another's), built on it from the start (no switch from the shared mechanism),
    and the shared mechanism never changed."""
    app = classroom_app
    lecturer = Page(app.port)
    views_of(app, 1)
    cookies = [page_cookie(app.port) for _ in range(5)]
    lengths = [str(270 + 5 * k) for k in range(5)]
    pages, left = [], []
    for cookie, length in zip(cookies, lengths, strict=True):
        known = set(app.views.values())
        page = Page(app.port, cookie=cookie)
        view = wait_for(lambda known=known: next((v for v in app.views.values() if v not in known), None), what="view")
        wait_for(lambda view=view: view in app.arrived, what="the tab connected")
        page.set("Work on my own copy", True)
        wait_for(lambda view=view: not view.session.shared, what="an own copy")
        page.set(L_A, length)
        page.set("Apply parameters", True)
        wait_for(lambda view=view, length=length: view.session.state.params.l_a * 1e3 == pytest.approx(float(length)))
        pages.append(page)
        left.append(view)
    for page in pages:
        page.close()
    wait_for(lambda: all(v.closed for v in left), what="all gone (kept after they left)")
    switched: list[object] = []
    view_type = type(next(iter(app.views.values())))
    switch = view_type.switch
    monkeypatch.setattr(view_type, "switch", lambda self, *a, **k: switched.append(self) or switch(self, *a, **k))
    back: dict[str, Page] = {}
    threads = [threading.Thread(target=lambda c=c: back.update({c: Page(app.port, cookie=c)})) for c in cookies]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    views = views_of(app, 6)
    wait_for(lambda: all(v in app.arrived for v in views), what="every tab back")
    for cookie, length in zip(cookies, lengths, strict=True):
        page = back[cookie]
        wait_for(lambda page=page, length=length: page.value(L_A) == length, what="its own l_a")
        wait_for(lambda page=page: page.value("Work on my own copy") is True, what="its box ticked")
    assert not switched
    with app.hub.lock:
        assert app.hub.shared.state.params.l_a == pytest.approx(0.26)
    for page in (*back.values(), lecturer):
        page.close()
