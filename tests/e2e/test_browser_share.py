"""Share links end to end in headless Chromium: *Copy share link* in one browser, the link opened in fresh browsers
(same server, the same store after a restart, a second server) on the visitor's own copy with the same parameters,
pose, load, trajectory (an uploaded one kept by content hash), player time and view options, the shared mechanism
untouched; a forged link refused with one line in the page. The expected state is the first tab's, set by the test
through the page (and the run hub for the player time), never recomputed by the code under test."""

from __future__ import annotations

import time
from pathlib import Path
from urllib.parse import urlsplit, urlunsplit

import numpy as np
import pytest

from tests.support.browser import launched_chromium, text_input
from tests.support.protocol import wait_for
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.continuity import lecture_store
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = [pytest.mark.browser, pytest.mark.slow]

PAUSE = 0.08  # s, longer than the client's 50 ms input throttle
WAIT = 120.0  # s, for the server to take a click: generous on a loaded machine
RUN_SECONDS = 120.0  # runs are computed in the worker: generous on a loaded machine (no timed assert)
PAGE_MS = 240_000  # a page on a loaded machine (software WebGL): generous, never a timed assert


@pytest.fixture
def chromium():
    """A headless Chromium (fresh profile); each ``new_context()`` is a new browser with no cookies."""
    with launched_chromium() as browser:
        yield browser


def _serve(path: Path, port: int = 0) -> TpmApp:
    store = lecture_store(path)
    store.open()
    return TpmApp(build_server("127.0.0.1", port, keys=store.keys), store=store)


def _open(browser, app: TpmApp, url: str):
    """A fresh browser context opening ``url`` (its host and port replaced by ``app``'s): ``(context, page, view)``
    once the app has built the tab and opened (or refused) its link."""
    context = browser.new_context(viewport={"width": 1400, "height": 860})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    before = set(app.views.values())
    parts = urlsplit(url)
    page.goto(urlunsplit(("http", f"127.0.0.1:{app.port}", parts.path or "/", parts.query, "")))
    page.get_by_role("tab", name="Setup", exact=True).wait_for(timeout=PAGE_MS)  # the panel is drawn
    view = wait_for(
        lambda: next((v for v in app.views.values() if v not in before), None), PAGE_MS / 1e3, what="the tab's view"
    )
    wait_for(lambda: view in app.shares.ready, PAGE_MS / 1e3, what="the link opened or refused")
    page.errors = errors
    return context, page, view


def _tab(page, group: str, name: str) -> None:
    """Open the panel's tab ``name`` of the group ``group`` (the two rows of tabs)."""
    page.get_by_role("tab", name=group, exact=True).click()
    page.get_by_role("tab", name=name, exact=True).click()
    time.sleep(PAUSE)


def _pick(page, handle, option: str) -> None:
    page.locator(f'[id="{widget_uuid(handle)}"]').click()
    page.get_by_role("option", name=option, exact=True).click()
    time.sleep(PAUSE)


def _copy_link(page, share) -> str:
    """Click *Copy share link* of ``share`` (a :class:`~tpm_viz.ui.share.ShareBox` in the open tab); the link as
    the page's text field shows it."""
    before = share.text.value
    page.locator(f'[id="{widget_uuid(share.button)}"]').click()
    wait_for(lambda: share.text.value and share.text.value != before, WAIT, what="a new link")
    field = text_input(page, share.text)
    wait_for(lambda: field.input_value() == share.text.value, WAIT, what="the link in the page's field")
    return field.input_value()


def _state(app: TpmApp, view) -> dict:
    """What a tab shows: parameters, pose, load, run (source, knots), player time, view options."""
    with app.hub.lock:
        s = view.session.state
        run = app.services.runs.of(view.session).run
        return {
            "own": not view.session.shared,
            "params": s.params,
            "p": np.array(s.pose.p),
            "d": np.array(s.pose.d),
            "load": s.load,
            "source": None if run is None else run.source,
            "knots": None if run is None or run.source.knots is None else np.array(run.source.knots[1]),
            "t": s.trajectory.t,
            "show": dict(view.scene.show),
        }


def _same(got: dict, want: dict) -> None:
    assert got["own"] and got["params"] == want["params"] and got["load"] == want["load"]
    np.testing.assert_allclose(got["p"], want["p"], atol=1e-12)
    np.testing.assert_allclose(got["d"], want["d"], atol=1e-12)
    assert got["source"] == want["source"] and got["t"] == pytest.approx(want["t"]) and got["show"] == want["show"]
    if want["knots"] is not None:
        np.testing.assert_allclose(got["knots"], want["knots"])


def _opened(app: TpmApp, page, view, want: dict) -> None:
    wait_for(lambda: app.services.runs.of(view.session).run is not None, RUN_SECONDS, what="the visitor's run")
    wait_for(
        lambda: view.session.state.trajectory.t == pytest.approx(want["t"]), WAIT, what="the visitor's player time"
    )
    page.get_by_text("Opened a share link on your own copy").first.wait_for(timeout=PAGE_MS)
    _same(_state(app, view), want)


def test_a_link_made_in_one_browser_opens_the_same_state_in_fresh_ones(chromium, tmp_path):
    path = tmp_path / "lecture.sqlite"
    app = _serve(path)
    try:
        shared_before = app.hub.shared.state
        maker, page, a = _open(chromium, app, "/")
        player = a.teaching.player
        _tab(page, "Setup", "Class & view")
        page.locator(f'[id="{widget_uuid(a.panel.own_copy)}"]').click()
        wait_for(lambda: not a.session.shared, WAIT, what="the maker's own copy")
        page.locator(f'[id="{widget_uuid(a.panel.show_toggles["labels"])}"]').click()
        wait_for(lambda: not a.scene.show["labels"], WAIT, what="labels hidden")
        _tab(page, "Teach", "Player")
        _pick(page, player.choice, "circle (Fig. 5)")
        wait_for(lambda: app.services.runs.of(a.session).run is not None, RUN_SECONDS, what="the circle")
        with app.hub.lock:
            app.services.runs.seek(a.session, 0.2)
        wait_for(lambda: a.session.state.trajectory.t == pytest.approx(0.2), WAIT, what="t = 0.2 s")
        circle = _state(app, a)
        circle_url = _copy_link(page, player.share)
        assert circle_url.startswith(f"http://127.0.0.1:{app.port}/?share=")
        page.locator("img[alt='QR code of the share link']").first.wait_for(timeout=PAGE_MS)

        t = np.linspace(0.0, 0.5, 400)  # too many samples for a link: kept in the store by content hash
        rows = "".join(f"{x:.6f},{0.03 * np.sin(4 * np.pi * x):.6f},{0.02 * np.sin(2 * np.pi * x):.6f}\n" for x in t)
        (tmp_path / "lab.csv").write_text("t,p1,p2\n" + rows)
        page.set_input_files(f'[id="file_upload_{widget_uuid(player.upload)}"]', str(tmp_path / "lab.csv"))
        wait_for(
            lambda: (run := app.services.runs.of(a.session).run) is not None and run.source.kind == "csv",
            RUN_SECONDS,
            what="the uploaded run",
        )
        with app.hub.lock:
            app.services.runs.seek(a.session, 0.125)
        wait_for(lambda: a.session.state.trajectory.t == pytest.approx(0.125), WAIT, what="t = 0.125 s")
        upload = _state(app, a)
        _tab(page, "Setup", "Share")  # the same link from the Share tab beside Class & view
        upload_url = _copy_link(page, a.share)
        assert "lab.csv" not in upload_url and len(upload_url) < len(circle_url) + 400
        assert page.errors == []
        maker.close()  # one browser at a time on this 2-core machine

        visitor, vpage, b = _open(chromium, app, upload_url)  # a fresh browser on the same server
        _opened(app, vpage, b, upload)
        assert vpage.errors == []
        visitor.close()
        onlooker, opage, c = _open(chromium, app, "/?share=" + upload_url.split("=", 1)[1][:-3] + "abc")
        opage.get_by_text("This tab was opened with a share link that is refused").first.wait_for(timeout=PAGE_MS)
        opage.get_by_text("the share link is damaged: copy it again in full").first.wait_for(timeout=PAGE_MS)
        with app.hub.lock:
            assert c.session.shared and app.hub.shared.state is shared_before  # the shared mechanism untouched
            assert app.services.runs.of(app.hub.shared).run is None
        assert c.panel.message.content.count("\n") == 0
        assert opage.errors == []
        onlooker.close()
    finally:
        app.stop()

    again = _serve(path, app.port)  # a restart on the same store (on the same port if it is free again)
    try:
        context, page, b = _open(chromium, again, upload_url)
        _opened(again, page, b, upload)
        context.close()
    finally:
        again.stop()

    other = _serve(tmp_path / "elsewhere.sqlite")  # a second server: the circle opens, the upload is not there
    try:
        context, page, b = _open(chromium, other, circle_url)
        _opened(other, page, b, circle)
        context.close()
        refused, rpage, c = _open(chromium, other, upload_url)
        rpage.get_by_text("is kept on the server that made the link").first.wait_for(timeout=PAGE_MS)
        rpage.get_by_text("or upload the CSV here").first.wait_for(timeout=PAGE_MS)
        with other.hub.lock:
            assert c.session.shared and other.services.runs.of(c.session).run is None
        refused.close()
    finally:
        other.stop()
