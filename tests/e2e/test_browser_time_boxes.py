"""The Player's *Time t (s)* box in headless Chromium (issue 40, item 1), with the real keyboard: on a 1366×768
laptop in English and on a 390×844 touch phone in Korean, with the circle loaded (T = 0.5 s), ``2e-1``⏎ puts the
player at 0.2 s (viser's number box put it at 0.500 s), and ``1e9``, ``abc``, ``-5`` are refused in the note under
the box (the page shows the server's note; the box keeps the text typed, the slider the time in use).
Screenshots in a temporary folder named in the output.
"""

from __future__ import annotations

import html
import os
import re
import tempfile

import pytest

from tests.e2e.test_browser_layout import chromium  # noqa: F401  (fixture)
from tests.e2e.test_browser_stage import _open
from tests.support.browser import text_input
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, open_tab
from tpm_viz.core.words import Lang, shown
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser


@pytest.fixture
def served():
    """An app of its own per case (the shared mechanism starts at home, no trajectory loaded)."""
    application = TpmApp(build_server("127.0.0.1", 0))
    yield application
    application.stop()


CASES = [((1366, 768), "en-US", Lang.EN), ((390, 844), "ko-KR", Lang.KO)]


def _note(typed) -> str:
    """The note under the box as the page shows it (tags dropped, spaces joined), from the server's HTML."""
    return " ".join(html.unescape(re.sub(r"<[^>]+>", " ", str(typed.box.note.handle.content))).split())


@pytest.mark.parametrize(("size", "locale", "lang"), CASES, ids=["1366x768-en", "390x844-ko"])
def test_typing_into_the_players_time_box(served, chromium, size, locale, lang):  # noqa: F811
    shots = tempfile.mkdtemp(prefix="tpm-viz-time-box-")
    context, page, view = _open(served, chromium, size, locale=locale)
    try:
        assert view.lang is lang
        open_tab(page, shown(lang, "Player"), shown(lang, GROUP_OF["Player"]))
        pv = view.teaching.player
        page.locator(f'[id="{widget_uuid(pv.choice)}"]').click()
        page.get_by_role("option", name=shown(lang, "circle (Fig. 5)"), exact=True).dispatch_event(
            "click"
        )  # the list moves on a phone
        runs = view.teaching.services.runs
        wait_for(lambda: (r := runs.of(view.session).run) is not None and r.duration == 0.5, what="the circle")
        wait_for(lambda: pv.time.max == 0.5, what="the box spanning 0.5 s")
        typed = pv.time_typed
        field = text_input(page, typed.field)
        field.scroll_into_view_if_needed()

        def enter(text: str) -> None:
            field.click()
            field.press("Control+a")
            page.keyboard.type(text, delay=40)
            field.press("Enter")

        enter("2e-1")
        wait_for(lambda: view.session.state.trajectory.t == pytest.approx(0.2, abs=1e-12), what="t = 0.2 s")
        wait_for(lambda: field.input_value() == "2e-1", what="the text typed, without the line break")
        page.screenshot(path=os.path.join(shots, f"time-2e-1-{size[0]}.png"))
        english = {
            "1e9": "t: 1e+09 s is out of range; type a value from 0 to 0.5 s (in use: 0.2 s)",
            "abc": "t [s]: 'abc' is not a number (examples: 0.25, 0,25, -1.5e-3) (in use: 0.2 s)",
            "-5": "t: -5 s is out of range; type a value from 0 to 0.5 s (in use: 0.2 s)",
        }
        for text, sentence in english.items():
            enter(text)
            wait_for(
                lambda t=text: t.replace("1e9", "1e+09") in _note(typed),
                what=f"{text} refused on the server",
            )
            note = _note(typed)
            if lang is Lang.EN:
                assert note == sentence
            else:
                assert re.search("[\uac00-\ud7a3]", note) and "0.2 s" in note, note  # Korean, with the time in use
            wait_for(
                lambda n=note: n in " ".join(page.locator("body").inner_text().split()), what=f"{text}'s note shown"
            )
            assert field.input_value() == text
            assert view.session.state.trajectory.t == pytest.approx(0.2, abs=1e-12)
            assert pv.time.value == pytest.approx(0.2)
            page.screenshot(path=os.path.join(shots, f"time-{text}-{size[0]}.png"))
        print(f"screenshots: {shots}")
    finally:
        context.close()
