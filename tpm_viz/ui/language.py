"""The language of one browser tab: the *Language* selector, and every text the tab is sent, in that language.

The code writes its fixed texts in English (labels, hints, dropdown options, tab names, static markdown and HTML);
:class:`TabWords` sits on the tab's connection (:func:`~tpm_viz.viserkit.core.reword`) and shows each of them in the
tab's
language on the way out (:func:`tpm_viz.words.shown`: a whole text that is a template of the catalogue;
:func:`tpm_viz.words.shown_html`: each text between two tags of HTML). The Python side keeps the English: a
dropdown's value is still ``"static"`` for the callbacks, whatever the page shows, and the choice the page sends
back in Korean is mapped back to its English option before anything else reads it. Texts built with numbers are
rendered by their producers with ``say(view.lang, phrase)``.

:class:`TabWords` remembers the English texts the server last wrote to each element of the tab, so that a switch
of language writes them all again (translated on the way out) and then redraws the tab's live parts.

The language of a new tab is the first one its browser asks for (``Accept-Language`` of its websocket handshake,
:func:`tpm_viz.words.preferred`); a tab that comes back after a drop or a restart gets its own back
(:mod:`.continuity`).
"""

from __future__ import annotations

import threading
from typing import Any

from tpm_viz.classroom.guard import guarded
from tpm_viz.viserkit.core import reword
from tpm_viz.words import Lang, preferred, shown, shown_html

__all__ = ["LABEL", "TabWords", "show_text"]

LABEL = "Language"
"""The selector's label (shown in the tab's language: 언어). Its options are each language's own name."""
_WORDS = frozenset({"label", "hint", "title", "_markdown", "content", "options", "_tab_labels", "series", "axes"})
KEEP_ALL = "<style>.mantine-Paper-root { word-break: keep-all; overflow-wrap: anywhere; }</style>"
"""Korean typesetting: lines break between words (at spaces), as in English, not inside one; a word longer than
its line still breaks anywhere. In the page of a tab shown in Korean only."""


def show_text(lang: Lang, name: str, value: Any) -> Any:
    """The value of the text property ``name`` as a tab in ``lang`` shows it (see the module docstring)."""
    if lang is Lang.EN or value is None:
        return value
    if name == "content" and isinstance(value, str):
        whole = shown(lang, value)
        return whole if whole is not value else shown_html(lang, value)
    if isinstance(value, str):
        return shown(lang, value)
    if name in ("series", "axes") and isinstance(value, (tuple, list)):  # uPlot: dictionaries with a "label"
        return tuple(
            {**v, "label": shown(lang, v["label"])} if isinstance(v, dict) and isinstance(v.get("label"), str) else v
            for v in value
        )
    if isinstance(value, (tuple, list)):
        return tuple(shown(lang, v) if isinstance(v, str) else v for v in value)
    return value


class TabWords:
    """The words of one tab (``view``: its :class:`~.client.ClientView`, whose ``lang`` this sets)."""

    def __init__(self, view: Any) -> None:
        self.view = view
        self._lock = threading.Lock()
        self._texts: dict[str, dict[str, Any]] = {}
        """The English texts last written to each element of the tab (uuid -> property -> value)."""
        self._choices: set[str] = set()
        """Elements whose value is one of their options (dropdowns, button groups)."""
        self._send, headers = reword(view.client, self._out, self._back)
        view.lang = preferred(None if headers is None else headers.get("Accept-Language"))
        self.selector = view.client.gui.add_dropdown(
            LABEL, tuple(lang.label for lang in Lang), initial_value=view.lang.label
        )
        self.selector.on_update(self._on_select)
        self._style: Any = None
        self._typeset()

    def _typeset(self) -> None:
        """The page's line breaking for the tab's language (:data:`KEEP_ALL` in Korean; created when first needed)."""
        content = KEEP_ALL if self.view.lang is Lang.KO else ""
        if self._style is None and content:
            self._style = self.view.client.gui.add_html(content)
        elif self._style is not None:
            self._style.content = content

    # -- the connection -------------------------------------------------------------------------------------------
    def _out(self, uuid: str, texts: dict[str, Any] | None, kind: str) -> dict[str, Any]:
        """Remember the English ``texts`` of element ``uuid`` and return them as the tab shows them."""
        if texts is None:  # the element was removed
            with self._lock:
                self._texts.pop(uuid, None)
                self._choices.discard(uuid)
            return {}
        with self._lock:
            if kind == "new":
                self._texts[uuid] = dict(texts)
                if "options" in texts:
                    self._choices.add(uuid)
            choice = uuid in self._choices
            names = [n for n in texts if n in _WORDS or (n == "value" and choice)]
            if not names:
                return texts
            if kind != "new":
                self._texts.setdefault(uuid, {}).update((n, texts[n]) for n in names)
        lang = self.view.lang
        if lang is Lang.EN:
            return texts
        return {**texts, **{n: show_text(lang, "label" if n == "value" else n, texts[n]) for n in names}}

    def _back(self, uuid: str, value: Any) -> Any:
        """The English option behind the choice ``value`` the page sent for element ``uuid`` (any other value as it
        is). The tab's language first, then any other (a choice made just before a switch of language)."""
        with self._lock:
            options = self._texts.get(uuid, {}).get("options") if uuid in self._choices else None
        if not isinstance(value, str) or not options or value in options:
            return value
        current = self.view.lang
        for lang in (current, *[lang for lang in Lang if lang is not current]):
            for option in options:
                if isinstance(option, str) and shown(lang, option) == value:
                    return option
        return value

    # -- switching --------------------------------------------------------------------------------------------------
    @guarded
    def _on_select(self, event) -> None:
        if getattr(event, "client", None) is None:
            return
        self.set(Lang.parse(self.selector.value, default=self.view.lang))

    def set(self, lang: Lang) -> None:
        """Show this tab in ``lang``: every fixed text written again, then its live parts redrawn."""
        view = self.view
        with view.hub.lock:
            if view.closed:
                return
            if self.selector.value != lang.label:
                self.selector.value = lang.label  # an echo with client=None: ignored by the callback
            if lang is view.lang:
                return
            view.lang = lang
            self._typeset()
            with self._lock:
                everything = [(uuid, dict(texts)) for uuid, texts in self._texts.items()]
            for uuid, texts in everything:
                self._send(uuid, texts)  # shown in the new language on the way out
            self._redraw()
            view.client.flush()

    def _redraw(self) -> None:
        """The live parts of the tab (dashboard, equations, the teaching tabs' texts) drawn again in its language."""
        view = self.view
        view.panel.forget()
        frame = view.session.frame
        if frame is not None:
            view.render(frame)
        view.hub.membership_changed()  # the classroom line, written by the app (coalesced for all tabs)
        view.teaching.words_changed()
