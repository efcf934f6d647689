"""The compact readout's style sheet (:func:`tpm_viz.ui.panels.fold_css`) names the tab buttons by the ids the page
itself was sent: the *Explore* group's tab, and its *Move* and *Forces* tabs (read from viser's
``GuiTabGroupMessage`` as a tab received it, not from the server's handles: :func:`tpm_viz.viserkit.core.tab_id`)."""

from __future__ import annotations

import re

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.ui.panels import GROUPS


class _Tabs(ProtocolClient):
    """A tab that keeps the tab groups it is sent: label -> container id."""

    def __init__(self, port: int) -> None:
        self.tab_ids: dict[str, str] = {}
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        if m.get("type") == "GuiTabGroupMessage":
            props = m["props"]
            self.tab_ids.update(zip(props["_tab_labels"], props["_tab_container_ids"], strict=True))
        super().take(m, now)


def test_the_fold_style_sheet_names_the_explore_move_and_forces_buttons_by_the_ids_the_page_got(app):
    client = _Tabs(app.port)
    try:
        view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
        wanted = (GROUPS["explore"], "Move", "Forces")
        wait_for(lambda: all(label in client.tab_ids for label in wanted), what="the tab groups in the tab")
        css = view.panel.fold.content
        named = set(re.findall(r'data-dock-tab="([^"]+)"', css))
        assert named == {client.tab_ids[label] for label in wanted}
        assert {client.tab_ids[label] for label in wanted} <= set(re.findall(r'\[id\$="-tab-([^"]+)"\]', css))
    finally:
        client.close()
