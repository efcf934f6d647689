"""``--classroom`` on 127.0.0.1 (issue 40, item 6): the terminal says students cannot connect, and so does the
Lecturer folder now, under "Students open (same network)", in English and in Korean (the tab switched to Korean)."""

from __future__ import annotations

import html
import io
from contextlib import redirect_stderr, redirect_stdout

import tpm_viz.ui.app as app_module
from tests.support.pages import ADDRESSES, views_of
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.core.words import Lang, T, say
from tpm_viz.ui.lecturer import LOOPBACK_ONLY, join_html


def test_the_join_box_warns_when_the_server_is_bound_to_this_computer():
    room = ["http://192.0.2.7:8080/"]
    assert LOOPBACK_ONLY.template in join_html(room, loopback=True)
    assert LOOPBACK_ONLY.template not in join_html(room, loopback=False)


def test_a_loopback_classroom_warns_in_the_lecturer_folder_in_english_and_korean(tmp_path):
    out = io.StringIO()
    with redirect_stdout(out), redirect_stderr(io.StringIO()):
        app = app_module.main(
            host="127.0.0.1",
            port=0,
            block=False,
            classroom=True,
            session=tmp_path / "s.json",
            addresses=lambda: list(ADDRESSES),
        )
    client = None
    try:
        assert "students cannot connect" in out.getvalue()  # the terminal's line
        client = ProtocolClient(app.port)
        (view,) = views_of(app, 1)
        panel = app.room._lecturers[view]
        english = html.unescape(panel.join.handle.content)
        assert "Students open (same network):" in english and f"http://{ADDRESSES[0]}:" in english
        assert LOOPBACK_ONLY.template in english
        client.set_value(view.words.selector, Lang.KO.label)
        wait_for(lambda: view.lang is Lang.KO, what="the tab in Korean")
        wanted = (say(Lang.KO, LOOPBACK_ONLY), say(Lang.KO, T("Students open (same network):")))
        wait_for(lambda: all(w in html.unescape(panel.join.handle.content) for w in wanted), what="the Korean warning")
        assert LOOPBACK_ONLY.template not in html.unescape(panel.join.handle.content)
    finally:
        if client is not None:
            client.close()
        app.stop()
