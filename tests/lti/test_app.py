"""The launch ends in the app (``main(..., lti=LtiPlug)``, what ``serve --lti`` runs): the page spends the ticket,
its websocket becomes the LMS user's tab: an Instructor's presents, a Learner's is a student even on this machine, a
tab without a launch watches; the ticket opened again or in another browser gives nothing; a lesson link opens the
lesson; the class line names the course; a reconnecting tab keeps its LMS user. Protocol-level tabs
(:class:`tests.support.pages.Page`), the platform of :mod:`tests.lti.platform`."""

from __future__ import annotations

import io
from contextlib import redirect_stdout
from urllib.parse import urlsplit

import httpx
import pytest

from tests.lti.conftest import until, write_config
from tests.lti.platform import form_fields
from tests.support.pages import Page, views_of
from tpm_viz.app.lessons import DEMOS
from tpm_viz.classroom.launches import Role
from tpm_viz.core.words import say
from tpm_viz.lti.run import LtiPlug
from tpm_viz.ui.app import main
from tpm_viz.ui.launched import SPENT


@pytest.fixture
def served(tmp_path, platform):
    plug = LtiPlug(write_config(tmp_path, platform), "127.0.0.1", DEMOS)
    out = io.StringIO()
    with redirect_stdout(out):
        app = main(host="127.0.0.1", port=0, block=False, session=tmp_path / "store.sqlite3", lti=plug)
    platform.tool_jwks = plug.tool.urls.jwks
    yield app, plug, out.getvalue().splitlines()
    app.stop()


def _launch(plug, platform, hint: str, link: str) -> tuple[httpx.Client, str]:
    """A browser launched from the LMS: ``(its cookie jar, the app URL it is sent to)``."""
    browser = httpx.Client(timeout=10, follow_redirects=False)
    urls = plug.tool.urls
    answer = browser.get(urls.login, params=platform.login_query(urls.launch, hint, link))
    action, fields = form_fields(browser.get(answer.headers["location"]).text)
    answer = browser.post(action, data=fields)
    assert answer.status_code == 303, answer.text
    return browser, answer.headers["location"]


def _open(app, browser: httpx.Client, url: str) -> Page:
    """The browser opens ``url`` (the page request sets its cookies), then its tab's websocket connects."""
    assert browser.get(url).status_code == 200
    cookie = "; ".join(f"{c.name}={c.value}" for c in browser.cookies.jar if c.path == "/")
    return Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=cookie)


def _view(app, n: int):
    return views_of(app, n)[n - 1]


def test_serving_prints_the_four_lti_lines_after_the_url(served):
    app, plug, lines = served
    base = plug.tool.urls.base
    assert lines == [
        f"tpm-viz serving at http://127.0.0.1:{app.port}",
        f"LTI login URL: {base}/lti/login",
        f"LTI launch URL: {base}/lti/launch",
        f"LTI JWKS URL: {base}/lti/jwks",
        f"LTI deep linking URL: {base}/lti/deeplink",
    ]
    assert plug.tool.urls.app == f"http://127.0.0.1:{app.port}/"


def test_an_instructor_presents_a_learner_and_a_plain_tab_watch(served, platform):
    app, plug, _ = served
    teacher, url = _launch(plug, platform, "teacher", "plain")
    assert urlsplit(url).netloc == f"127.0.0.1:{app.port}"
    pages = [_open(app, teacher, url)]
    presenter = _view(app, 1)
    student_browser, student_url = _launch(plug, platform, "student", "plain")
    pages.append(_open(app, student_browser, student_url))
    student = _view(app, 2)
    pages.append(Page(app.port, origin=f"http://127.0.0.1:{app.port}"))  # this machine, no launch
    watcher = _view(app, 3)
    try:
        assert app.access.is_presenter_tab(presenter) and presenter.launch.role is Role.PRESENTER
        assert not app.access.is_presenter_tab(student) and student.launch.role is Role.STUDENT
        assert not app.access.is_presenter_tab(watcher) and watcher.launch is None  # loopback is not special
        assert "You are the presenter** of Mechanisms 101" in presenter.login.status.content
        assert say(student.lang, "You joined {course} as a student.", course="Mechanisms 101") in (
            student.panel.message.content
        )  # in the student's language (the launch's locale: ko-KR)
        until(lambda: "Course: Mechanisms 101." in presenter.panel.class_info.content, "the course in the class line")
        assert app.access.is_presenter(presenter) and not app.access.is_presenter(student)
    finally:
        for page in pages:
            page.close()


def test_the_ticket_opened_again_or_in_another_browser_gives_nothing(served, platform):
    app, plug, _ = served
    teacher, url = _launch(plug, platform, "teacher", "plain")
    pages = [_open(app, teacher, url)]
    first = _view(app, 1)
    other = httpx.Client(timeout=10)
    pages.append(_open(app, other, url))  # the same URL in another browser
    second = _view(app, 2)
    pages.append(_open(app, teacher, url))  # and again in the first
    third = _view(app, 3)
    try:
        assert app.access.is_presenter_tab(first)
        for late in (second, third):
            assert late.launch is None and not app.access.is_presenter_tab(late)
            assert say(late.lang, SPENT) in late.panel.message.content
        assert app.launched.arrived == 1
    finally:
        for page in pages:
            page.close()


def test_a_lesson_link_opens_the_lesson_on_a_student_s_own_copy(served, platform):
    app, plug, _ = served
    browser, url = _launch(plug, platform, "student2", "lesson3")
    page = _open(app, browser, url)
    view = _view(app, 1)
    try:
        until(lambda: view.teaching.demos.index == 2, "lesson 3 shown")
        assert not view.session.shared and app.hub.shared.state.params == app.hub.shared.state.params.paper()
    finally:
        page.close()


def test_a_reconnecting_tab_is_still_the_lms_user_but_not_the_presenter_by_its_cookie_alone(served, platform):
    app, plug, _ = served
    browser, url = _launch(plug, platform, "student", "plain")
    page = _open(app, browser, url)
    first = _view(app, 1)
    user = first.launch.user
    page.close()
    until(lambda: len(app.views) == 0, "the tab gone")
    cookie = "; ".join(f"{c.name}={c.value}" for c in browser.cookies.jar if c.name == "tpmviz_id")
    again = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=cookie)  # a blip: no new page, no ticket
    try:
        view = _view(app, 1)
        assert view.launch is not None and view.launch.user == user and view.launch.role is Role.STUDENT
        assert app.room._keys[view] == first.launch.key  # the LMS user's records, not the cookie's
    finally:
        again.close()


def test_in_classroom_mode_a_tab_on_this_machine_is_a_student_unless_launched_as_instructor(tmp_path, platform):
    """Without --lti a tab opened on the serving machine presents (classroom mode); with it, only a launch does."""
    plug = LtiPlug(write_config(tmp_path, platform), "127.0.0.1", DEMOS)
    out = io.StringIO()
    with redirect_stdout(out):
        app = main(
            host="127.0.0.1", port=0, block=False, classroom=True, addresses=lambda: ["192.0.2.7"],
            session=tmp_path / "store.sqlite3", lti=plug,
        )  # fmt: skip
    platform.tool_jwks = plug.tool.urls.jwks
    pages = [Page(app.port, origin=f"http://127.0.0.1:{app.port}")]
    try:
        local = _view(app, 1)
        assert app.access.enabled and not app.access.is_presenter_tab(local)
        assert "Only an instructor's launch from the course" in out.getvalue()
        assert "presenter token" not in out.getvalue()  # no random token printed: it would present too
        teacher, url = _launch(plug, platform, "teacher", "plain")
        pages.append(_open(app, teacher, url))
        assert app.access.is_presenter_tab(_view(app, 2))
    finally:
        for page in pages:
            page.close()
        app.stop()
