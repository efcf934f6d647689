"""A tab's language (issue 13): chosen from the browser's ``Accept-Language``, switched with the *Language* selector,
shown by the page in every label, option and tab name while the server keeps its English values, and kept across
a dropped connection and a restart of the server (with the session file). Checked on the wire, with protocol-level
tabs that record what the page is sent, as the browser would draw it.
"""

from __future__ import annotations

import json
import threading
import time

import pytest

from tests.support.pages import Page, classroom_app, views_of
from tests.support.protocol import ServerProcess, wait_for
from tests.support.stores import page_cookie, stored_tabs
from tpm_viz.app.state import AppState
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.sessionfile import Document, Saved
from tpm_viz.core.words import Lang, catalogue, preferred

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

__all__ = ["classroom_app"]  # the fixture, imported

KO = catalogue(Lang.KO)


class Shown(Page):
    """A protocol-level tab that keeps, per element, what its page currently shows: label, options, value, tab
    names (creation messages, then every update)."""

    def __init__(self, port: int, cookie: str | None = None, accept_language: str | None = None) -> None:
        self.props: dict[str, dict] = {}
        self._lock = threading.Lock()
        super().__init__(port, cookie=cookie, accept_language=accept_language)

    def take(self, m: dict) -> None:
        with self._lock:
            if m["type"].startswith("Gui") and isinstance(m.get("props"), dict) and "uuid" in m:
                self.props[m["uuid"]] = dict(m["props"], value=m.get("value"))
            elif m["type"] == "GuiUpdateMessage" and m["uuid"] in self.props:
                self.props[m["uuid"]].update(m["updates"])

    def uuid(self, label: str) -> str | None:
        """The first element the page shows with this label now."""
        with self._lock:
            return next((u for u, p in self.props.items() if p.get("label") == label), None)

    def shown(self, label: str) -> dict | None:
        uuid = self.uuid(label)
        with self._lock:
            return None if uuid is None else dict(self.props[uuid])

    def tabs(self) -> set[str]:
        with self._lock:
            return {t for p in self.props.values() for t in p.get("_tab_labels") or ()}

    def set(self, label: str, value) -> None:
        uuid = wait_for(lambda: self.uuid(label), what=f"an element labelled {label!r}")
        self.send(type="GuiUpdateMessage", uuid=uuid, updates={"value": value})


def test_a_tab_opens_in_the_language_its_browser_asks_for(classroom_app):
    app = classroom_app
    english = Shown(app.port)  # no header: English
    korean = Shown(app.port, accept_language="ko-KR,ko;q=0.9,en-US;q=0.8,en;q=0.7")
    views = views_of(app, 2)
    wait_for(lambda: korean.uuid("파라미터 적용"), what="Korean labels")
    assert sorted(v.lang.value for v in views) == ["en", "ko"]
    assert english.uuid("Apply parameters") and not english.uuid("파라미터 적용")
    # the last tab's name may arrive after the button: wait for the whole page, then compare
    wait_for(lambda: {"이동", "힘", "파라미터", "수식"} <= korean.tabs(), what="the Korean tab names")
    wait_for(lambda: "Move" in english.tabs(), what="the English tab names")
    assert not {"이동", "힘"} & english.tabs()
    assert korean.shown("언어")["value"] == "한국어" and english.shown("Language")["value"] == "English"
    load = korean.shown("하중")
    assert load["options"] == ["정적", "동적"] and load["value"] == "정적"
    for view in views:  # the server side keeps its English labels and values whatever the page shows
        assert view.panel.apply.label == "Apply parameters" and view.panel.load_mode.value == "static"
    for page in (english, korean):
        page.close()


def test_switching_relabels_the_tab_and_its_choices_still_reach_the_callbacks(classroom_app):
    app = classroom_app
    page = Shown(app.port)
    (view,) = views_of(app, 1)
    page.set("Language", "한국어")
    wait_for(lambda: page.uuid("파라미터 적용"), what="the labels in Korean")
    wait_for(lambda: "수업·보기" in page.tabs(), what="the tab names in Korean")
    assert view.lang is Lang.KO and not page.uuid("Apply parameters")
    assert page.shown("구동기 d1 (mm)")["hint"] == KO["Forward kinematics"]
    page.set("하중", "동적")  # a choice sent in Korean is the English option for the server
    wait_for(lambda: view.session.state.load.mode == "dynamic", what="the dynamic load")
    assert view.panel.load_mode.value == "dynamic"
    page.set("하중", "not an option")  # still refused by the transport's check, as in English
    time.sleep(0.3)
    assert view.session.state.load.mode == "dynamic"
    page.set("단계", "다음")  # a button group: Step / Next (the lesson sets the static load again)
    wait_for(lambda: view.teaching.demos.index == 1, what="the next lesson")
    wait_for(lambda: page.shown("시연")["value"] == KO[view.teaching.demos.titles[1]], what="its title in Korean")
    wait_for(lambda: page.shown("하중")["value"] == "정적", what="the load written back, in Korean")
    page.set("언어", "English")
    wait_for(lambda: page.uuid("Apply parameters"), what="the labels in English again")
    assert page.shown("Load")["options"] == ["static", "dynamic"] and page.shown("Load")["value"] == "static"
    assert view.lang is Lang.EN and "Class & view" in page.tabs()
    page.close()


def test_a_refusal_is_told_in_the_tabs_language(classroom_app):
    app = classroom_app
    page = Shown(app.port, accept_language="ko")
    (view,) = views_of(app, 1)
    page.set("l_a, 링크 길이 (mm)", "-5")
    page.set("파라미터 적용", True)
    note = view.panel.params.note.handle  # under the Apply button
    wait_for(lambda: "거부됨: " in note.content, what="the refusal in Korean")
    page.close()


def test_a_tab_that_comes_back_after_a_drop_has_its_language_back(classroom_app):
    app = classroom_app
    cookie = page_cookie(app.port)  # the page's, signed by the server
    page = Shown(app.port, cookie=cookie, accept_language="en-US,en")
    (view,) = views_of(app, 1)
    page.set("Language", "한국어")
    wait_for(lambda: view.lang is Lang.KO, what="Korean")
    page.close()
    wait_for(lambda: not app.views, what="the tab gone")
    back = Shown(app.port, cookie=cookie, accept_language="en-US,en")  # the browser still asks for English
    (bv,) = views_of(app, 1)
    wait_for(lambda: back.uuid("파라미터 적용"), what="the tab back in Korean")
    assert bv.lang is Lang.KO and back.shown("언어")["value"] == "한국어"
    back.close()
    wait_for(lambda: not app.views, what="gone again")
    other = Shown(app.port, cookie=page_cookie(app.port))  # another browser: its own (English)
    (ov,) = views_of(app, 1)
    assert ov.lang is Lang.EN
    other.close()


def test_a_restart_brings_a_tab_back_in_its_language(tmp_path):
    path = tmp_path / "classroom.sqlite3"
    first = ServerProcess(session=path)
    try:
        cookie = page_cookie(first.port)  # signed with the secret kept beside the store: valid after a restart
        page = Shown(first.port, cookie=cookie)
        page.set("Language", "한국어")
        wait_for(lambda: page.uuid("파라미터 적용"), what="Korean")
        wait_for(  # the live tab is saved within SAVE_SECONDS (a bound of 30 s holds on a loaded machine)
            lambda: any(
                r["saved"].lang == "ko" for records in stored_tabs(path, time.time()).values() for r in records
            ),
            interval=0.2,
            what="the tab saved in Korean",
        )
        page.close()
    finally:
        first.stop()
    second = ServerProcess(session=path)  # same file, new process
    try:
        back = Shown(second.port, cookie=cookie)
        wait_for(lambda: back.uuid("파라미터 적용"), what="the tab back in Korean after the restart")
        back.close()
    finally:
        second.stop()
    assert not second.log_problems()


def test_the_session_file_keeps_each_tabs_language_and_reads_older_files_as_english():
    saved = Saved(AppState.initial(), lang="ko")
    doc = Document(Saved(AppState.initial()), tabs={"c:x": [{"private": False, "saved": saved, "left_at": 1e9}]})
    text = sessionfile.dumps(doc)
    back = sessionfile.loads(text, now=1e9 + 1)
    assert back.tabs["c:x"][0]["saved"].lang == "ko" and back.shared.lang == "en"
    raw = json.loads(text)
    del raw["tabs"]["c:x"][0]["saved"]["lang"]  # a file written before languages
    raw["shared"]["lang"] = "tlh"  # and a language this app does not have
    old = sessionfile.loads(json.dumps(raw), now=1e9 + 1)
    assert old.tabs["c:x"][0]["saved"].lang == "en" and old.shared.lang == "en"


@pytest.mark.parametrize(
    ("header", "lang"),
    [
        ("ko-KR,ko;q=0.9,en-US;q=0.8", "ko"),
        ("en-US,en;q=0.9,ko;q=0.8", "en"),
        ("fr-FR,fr;q=0.9,ko;q=0.5", "ko"),
        ("ko;q=0, en;q=0.1", "en"),
        ("de-DE", "en"),
        ("", "en"),
        ("*", "en"),
    ],
)
def test_the_browsers_first_language_among_ours_is_the_default(header, lang):
    assert preferred(header).value == lang  # what a new tab starts in (the first test: through a real handshake)
