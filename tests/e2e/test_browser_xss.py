"""Every user-controlled string a page shows is shown as text, in headless Chromium (issue 35, item 1), written as
the attack: a share link whose uploaded trajectory's label is markup, a link naming an upload this server lacks (the
refusal quotes the label), a CSV whose file name and cells are markup, a session file and a lessons folder whose
labels, titles, texts and file names are markup.

The payloads (``<iframe srcdoc="<script>...">``, ``<img src=... onerror=...>``, ``<svg onload=...>``, a
``javascript:`` link, Markdown link, image and autolink syntax) would each leave a trace if the page read them as
markup: an element marked ``data-xss``, a flag on ``window`` (or the page's title), a request to a listener on
127.0.0.2 (counted). After each path the page must have none, and show the payload's text literally.
"""

from __future__ import annotations

import http.server
import json
import threading
import time

import numpy as np
import pytest

from tests.support.browser import launched_chromium
from tests.support.protocol import wait_for
from tests.support.upload_flood import CSV
from tpm_viz.app.lesson_files import load_lessons
from tpm_viz.app.runs import Source
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.links import _pack, encode_link
from tpm_viz.classroom.sessionfile import Document, Saved, encode_saved
from tpm_viz.paper.trajectories import Trajectory
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = [pytest.mark.browser, pytest.mark.slow]

PAGE_MS = 240_000  # a page on a loaded machine (software WebGL): generous, never a timed assert
WAIT = 120.0

TRACES = r"""
() => {
  const a = [...document.querySelectorAll('a[href]')];
  const img = [...document.querySelectorAll('img[src]')];
  return {
    pwned: window.__pwned === undefined ? null : String(window.__pwned),
    title: document.title,
    marked: document.querySelectorAll('[data-xss]').length,
    frames: document.querySelectorAll('iframe').length,
    svgs: document.querySelectorAll('svg[onload]').length,
    scripts: a.filter(e => e.getAttribute('href').trim().toLowerCase().startsWith('javascript')).length,
    links: a.filter(e => /127\.0\.0\.2|example\.com/.test(e.getAttribute('href'))).length,
    images: img.filter(e => e.getAttribute('src').includes('127.0.0.2')).length,
  };
}
"""
"""What a payload read as markup leaves in the page."""
CLEAN = {"pwned": None, "marked": 0, "frames": 0, "svgs": 0, "scripts": 0, "links": 0, "images": 0}


class _Listener(http.server.ThreadingHTTPServer):
    """Counts the requests it gets (a payload that loads anything)."""

    def __init__(self) -> None:
        self.hits: list[str] = []
        listener = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self) -> None:
                listener.hits.append(self.path)
                self.send_response(204)
                self.end_headers()

            def log_message(self, *args) -> None:
                pass

        super().__init__(("127.0.0.2", 0), Handler)
        self.thread = threading.Thread(target=self.serve_forever, daemon=True)
        self.thread.start()

    @property
    def url(self) -> str:
        return f"http://127.0.0.2:{self.server_address[1]}"


def _payloads(url: str) -> dict[str, str]:
    """The attacks (each under 200 characters: a link label's most), by name."""
    return {
        "iframe": f"<iframe data-xss srcdoc=\"<script>parent.__pwned='iframe';parent.document.title='pwned';"
        f"fetch('{url}/iframe')</script>\"></iframe>",
        "img": f"<img data-xss src={url}/img onerror=\"window.__pwned='img'\">",
        "svg": "<svg data-xss onload=\"window.__pwned='svg'\"></svg>",
        "js": "<a data-xss href=\"javascript:window.__pwned='js'\">run</a>",
        "md-link": "[run](javascript:window.__pwned='md')",
        "md-image": f"![i]({url}/md.png)",
        "autolink": f"<{url}/auto> www.example.com",
    }


# file names: no slash (a browser's file name has none); at most 80 characters are kept
NAME = "<img data-xss src=x onerror=\"window.__pwned='name'\"> [n](javascript:x) ![i](x.png).csv"
CELL = "<svg data-xss onload=window.__pwned='cell'>"


def _traces(page) -> dict:
    found = page.evaluate(TRACES)
    frames = [f.evaluate("() => window.__pwned === undefined ? null : String(window.__pwned)") for f in page.frames]
    return {
        **{k: found[k] for k in CLEAN},
        "frame_flags": [f for f in frames if f is not None],
        "title": found["title"],
    }


def _assert_clean(page, listener: _Listener, what: str) -> None:
    traces = _traces(page)
    assert {k: traces[k] for k in CLEAN} == CLEAN, (what, traces)
    assert traces["frame_flags"] == [] and traces["title"] != "pwned", (what, traces)
    assert listener.hits == [], (what, listener.hits)


def _shows(page, listener: _Listener, text: str, what: str) -> None:
    """Wait until the page shows ``text`` literally or a payload left a trace (what the page made of it, either
    way; bounded); then: no trace, and ``text`` shown."""

    def settled() -> bool:
        traces = _traces(page)
        ran = {k: traces[k] for k in CLEAN} != CLEAN or traces["frame_flags"] or listener.hits
        return bool(ran) or text in page.evaluate("() => document.body.innerText")

    wait_for(settled, PAGE_MS / 1e3, interval=0.2, what=f"{what}: the text or a trace of it")
    _assert_clean(page, listener, what)
    assert text in page.evaluate("() => document.body.innerText"), what


def _tab(page, group: str, name: str) -> None:
    page.get_by_role("tab", name=group, exact=True).first.click()
    page.get_by_role("tab", name=name, exact=True).first.click()
    time.sleep(0.1)


def _source(label: str) -> Source:
    t = np.linspace(0.0, 0.5, 6)
    p = np.stack([0.01 * np.sin(t), 0.01 * np.cos(t) - 0.01], axis=1)
    zero = np.zeros_like(p)
    return Source.from_trajectory(Trajectory("x", t, p, zero, zero), label=label)


@pytest.fixture
def attack(tmp_path):
    """The app (with a lessons folder made of payloads), a listener on 127.0.0.2 and Chromium."""
    listener = _Listener()
    payloads = _payloads(listener.url)
    lessons = tmp_path / "lessons"
    lessons.mkdir()
    text = " ".join(payloads.values()).replace('"', "'")
    title = payloads["svg"].replace('"', "'")
    (lessons / "01-x.toml").write_text(
        f'title = "{title}"\n\n[text]\nen = """\n{text}\n"""\n\n[pose]\np = [0.0, 0.0]\n'
    )
    (lessons / f"{payloads['svg'].replace('/', '')}.toml").write_text("title = 3\n")  # refused: its name is quoted
    tour = load_lessons(lessons)
    assert tour[0] and tour[1]
    app = TpmApp(build_server("127.0.0.1", 0), lessons=tour)
    try:
        with launched_chromium() as browser:
            yield app, browser, listener, payloads, tmp_path
    finally:
        app.stop()
        listener.shutdown()


def _open(app, browser, query: str = ""):
    context = browser.new_context(viewport={"width": 1400, "height": 860})
    page = context.new_page()
    errors: list[str] = []
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    before = set(app.views.values())
    page.goto(f"http://127.0.0.1:{app.port}/{query}")
    page.get_by_role("tab", name="Setup", exact=True).wait_for(timeout=PAGE_MS)
    view = wait_for(lambda: next((v for v in app.views.values() if v not in before), None), WAIT, what="the view")
    wait_for(lambda: view in app.shares.ready and view in app.arrived, WAIT, what="the tab connected")
    page.errors = errors
    return context, page, view


def test_no_user_string_becomes_markup_in_the_page(attack):
    app, browser, listener, payloads, _tmp = attack
    state = app.hub.shared.state

    # 1. a share link whose uploaded trajectory's label is each payload: the message line quotes it
    for name, payload in payloads.items():
        token = encode_link(Saved(state, _source(payload)))
        context, page, view = _open(app, browser, f"?share={token}")
        _shows(page, listener, payload, f"the link's label ({name})")
        assert not view.session.shared  # opened on the visitor's own copy
        _tab(page, "Teach", "Player")
        _shows(page, listener, payload, f"the label in the player ({name})")
        _assert_clean(page, listener, f"share link label {name}")
        context.close()

    # 2. a link naming an upload this server lacks, with markup beside the digest: the refusal quotes nothing of it
    raw = encode_saved(Saved(state))
    raw["trajectory"] = {"stored": "ab" * 32, "label": payloads["img"]}
    context, page, view = _open(app, browser, f"?share={_pack(raw)}")
    _shows(page, listener, "kept on the server that made the link", "the refusal of the link")
    assert payloads["img"][:40] not in page.evaluate("() => document.body.innerText")
    assert view.session.shared and app.shares.refused >= 1
    _assert_clean(page, listener, "refused link")

    # 3. CSVs: a file name of markup (its run's name in the player, the control tab's choice, the message line),
    # then cells of markup (the refusal quotes the cell)
    _tab(page, "Teach", "Player")
    upload = f'[id="file_upload_{widget_uuid(view.teaching.player.upload)}"]'
    page.set_input_files(upload, files=[{"name": NAME, "mimeType": "text/csv", "buffer": CSV}])
    shown = NAME[:30]
    _shows(page, listener, shown, "the file name in the player")
    wait_for(lambda: app.services.runs.of(view.session).run is not None, WAIT, what="the uploaded run")
    _tab(page, "Lab", "Control")
    _assert_clean(page, listener, "file name")
    bad = b"t,p1,p2\n0,0,0\n0.1," + CELL.encode() + b",0\n0.2,0,0\n0.3,0,0\n"
    _tab(page, "Teach", "Player")
    page.set_input_files(upload, files=[{"name": "cells.csv", "mimeType": "text/csv", "buffer": bad}])
    _shows(page, listener, CELL[:20], "the refusal quoting the cell")
    _assert_clean(page, listener, "cell")
    context.close()

    # 4. a session file whose trajectory's label is markup, opened by the lecturer (every tab's, with no presenter)
    doc = sessionfile.dumps(Document(Saved(state, _source(payloads["iframe"]))))
    assert json.loads(doc)
    context, page, view = _open(app, browser)
    page.get_by_text("Lecturer", exact=True).first.click()
    lecturer = app.room._lecturers[view]
    page.set_input_files(
        f'[id="file_upload_{widget_uuid(lecturer.open)}"]',
        files=[{"name": "session.json", "mimeType": "application/json", "buffer": doc.encode()}],
    )
    wait_for(lambda: app.services.runs.of(app.hub.shared).run is not None, WAIT, what="the session's run")
    _tab(page, "Teach", "Player")
    _shows(page, listener, payloads["iframe"][:60], "the session's label in the player")
    _assert_clean(page, listener, "session file")

    # 5. the lessons folder: a title, a text and a refused file's name, all markup
    _tab(page, "Teach", "Demos")
    _shows(page, listener, payloads["autolink"], "the lesson's text")
    _shows(page, listener, "lesson file(s) refused", "the refused lesson file")
    _assert_clean(page, listener, "lessons")
    assert page.errors == []
    context.close()
