"""End to end in headless Chromium: the LMS's course page -> the tool's login -> the platform's authorisation (its
auto-submitted form) -> the tool's launch -> the app, as the presenter (an Instructor) and as a student (a Learner,
whose LMS speaks Korean); the app URL opened again in a fresh browser gives nothing. A real browser follows every
redirect, keeps the login's state cookie and sends it back with the platform's cross-origin form post."""

from __future__ import annotations

import io
import re
from contextlib import redirect_stdout

import pytest

from tests.lti.conftest import until, write_config
from tests.support.browser import launched_chromium
from tpm_viz.app.lessons import DEMOS
from tpm_viz.core.words import Lang, say
from tpm_viz.lti.run import LtiPlug
from tpm_viz.ui.app import main
from tpm_viz.ui.launched import SPENT

pytestmark = [pytest.mark.browser, pytest.mark.slow]

PAGE_MS = 240_000  # a page on a loaded machine (software WebGL): generous, never a timed assert


@pytest.fixture
def served(tmp_path, platform):
    plug = LtiPlug(write_config(tmp_path, platform), "127.0.0.1", DEMOS)
    with redirect_stdout(io.StringIO()):
        app = main(host="127.0.0.1", port=0, block=False, session=tmp_path / "store.sqlite3", lti=plug)
    urls = plug.tool.urls
    platform.tool_jwks, platform.tool_login, platform.tool_launch = urls.jwks, urls.login, urls.launch
    yield app
    app.stop()


def _arrive(browser, app, start: str):
    """A fresh browser opens ``start`` (and clicks the course page's link when there is one): ``(context, page,
    view)`` once the app has handled the tab."""
    context = browser.new_context(viewport={"width": 1400, "height": 860})
    page = context.new_page()
    before = set(app.views.values())
    page.goto(start)
    if "/course/" in start:
        page.click("#open")
        page.wait_for_url(re.compile(rf"^http://127\.0\.0\.1:{app.port}/\?lti="), timeout=PAGE_MS)
    view = until(
        lambda: next((v for v in app.views.values() if v not in before), None), "the tab's view", PAGE_MS / 1e3
    )
    until(lambda: view in app.arrived, "the tab handled", PAGE_MS / 1e3)
    return context, page, view


def test_from_the_course_page_to_the_app_as_presenter_and_as_student(served, platform):
    app = served
    with launched_chromium() as browser:
        context, page, teacher = _arrive(browser, app, f"{platform.url}/course/teacher/plain")
        ticket_url = page.url
        assert app.access.is_presenter_tab(teacher) and teacher.launch.course == "Mechanisms 101"
        page.get_by_text("You are the presenter of Mechanisms 101.").wait_for(timeout=PAGE_MS)
        context.close()  # one browser at a time on this 2-core machine

        context, page, student = _arrive(browser, app, f"{platform.url}/course/student/plain")
        assert not app.access.is_presenter_tab(student) and student.lang is Lang.KO  # the launch's locale
        page.get_by_text(say(Lang.KO, "You joined {course} as a student.", course="Mechanisms 101")).wait_for(
            timeout=PAGE_MS
        )
        context.close()

        context, page, late = _arrive(browser, app, ticket_url)  # the teacher's app URL, in another browser
        assert late.launch is None and not app.access.is_presenter_tab(late)
        page.get_by_text(say(late.lang, SPENT)).wait_for(timeout=PAGE_MS)
        context.close()
    assert app.launched.arrived == 2
