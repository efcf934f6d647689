"""The page script's way back after a network drop, without a browser: its settings (the issue's bounds, viser's own
attempt timeout read from viser's client source, the button's words in every language), the route a disconnected
page asks, and the button's words in a tab's hidden element. The behaviour in a browser (a 30 s drop, the button,
``online`` and ``visibilitychange``) is ``tests/e2e/test_browser_reconnect.py``."""

from __future__ import annotations

import pathlib
import re
import urllib.error
import urllib.request

import pytest
import viser

from tpm_viz.core.words import Lang, catalogue, say
from tpm_viz.ui.keyboard import WORDS, _marker
from tpm_viz.viserkit import page

WORKER_TS = pathlib.Path(viser.__file__).parent / "client" / "src" / "WebsocketClientWorker.ts"
"""viser's websocket worker, as shipped in its wheel (its TypeScript source beside the built page)."""


def test_the_script_reads_exactly_the_reconnect_settings_python_sends():
    read = set(re.findall(r"\bRECONNECT\.(\w+)", page.SCRIPT))
    assert read == set(page.RECONNECT), (
        f"read, not sent: {read - set(page.RECONNECT)}; unread: {set(page.RECONNECT) - read}"
    )
    assert page.CONFIG["reconnect"] is page.RECONNECT and page.RECONNECT["path"] == page.ALIVE_PATH


def test_the_page_asks_at_most_2_to_3_s_apart_and_gives_each_question_up_before_the_next():
    assert 0 < page.RECONNECT["wait"] < page.RECONNECT["every"] <= 3000  # issue 40: at most 2-3 s apart
    assert 0 < page.RECONNECT["after"] <= page.RECONNECT["every"]  # the button shows before the second question


def test_a_websocket_attempt_is_waited_for_longer_than_viser_s_worker_waits_for_it():
    """The page asks again after ``stale`` ms without an answer to a connect; viser's worker closes an attempt that
    has not opened after its own timeout (and says so): ``stale`` must be longer, or the page would close an attempt
    the worker still waits for."""
    if not WORKER_TS.exists():
        pytest.skip(f"{WORKER_TS} is not in this viser wheel")
    source = WORKER_TS.read_text(encoding="utf-8")
    timeouts = re.findall(r"setTimeout\(\(\) => \{\s*socket\.close\(\);\s*\}, (\d+)\)", source)
    assert len(timeouts) == 1, "viser's worker no longer closes an attempt after a timeout: read it again"
    assert page.RECONNECT["stale"] > int(timeouts[0])
    assert '"retry"' in source and '"connected"' in source and '"closed"' in source  # the messages the script reads


def test_the_button_has_its_words_in_every_language():
    words = page.RECONNECT["words"]
    assert set(words) == {lang.value for lang in Lang}
    assert words["en"] == "Reconnect now"
    assert words["ko"] == catalogue(Lang.KO)["Reconnect now"] != words["en"]


@pytest.mark.parametrize("lang", list(Lang))
def test_a_tab_s_hidden_element_carries_the_button_s_words_in_the_tab_s_language(lang):
    """The script reads ``data-w="reconnect"`` of the tab's hidden element (in the tab's language on the wire)."""
    assert WORDS["reconnect"] is page.RECONNECT_NOW
    marker = _marker("nonce")
    assert '<span data-w="reconnect">Reconnect now</span>' in marker
    assert say(lang, page.RECONNECT_NOW) == page.RECONNECT["words"][lang.value]


def _get(port: int, path: str, host: str | None = None) -> tuple[int, bytes]:
    request = urllib.request.Request(f"http://127.0.0.1:{port}{path}")
    if host is not None:
        request.add_header("Host", host)
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status, response.read()
    except urllib.error.HTTPError as exc:
        return exc.code, exc.read()


def test_a_disconnected_page_s_question_is_answered_and_only_for_this_server_s_names(app):
    assert _get(app.port, page.ALIVE_PATH) == (200, b"ok\n")
    assert _get(app.port, page.ALIVE_PATH + "?t=1") == (200, b"ok\n")
    assert _get(app.port, page.ALIVE_PATH, host="evil.example")[0] == 403  # DNS rebinding: refused first
    assert _get(app.port, page.ALIVE_PATH + "/x")[0] == 404  # that path only
