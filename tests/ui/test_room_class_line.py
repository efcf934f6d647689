"""The classroom line of *Class & view*: right counts, in the tab's language, and redrawn once per burst of
arrivals and departures (150 tabs leaving at once must not redraw 150 lines 150 times: issue 11)."""

from __future__ import annotations

import re

from tests.support.fixtures import open_tab
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.core.words import Lang

HANGUL = re.compile("[\uac00-\ud7a3]")


def test_the_class_line_counts_tabs_and_is_redrawn_once_per_burst(app, connect, monkeypatch):
    leaving: list[ProtocolClient] = []
    tabs = [connect() for _ in range(3)] + [open_tab(app, leaving) for _ in range(3)]
    first = tabs[0][1]
    six = "6 tabs connected, 6 on the shared mechanism"
    wait_for(lambda: all(six in view.panel.class_info.content for _c, view in tabs), what="6 tabs on every line")
    writes: list[str] = []
    original = type(first).set_class_info
    monkeypatch.setattr(type(first), "set_class_info", lambda self, text: writes.append(text) or original(self, text))

    tabs[1][0].set_value(tabs[1][1].panel.own_copy, True)
    for client in leaving:  # three tabs leave at once, one switches to its own copy
        client.close()
    wait_for(lambda: len(app.views) == 3, what="three tabs gone")
    three = "3 tabs connected, 2 on the shared mechanism"
    remaining = [view for _c, view in tabs[:3]]
    # the redraw runs on its own timer, not in a hub step: wait until no redraw is pending and every remaining tab
    # shows the burst's outcome (the last lines of the six-tab redraw may still be written after every tab shows it;
    # the burst's own redraws are the ones after it)
    wait_for(
        lambda: (
            app._class_info_timer is None
            and all(three in view.panel.class_info.content for view in remaining)
            and "You see your own copy." in tabs[1][1].panel.class_info.content
            and "You see the shared mechanism." in first.panel.class_info.content
        ),
        what="the burst's redraw on every remaining tab, and no redraw pending",
    )
    burst = [text for text in writes if six not in text]
    assert burst and len(burst) <= 2 * 3  # each remaining tab written once or twice, not once per change (4 changes)


def test_the_class_line_follows_the_tab_language(connect):
    (_c1, v1), (_c2, v2) = connect(), connect()
    wait_for(lambda: "2 tabs connected" in v1.panel.class_info.content, what="the line")
    v1.words.set(Lang.KO)
    wait_for(lambda: HANGUL.search(v1.panel.class_info.content), what="the Korean line")
    assert "2" in v1.panel.class_info.content  # the same count
    assert not HANGUL.search(v2.panel.class_info.content)  # the other tab stays in English


def test_one_tab_is_one_tab_in_english_and_in_korean(connect):
    """Not "1 tab(s) connected" (issue 40, item 8): English has a singular; the Korean line counts the same way."""
    client, view = connect()
    wait_for(lambda: "1 tab connected, 1 on the shared mechanism." in view.panel.class_info.content, what="singular")
    connect()
    wait_for(lambda: "2 tabs connected, 2 on the shared mechanism." in view.panel.class_info.content, what="plural")
    client.set_value(view.words.selector, Lang.KO.label)
    wait_for(lambda: "탭 2개 연결됨" in view.panel.class_info.content, what="the Korean line")
