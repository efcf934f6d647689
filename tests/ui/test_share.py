"""Share links wired end to end without a browser: the page asked with ``?share=TOKEN`` -> the short-lived cookie ->
the tab's own copy; *Copy share link* in a tab; refusals in one line in the tab's language; an upload kept by content
hash, opened after a restart on the same store and refused on another server. The expected states are what the
first tab was given (by typed inputs and the run hub), never what the code under test computes."""

from __future__ import annotations

import html
import http.client
from pathlib import Path
from urllib.parse import urlsplit

import numpy as np
import pytest
from websockets.datastructures import Headers
from websockets.http11 import Response

from tests.support.pages import Page, views_of
from tests.support.protocol import wait_for
from tpm_viz.app.runs import Source
from tpm_viz.classroom.links import LINK_VERSION, PendingLinks, encode_link
from tpm_viz.classroom.sessionfile import Saved
from tpm_viz.core.words import Lang, Phrase, say
from tpm_viz.paper.trajectories import Trajectory
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.classroom import SHARE_COOKIE, Handshakes, shared_token
from tpm_viz.ui.continuity import lecture_store
from tpm_viz.ui.share import origin_of
from tpm_viz.viserkit.probe import widget_uuid

RUN_SECONDS = 120.0  # a run is computed in the worker: generous under a loaded machine (no timed assert)


# -- the handshake: token -> cookie -> the tab's websocket -------------------------------------------------------------
class _Connection:
    remote_address = ("127.0.0.1", 40000)

    def respond(self, status, text):  # a refusal (not expected here)
        raise AssertionError(f"refused: {status} {text}")


class _Request:
    def __init__(self, path: str, **headers: str) -> None:
        self.path = path
        self.headers = Headers({"Host": "127.0.0.1:8080", **headers})


def _page(hook: Handshakes, path: str, **headers: str) -> list[str]:
    """The Set-Cookie values of the page response to ``GET path``."""
    response = hook(_Connection(), _Request(path, **headers), lambda: Response(200, "OK", Headers(), b"<html>"))
    return response.headers.get_all("Set-Cookie")


def _share_cookie(cookies: list[str]) -> str | None:
    found = [c.split(";")[0] for c in cookies if c.startswith(SHARE_COOKIE + "=")]
    return found[0] if found else None


def test_a_page_asked_with_a_link_hands_its_token_to_its_own_websocket_once():
    links = PendingLinks()
    hook = Handshakes(links=links)
    cookies = _page(hook, "/?share=1.abc.0123456789abcdef")
    cookie = _share_cookie(cookies)
    assert cookie is not None and "1.abc" not in cookie  # a nonce, not the token itself
    share = next(c for c in cookies if c.startswith(SHARE_COOKIE + "="))
    assert "HttpOnly" in share and "SameSite=Strict" in share and "Max-Age=120" in share
    handshake = Headers({"Cookie": f"tpmviz_id=x; {cookie}", "Upgrade": "websocket"})
    assert shared_token(handshake, links) == "1.abc.0123456789abcdef"
    assert shared_token(handshake, links) is None  # a reconnection of the same tab opens nothing again
    assert _share_cookie(_page(hook, "/index.html?lang=ko")) is None and len(links) == 0
    assert _share_cookie(_page(hook, "/favicon.ico?share=1.abc.0123456789abcdef")) is None  # pages only


def test_a_plain_reload_forgets_a_link_still_waiting():
    links = PendingLinks()
    hook = Handshakes(links=links)
    cookie = _share_cookie(_page(hook, "/?share=anything"))
    cleared = _page(hook, "/", Cookie=cookie)
    assert any(c.startswith(SHARE_COOKIE + "=;") and "Max-Age=0" in c for c in cleared)
    assert shared_token(Headers({"Cookie": cookie}), links) is None


def test_the_link_names_the_page_the_browser_saw():
    assert origin_of(Headers({"Origin": "https://tpm.example.edu", "Host": "127.0.0.1:8080"})) == (
        "https://tpm.example.edu"  # behind a proxy: the public name, not the proxied one
    )
    assert origin_of(Headers({"Origin": "http://192.0.2.7:8080"}), ["http://198.51.100.1:8080/"]) == (
        "http://192.0.2.7:8080"
    )
    students = ["http://192.0.2.7:8080/"]  # classroom mode: a page opened on this computer hands out the LAN URL
    assert origin_of(Headers({"Origin": "http://127.0.0.1:8080"}), students) == "http://192.0.2.7:8080"
    assert origin_of(Headers({"Origin": "http://localhost:8080"}), None) == "http://localhost:8080"
    assert origin_of(Headers({"Host": "127.0.0.1:9000"})) == "http://127.0.0.1:9000"  # not a browser
    assert origin_of(Headers({"Origin": "null", "Host": "h:1"})) == "http://h:1" and origin_of(None).startswith("http")


# -- the app -------------------------------------------------------------------------------------------------------
def _serve(path: Path | None) -> TpmApp:
    store = lecture_store(path)
    store.open()
    return TpmApp(build_server("127.0.0.1", 0, keys=store.keys), store=store)


@pytest.fixture
def stored(tmp_path):
    """An app with a store in ``tmp_path`` (uploads too large for a link are kept there)."""
    app = _serve(tmp_path / "lecture.sqlite")
    yield app
    app.stop()


def _get(port: int, target: str) -> str:
    """GET ``target`` like a browser without cookies; the ``Cookie`` header it would send back."""
    conn = http.client.HTTPConnection("127.0.0.1", port, timeout=30)
    try:
        conn.request("GET", target, headers={"Host": f"127.0.0.1:{port}"})
        response = conn.getresponse()
        response.read()
        return "; ".join(c.split(";")[0] for c in response.headers.get_all("Set-Cookie") or [])
    finally:
        conn.close()


def _visit(app: TpmApp, url: str, lang: str | None = None):
    """Open ``url``'s page on ``app`` as a new browser (the path and query of the link, on this app's port), then its
    tab; ``(page, view)`` once the app has done with it."""
    parts = urlsplit(url)
    before = set(app.views.values())
    cookie = _get(app.port, f"{parts.path or '/'}?{parts.query}")
    page = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=cookie, accept_language=lang)
    view = wait_for(lambda: next((v for v in app.views.values() if v not in before), None), what="the new tab")
    views_of(app, len(before) + 1)
    wait_for(lambda: view in app.shares.ready, what="the link opened or refused")
    return page, view


def _link_of(page: Page, view) -> str:
    share = view.teaching.player.share  # the Player's (the Share tab of Setup has the same button)
    page.send(type="GuiUpdateMessage", uuid=widget_uuid(share.button), updates={"value": True})
    return wait_for(lambda: share.text.value, what="the link in the field")


def _prepared(app: TpmApp, page: Page, view, source: Source, t: float) -> None:
    """The first tab: its own copy, l_a typed as 280 mm, labels hidden, ``source`` loaded and sought to ``t``."""
    page.set("Work on my own copy", True)
    wait_for(lambda: not view.session.shared, what="own copy")
    page.set("l_a, link length (mm)", "280")
    page.set("Apply parameters", True)
    wait_for(lambda: view.session.state.params.l_a == pytest.approx(0.28), what="l_a applied")
    page.set("Labels O, A_i, B_i, P", False)
    wait_for(lambda: not view.scene.show["labels"], what="labels hidden")
    with app.hub.lock:
        app.services.runs.load(view.session, source)
    wait_for(lambda: app.services.runs.of(view.session).run is not None, RUN_SECONDS, what="the run")
    with app.hub.lock:
        app.services.runs.seek(view.session, t)
    wait_for(lambda: view.session.state.trajectory.t == pytest.approx(t), what="the player time")


def _same_state(app: TpmApp, a, b) -> None:
    wait_for(lambda: app.services.runs.of(b.session).run is not None, RUN_SECONDS, what="the visitor's run")
    wait_for(lambda: b.session.state.trajectory.t == pytest.approx(a.session.state.trajectory.t), what="its time")
    with app.hub.lock:
        sa, sb = a.session.state, b.session.state
        assert not b.session.shared and sb.params == sa.params and sb.load == sa.load
        np.testing.assert_allclose(sb.pose.p, sa.pose.p, atol=1e-12)
        np.testing.assert_allclose(sb.pose.d, sa.pose.d, atol=1e-12)
        ra, rb = app.services.runs.of(a.session).run, app.services.runs.of(b.session).run
        assert rb.source == ra.source
        if ra.source.knots is not None:
            np.testing.assert_allclose(rb.source.knots[1], ra.source.knots[1])
        assert b.scene.show == a.scene.show


def _upload(n: int, name: str) -> Source:
    t = np.linspace(0.0, 0.5, n)
    p = np.column_stack([0.03 * np.sin(2 * np.pi * t / 0.5), 0.02 * (1 - np.cos(2 * np.pi * t / 0.5))])
    return Source.from_trajectory(Trajectory(name, t, p, np.zeros_like(p), np.zeros_like(p)))


def test_copy_share_link_opens_the_same_state_on_the_visitors_own_copy(stored):
    app = stored
    shared_before = app.hub.shared.state
    first = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=_get(app.port, "/"))
    (a,) = views_of(app, 1)
    _prepared(app, first, a, Source.paper("circle", 0.5), 0.2)
    url = _link_of(first, a)
    assert url.startswith(f"http://127.0.0.1:{app.port}/?share={LINK_VERSION}.")
    wait_for(lambda: a.teaching.player.share.qr.content.startswith("<img"), what="the QR code")
    onlooker = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=_get(app.port, "/"))
    views_of(app, 2)  # the onlooker's tab is built before the visitor's
    page, b = _visit(app, url)
    _same_state(app, a, b)
    with app.hub.lock:
        line = b.panel.message.content
        assert "Opened a share link on your own copy" in line and "l_a = 280.0 mm" in line and "circle" in line
        assert "\n" not in line.strip("*")
        assert app.hub.shared.state is shared_before  # the shared mechanism never moved
        assert all(v.session.shared and v.session.state is shared_before for v in app.hub.shared.views)
    for p in (page, onlooker, first):
        p.close()


DAMAGED = Phrase("the share link is damaged: copy it again in full")


@pytest.mark.parametrize("lang", ["en", "ko"])
def test_a_forged_or_damaged_link_is_refused_in_one_line_and_the_tab_opens_normally(stored, lang):
    app = stored
    good = encode_link(Saved(app.hub.shared.state))
    _, body, checksum = good.split(".")
    newer = Phrase(
        "this share link is of version {got}; this tpm-viz reads version {version}: ask for a new link",
        got=LINK_VERSION + 1,
        version=LINK_VERSION,
    )
    cases = [
        (good[:-1] + ("0" if good[-1] != "0" else "1"), DAMAGED),  # the checksum no longer matches
        (good[: len(good) // 2], DAMAGED),  # cut short
        ("%3Cscript%3E", DAMAGED),
        (f"{LINK_VERSION + 1}.{body}.{checksum}", newer),  # a link of another version
    ]
    for token, why in cases:
        page, view = _visit(app, f"/?share={token}", lang=lang)
        expected = say(Lang(lang), Phrase("This tab was opened with a share link that is refused: {why}", why=why))
        with app.hub.lock:
            line = view.panel.message.content
            assert expected in line and "\n" not in line
            assert view.session.shared and app.services.runs.of(view.session).run is None  # opened normally
        page.close()
        wait_for(lambda view=view: view not in app.views.values(), what="the tab gone")
    assert app.shares.refused == len(cases) and app.shares.opened == 0


def test_a_large_upload_is_kept_by_hash_opens_after_a_restart_and_is_refused_elsewhere(tmp_path):
    path = tmp_path / "lecture.sqlite"
    app = _serve(path)
    try:
        first = Page(app.port, origin=f"http://127.0.0.1:{app.port}", cookie=_get(app.port, "/"))
        (a,) = views_of(app, 1)
        _prepared(app, first, a, _upload(400, "lab.csv"), 0.125)
        url = _link_of(first, a)
        assert len(url) < 600 and "lab.csv" not in url  # the knots are in the store, not in the link: a QR code
        with app.hub.lock:
            expected = (a.session.state, app.services.runs.of(a.session).run.source)
        first.close()
    finally:
        app.stop()
    again = _serve(path)  # the same store, a new process's worth of state
    try:
        page, b = _visit(again, url)
        wait_for(lambda: again.services.runs.of(b.session).run is not None, RUN_SECONDS, what="the run")
        wait_for(lambda: b.session.state.trajectory.t == pytest.approx(0.125), what="the player time")
        with again.hub.lock:
            run = again.services.runs.of(b.session).run
            assert b.session.state.params == expected[0].params and run.source == expected[1]
            np.testing.assert_allclose(run.source.knots[1], expected[1].knots[1])
            np.testing.assert_allclose(b.session.state.pose.p, expected[0].pose.p, atol=1e-12)
        page.close()
    finally:
        again.stop()
    elsewhere = _serve(tmp_path / "other.sqlite")
    try:
        page, c = _visit(elsewhere, url, lang="ko")
        with elsewhere.hub.lock:
            line = html.unescape(c.panel.message.content)  # the line as the page shows it
            assert c.session.shared and "lab.csv" not in line and "CSV" in line  # nothing of the link quoted
            assert "링크를 만든 서버" in line  # "the server that made the link", in the tab's language
        page.close()
    finally:
        elsewhere.stop()
