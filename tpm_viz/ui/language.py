"""The language of one browser tab: the *Language* selector, and the switch that shows the whole tab in another.

Every element of the tab is made through its :class:`~tpm_viz.ui.worded.TabGui` (``view.gui``), which shows the
fixed English texts of the code in the tab's language and keeps the English for the code (a dropdown's value is
still ``"static"`` for the callbacks, whatever the page shows). Texts built with numbers are rendered by their
producers with ``say(view.lang, phrase)``.

:meth:`TabWords.set` switches: ``view.lang`` and every live element's texts (:meth:`~tpm_viz.ui.worded.TabGui.relabel`),
then the tab's live parts are drawn again in the new language.

The language of a new tab is the first one its browser asks for (``Accept-Language`` of its websocket handshake,
:func:`tpm_viz.core.words.preferred`, read by :func:`first_language`); a tab that comes back after a drop or a restart
gets its own back (:mod:`.continuity`).
"""

from __future__ import annotations

from typing import Any

import viser

from tpm_viz.classroom.guard import guarded
from tpm_viz.core.markup import Html
from tpm_viz.core.words import Lang, preferred
from tpm_viz.ui.worded import show_text
from tpm_viz.viserkit.core import client_request

__all__ = ["LABEL", "TabWords", "first_language", "show_text"]

LABEL = "Language"
"""The selector's label (shown in the tab's language: 언어). Its options are each language's own name."""
KEEP_ALL = Html("<style>.mantine-Paper-root { word-break: keep-all; overflow-wrap: anywhere; }</style>")
"""Korean typesetting: lines break between words (at spaces), as in English, not inside one; a word longer than
its line still breaks anywhere. In the page of a tab shown in Korean only."""


def first_language(client: viser.ClientHandle) -> Lang:
    """The language a new tab is shown in: the first of :class:`~tpm_viz.core.words.Lang` its browser asks for."""
    request = client_request(client)
    return preferred(None if request is None else request[1].get("Accept-Language"))


class TabWords:
    """The words of one tab (``view``: its :class:`~.client.ClientView`, whose ``lang`` and ``gui`` this switches)."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self.selector = view.gui.add_dropdown(LABEL, tuple(lang.label for lang in Lang), initial_value=view.lang.label)
        self.selector.on_update(self._on_select)
        self._style: Any = None
        self._typeset()

    def _typeset(self) -> None:
        """The page's line breaking for the tab's language (:data:`KEEP_ALL` in Korean; created when first needed)."""
        content = KEEP_ALL if self.view.lang is Lang.KO else Html("")
        if self._style is None and content:
            self._style = self.view.gui.add_html(content)
        elif self._style is not None:
            self._style.content = content

    # -- switching --------------------------------------------------------------------------------------------------
    @guarded
    def _on_select(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        self.set(Lang.parse(self.selector.value, default=self.view.lang))

    def set(self, lang: Lang) -> None:
        """Show this tab in ``lang``: every fixed text written again, then its live parts redrawn."""
        view = self.view
        with view.hub.locked():
            if view.closed:
                return
            if self.selector.value != lang.label:
                self.selector.value = lang.label  # an echo with client=None: ignored by the callback
            if lang is view.lang:
                return
            view.lang = lang
            self._typeset()
            view.gui.relabel(lang)  # every element's fixed texts, through its handle
            self._redraw()
            view.client.flush()

    def _redraw(self) -> None:
        """The live parts of the tab (dashboard, equations, the teaching tabs' texts) drawn again in its language."""
        view = self.view
        view.panel.forget(inputs=False)  # a choice the page sent during the switch still reaches its callback
        frame = view.session.frame
        if frame is not None:
            view.render(frame)
        view.hub.membership_changed()  # the classroom line, written by the app (coalesced for all tabs)
        view.teaching.words_changed()
