"""A real classroom: joining (URLs, QR), the lecturer keeps control, continuity after a drop or a restart, the
same-origin check, presenter-token limits across connections, and inputs sent before a tab is wired.

Every server listens on 127.0.0.1; classroom mode gets its address list injected (no network needed).
"""

from __future__ import annotations

import io
import threading
import time
from contextlib import redirect_stderr, redirect_stdout

import pytest
from websockets.exceptions import InvalidStatus

import tpm_viz.ui.app as app_module
from tests.support.browser import text_input
from tests.support.pages import ADDRESSES, TOKEN, Page, classroom_app, views_of
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz import InputError
from tpm_viz.classroom.access import MAX_FAILURES, MAX_FAILURES_SERVER, Access
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import same_origin
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

__all__ = ["classroom_app"]  # the fixture, imported


# -- joining ---------------------------------------------------------------------------------------------------------
def test_classroom_mode_prints_student_urls_a_qr_code_and_the_token_in_the_terminal_only(tmp_path):
    out, err = io.StringIO(), io.StringIO()
    with redirect_stdout(out), redirect_stderr(err):
        app = app_module.main(
            port=0, block=False, classroom=True, session=tmp_path / "s.json", addresses=lambda: list(ADDRESSES)
        )
    try:
        text = out.getvalue()
        students = [line for line in text.splitlines() if line.startswith("Students open:")]
        assert students == [f"Students open: http://{a}:{app.port}/" for a in ("192.0.2.7", "198.51.100.20")]
        assert "▀" in text or "█" in text  # the QR code
        assert text.splitlines()[0] == f"tpm-viz serving at http://127.0.0.1:{app.port}"
        token = app.room.classroom.token
        assert token in text
        client = ProtocolClient(app.port)
        (view,) = views_of(app, 1)
        panel = app.room._lecturers[view]  # a tab on this computer (loopback) is the presenter
        assert "http://192.0.2.7:" in panel.join.content and "data:image/svg+xml" in panel.join.content
        assert token not in panel.join.content and "127.0.0.1" not in panel.join.content
        client.close()
    finally:
        app.stop()


def test_loopback_stays_the_default_and_says_nothing_more():
    out = io.StringIO()
    with redirect_stdout(out), redirect_stderr(io.StringIO()):
        app = app_module.main(port=0, block=False)
    try:
        assert out.getvalue() == f"tpm-viz serving at http://127.0.0.1:{app.port}\n"
        assert app.room.classroom is None and not app.access.enabled
    finally:
        app.stop()


# -- the lecturer keeps control ----------------------------------------------------------------------------------
def test_only_the_presenter_changes_the_shared_mechanism_until_it_is_handed_to_the_class(classroom_app):
    app = classroom_app
    lecturer = Page(app.port)
    (lv,) = views_of(app, 1)
    student = Page(app.port)
    sv = next(v for v in views_of(app, 2) if v is not lv)
    assert app.access.is_presenter(lv) and not app.access.is_presenter(sv)
    assert sv not in app.room._lecturers and lv in app.room._lecturers
    student.set("Actuator d1 (mm)", 200.0)
    wait_for(lambda: "only the presenter" in sv.panel.move_note.handle.content, what="the refusal under Move")
    assert app.hub.shared.state.pose.d[0] == pytest.approx(0.13)
    lecturer.set("Let the class change the shared mechanism", True)
    wait_for(lambda: app.access.open_to_class, what="the hand-over")
    student.set("Actuator d1 (mm)", 200.0)
    wait_for(lambda: app.hub.shared.state.pose.d[0] == pytest.approx(0.2), what="the student's change")
    lecturer.set("Let the class change the shared mechanism", False)
    wait_for(lambda: not app.access.open_to_class, what="taken back")
    student.set("Actuator d1 (mm)", 150.0)
    wait_for(lambda: "only the presenter" in sv.panel.move_note.handle.content, what="refused again")
    student.set("Work on my own copy", True)  # always one click away
    wait_for(lambda: not sv.session.shared, what="the student's own copy")
    for page in (student, lecturer):
        page.close()


def test_token_tries_are_limited_per_address_across_connections(classroom_app):
    app = classroom_app
    lecturer = Page(app.port)  # the presenter (first tab)
    views_of(app, 1)
    guesser = Page(app.port)
    gv = next(v for v in views_of(app, 2) if not app.access.is_presenter(v))
    for k in range(MAX_FAILURES):
        guesser.set("Presenter token", f"guess-{k}")
        guesser.set("Log in as presenter", True)
        time.sleep(0.05)
    wait_for(lambda: "wrong presenter token" in gv.panel.message.content, what="the refusals")
    guesser.close()
    again = Page(app.port)  # a new connection from the same address does not start again
    av = wait_for(
        lambda: next(
            (
                v
                for v in app.views.values()
                if v is not gv and v.login and v is not None and not app.access.is_presenter(v) and not v.closed
            ),
            None,
        ),
        what="the new tab",
    )
    wait_for(lambda: av.session.readout is not None, what="render")
    again.set("Presenter token", TOKEN)
    again.set("Log in as presenter", True)
    wait_for(lambda: "too many" in av.panel.message.content, what="the lockout across connections")
    assert not app.access.is_presenter(av)
    again.close()
    lecturer.close()


def test_token_limit_server_wide_and_back_off_without_a_server():
    now = [0.0]
    access = Access(TOKEN, clock=lambda: now[0])
    tab = object.__new__(type("Tab", (), {}))
    for _ in range(MAX_FAILURES):
        assert not access.login(tab, "x", source="10.0.0.1")
    with pytest.raises(InputError, match="60 s"):
        access.login(tab, TOKEN, source="10.0.0.1")
    now[0] += 61
    for _ in range(MAX_FAILURES):
        assert not access.login(tab, "x", source="10.0.0.1")
    with pytest.raises(InputError, match="120 s"):  # the second lockout lasts twice as long
        access.login(tab, TOKEN, source="10.0.0.1")
    now[0] += 1000
    for k in range(MAX_FAILURES_SERVER):  # many addresses, a few tries each
        access.login(tab, "x", source=f"10.1.{k // 4}.{k % 4}")
    with pytest.raises(InputError, match="on this server"):
        access.login(tab, TOKEN, source="10.9.9.9")
    now[0] += 61
    assert access.login(tab, TOKEN, source="10.9.9.9")


# -- security ----------------------------------------------------------------------------------------------------
def test_a_websocket_from_another_site_is_refused_and_moves_nothing(classroom_app):
    app = classroom_app
    before = app.hub.shared.state
    for origin in ("http://evil.example", f"http://127.0.0.1:{app.port + 1}", "null", "file://"):
        with pytest.raises(InvalidStatus) as info:
            Page(app.port, origin=origin)
        assert info.value.response.status_code == 403
    assert app.views == {} and app.hub.shared.state is before
    for origin in (f"http://127.0.0.1:{app.port}", None):  # the page's own origin, or not a browser
        page = Page(app.port, origin=origin)
        wait_for(lambda: app.views, what="a tab")
        page.close()
        wait_for(lambda: not app.views, what="the tab gone")


@pytest.mark.parametrize(
    ("origin", "host", "ok"),
    [
        ("http://127.0.0.1:8080", "127.0.0.1:8080", True),
        ("http://LOCALHOST:8080", "localhost:8080", True),
        ("http://192.0.2.7", "192.0.2.7", True),
        ("http://192.0.2.7:80", "192.0.2.7", True),
        ("http://evil.example:8080", "127.0.0.1:8080", False),
        ("http://127.0.0.1:8081", "127.0.0.1:8080", False),
        ("null", "127.0.0.1:8080", False),
    ],
)
def test_same_origin_rule(origin, host, ok):
    assert same_origin({"Origin": origin, "Host": host}) is ok


# -- the first tab's early inputs ------------------------------------------------------------------------------------
def test_own_copy_ticked_as_soon_as_the_widget_arrives_is_handled_on_fresh_servers():
    failures = []
    for attempt in range(8):  # bounded: eight fresh servers
        app = TpmApp(build_server("127.0.0.1", 0), reference=None)
        try:
            page = Page(app.port)
            sent = threading.Event()

            def tick(label, uuid, page=page, sent=sent):
                if label == "Work on my own copy" and not sent.is_set():
                    sent.set()
                    page.send(type="GuiUpdateMessage", uuid=uuid, updates={"value": True})

            page.on_widget = tick
            if "Work on my own copy" in page.uuids:  # arrived before the hook was set
                tick("Work on my own copy", page.uuids["Work on my own copy"])
            (view,) = views_of(app, 1)
            wait_for(sent.is_set, what="the tick sent")
            try:
                wait_for(lambda view=view: not view.session.shared, timeout=5.0, what="the own copy")
            except AssertionError:
                failures.append(attempt)
            page.close()
        finally:
            app.stop()
    assert failures == []


@pytest.mark.browser
def test_the_token_field_shows_dots_not_the_token(browser):
    app = TpmApp(build_server("127.0.0.1", 0), presenter_token=TOKEN)
    try:
        page = browser.new_page()
        page.goto(f"http://127.0.0.1:{app.port}/")
        view = wait_for(lambda: next(iter(app.views.values()), None), timeout=30, what="the tab's view")
        wait_for(lambda: view.login is not None, what="the login folder")
        page.get_by_text("Presenter login").click()
        uuid = widget_uuid(view.login.token)
        field = page.locator(f'div:has(> div > p > label[for="{uuid}"]) textarea')  # one-line-drawn: Enter logs in
        field.fill("typed-secret")
        security = field.evaluate("e => getComputedStyle(e).webkitTextSecurity")
        assert security == "disc"
        other = text_input(page, view.panel.p.inputs["p1"])  # a typed number: a textarea drawn as one line
        assert other.evaluate("e => getComputedStyle(e).webkitTextSecurity") == "none"
        page.close()
    finally:
        app.stop()
