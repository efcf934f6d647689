"""The keyboard's server side (issue 25): a key request with a tab's nonce moves that tab's mechanism by the
documented step, through the permission of a drag; a forged nonce, another site's page, a malformed request and a
flood are refused. The requests go over real HTTP to the served app (the page script's route), the tabs are
protocol clients."""

from __future__ import annotations

import http
import secrets
import urllib.error
import urllib.request

import numpy as np
import pytest

from tests.support.fixtures import open_tab
from tests.support.protocol import wait_for
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.keyboard import KEY_BURST, KEY_RATE, Keyboard, _Tab
from tpm_viz.viserkit.page import key_request

MM = 1e-3


def _get(port: int, query: str, origin: str | None = None) -> int:
    """The status of ``GET /tpm-viz/key?query`` (the page script's request)."""
    request = urllib.request.Request(f"http://127.0.0.1:{port}/tpm-viz/key?{query}")
    if origin is not None:
        request.add_header("Origin", origin)
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status
    except urllib.error.HTTPError as exc:
        return exc.code


def test_a_key_moves_its_tab_by_the_documented_step_and_a_forged_nonce_is_refused(app, connect):
    _, view = connect()
    nonce = app.keyboard.nonce_of(view)
    assert nonce is not None and len(nonce) >= 22  # 128 bits
    p0 = np.array(view.session.state.pose.p)
    assert _get(app.port, f"n={nonce}&k=ArrowRight&s=0") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: abs(view.session.state.pose.p[0] - (p0[0] + 1 * MM)) < 1e-12, what="p1 + 1 mm")
    assert _get(app.port, f"n={nonce}&k=ArrowDown&s=1") == http.HTTPStatus.ACCEPTED  # Shift: 10 mm
    wait_for(lambda: abs(view.session.state.pose.p[1] - (p0[1] - 10 * MM)) < 1e-12, what="p2 - 10 mm")
    d0 = np.array(view.session.state.pose.d)
    assert _get(app.port, f"n={nonce}&k=KeyW&s=0") == http.HTTPStatus.ACCEPTED  # slider 2 forward
    wait_for(lambda: abs(view.session.state.pose.d[1] - (d0[1] + 1 * MM)) < 1e-12, what="d2 + 1 mm")
    assert view.session.state.pose.d[0] == d0[0]  # forward kinematics: slider 1 stays

    before = np.array(view.session.state.pose.p)
    forged = secrets.token_urlsafe(16)
    assert _get(app.port, f"n={forged}&k=ArrowRight&s=0") == http.HTTPStatus.FORBIDDEN
    assert _get(app.port, f"n={nonce}&k=ArrowRight&s=0", origin="http://evil.example") == http.HTTPStatus.FORBIDDEN
    assert _get(app.port, f"n={nonce}&k=Delete&s=0") == http.HTTPStatus.BAD_REQUEST
    assert _get(app.port, "n=short&k=ArrowRight") == http.HTTPStatus.BAD_REQUEST
    assert app.keyboard.refused == 4
    # A last good key, applied after the refused ones would have been (one tab's keys are applied in order).
    assert _get(app.port, f"n={nonce}&k=ArrowUp&s=0") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: abs(view.session.state.pose.p[1] - (before[1] + 1 * MM)) < 1e-12, what="p2 + 1 mm")
    assert view.session.state.pose.p[0] == before[0]


def test_a_student_cannot_move_the_presenters_mechanism_but_can_move_an_own_copy(connect_presenter_mode):
    app, connect = connect_presenter_mode
    _, student = connect()
    nonce = app.keyboard.nonce_of(student)
    shared = np.array(app.hub.shared.state.pose.p)
    assert _get(app.port, f"n={nonce}&k=ArrowLeft&s=1") == http.HTTPStatus.ACCEPTED  # the request is fine...
    wait_for(lambda: "presenter" in student.panel.message.content, what="the refusal in the student's tab")
    assert np.array_equal(app.hub.shared.state.pose.p, shared)  # ...the shared mechanism did not move
    with app.hub.lock:
        student.switch(True)  # "Work on my own copy"
    assert _get(app.port, f"n={nonce}&k=ArrowLeft&s=1") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: abs(student.session.state.pose.p[0] - (shared[0] - 10 * MM)) < 1e-12, what="own copy moved")
    assert np.array_equal(app.hub.shared.state.pose.p, shared)


def test_a_gone_tabs_nonce_is_refused(app, connect):
    _, view = connect()
    nonce = app.keyboard.nonce_of(view)
    app.keyboard.leave(view)
    assert app.keyboard.nonce_of(view) is None
    assert _get(app.port, f"n={nonce}&k=ArrowRight&s=0") == http.HTTPStatus.FORBIDDEN


def test_the_token_bucket_allows_a_burst_then_the_rate():
    tab = _Tab(view=None, tokens=float(KEY_BURST), at=100.0)  # type: ignore[arg-type]
    assert [tab.take(100.0) for _ in range(KEY_BURST + 1)] == [True] * KEY_BURST + [False]
    half = 0.5  # s: KEY_RATE / 2 keys come back
    assert sum(tab.take(100.0 + half) for _ in range(KEY_BURST)) == int(KEY_RATE * half)
    assert sum(tab.take(1000.0) for _ in range(3 * KEY_BURST)) == KEY_BURST  # never more than the burst


def test_key_requests_are_parsed_strictly():
    assert key_request("/index.html") is None
    ok = key_request("/tpm-viz/key?n=" + "A" * 22 + "&k=KeyQ&s=1")
    assert ok is not None and (ok.code, ok.shift) == ("KeyQ", True)
    for bad in ("n=" + "A" * 22 + "&k=KeyZ", "n=" + "<" * 22 + "&k=KeyQ", "k=KeyQ", "n=" + "A" * 65 + "&k=KeyQ"):
        with pytest.raises(ValueError):
            key_request(f"/tpm-viz/key?{bad}")
    assert Keyboard().answer("/tpm-viz/key?n=" + "A" * 22 + "&k=KeyQ", same_site=True)[0] == 403  # type: ignore[index]


@pytest.fixture
def connect_presenter_mode():
    """An app in presenter mode (nobody logged in: every tab is a student) and its ``connect``."""
    server = build_server("127.0.0.1", 0)
    app = TpmApp(server, presenter_token="a-Token-for-the-test-9")
    opened: list = []
    yield app, lambda: open_tab(app, opened)
    for client in opened:
        client.close()
    app.stop()
