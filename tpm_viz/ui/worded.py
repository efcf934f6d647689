"""The GUI of one browser tab in its language, through viser's public GUI API: :class:`TabGui` wraps ``client.gui``.

The code writes its fixed texts in English (labels, hints, dropdown and button-group options, tab names, markdown,
HTML, chart titles, series and axis labels). :class:`TabGui` creates each element with those texts as the tab shows
them (:func:`show_text`: a whole text of the catalogue with :func:`tpm_viz.core.words.shown`; each text between two tags
of HTML with :func:`tpm_viz.core.words.shown_html`) and returns a :class:`Worded` handle over viser's own:

- setting a text (``handle.content = Html("<b>Forces</b>")``, ``label``, ``hint``, ``options``, ``title``,
  ``series``, ``axes``) keeps the English and writes the shown text to viser's handle; reading it gives the English
  back;
- an HTML or Markdown element shows as markup only what the code built as such (:class:`~tpm_viz.core.markup.Html`,
  :class:`~tpm_viz.core.markup.Markdown`); anything else is text, escaped here (:func:`as_html`,
  :func:`as_markdown`): a share link's label, a file name, a lesson's words are never read as markup by the page;
- a choice (:class:`Choice`: a dropdown, a button group) reads and writes its English option, whatever the page
  shows; the page's choice, made in the tab's language, is mapped back to the English option at the same place;
- ``on_update`` / ``on_click`` / ``on_upload`` / ``on_submit`` callbacks get an event whose ``target`` is the
  :class:`Worded` handle;
- everything else (``value`` of other inputs, ``visible``, ``data``, ``remove()``, ``with folder:``) is viser's.

:meth:`TabGui.relabel` shows every live element in another language (a choice: its options first, then its value;
the callbacks skip the server's own echoes of that). Texts built with numbers are rendered by their producers with
``say(view.lang, phrase)``; those pass :func:`show_text` unchanged.
"""

from __future__ import annotations

import dataclasses
import inspect
import threading
from collections.abc import Callable, Sequence
from typing import Any, ClassVar, TypeVar

import viser

from tpm_viz.core.markup import Html, Markdown
from tpm_viz.core.words import Lang
from tpm_viz.ui.shown import as_html, as_markdown, show_text
from tpm_viz.viserkit.core import relabel_tab, removed
from tpm_viz.viserkit.inputs import running, sent, writable

__all__ = ["TEXTS", "Choice", "Tab", "TabGui", "Tabs", "Worded", "as_html", "as_markdown", "put", "show_text", "stored"]

TEXTS = frozenset({"label", "hint", "content", "title", "options", "series", "axes"})
"""The text properties of a GUI element that a tab shows in its language."""


def put(handle: Any, value: Any) -> bool:
    """Write a widget's value unless an input of the browser is on its way to its callback (:meth:`Worded.put`;
    a handle that is not a :class:`Worded`, e.g. a test's stand-in, likewise). -> whether it was written."""
    if isinstance(handle, Worded):
        return handle.put(value)
    if not writable(handle):
        return False
    handle.value = value
    return True


def stored(handle: Any) -> Any:
    """A widget's value as viser holds it now (not the one its running callback's event brought)."""
    return handle.handle.value if isinstance(handle, Worded) else handle.value


class Worded:
    """A GUI element of one tab: viser's ``handle`` with its texts kept in English and shown in the tab's language."""

    _AS: ClassVar[dict[str, str]] = {}
    """Text property -> the name :func:`show_text` translates it as (markdown: a whole text, not HTML)."""
    _CONTENT: ClassVar[Any] = staticmethod(as_html)
    """What a ``content`` becomes before it is shown (an HTML element: :func:`as_html`; Markdown:
    :func:`as_markdown`): no text reaches the page as markup unless the code built it as such."""

    def __init__(self, gui: TabGui, handle: Any, texts: dict[str, Any]) -> None:
        object.__setattr__(self, "handle", handle)
        object.__setattr__(self, "_gui", gui)
        object.__setattr__(self, "_texts", texts)  # the English texts, as the code last wrote them
        object.__setattr__(self, "_quiet", False)  # relabelling: the server's own echoes reach no callback

    def __getattr__(self, name: str) -> Any:
        texts = self.__dict__.get("_texts", {})
        if name in texts:
            return texts[name]
        handle = self.__dict__["handle"]
        if name == "value":  # in its own callback: the value its event brought (viserkit/inputs.py)
            return sent(handle, handle.value)
        return getattr(handle, name)

    def __setattr__(self, name: str, value: Any) -> None:
        if isinstance(getattr(type(self), name, None), property):
            object.__setattr__(self, name, value)
        elif name in TEXTS:
            if name == "content":
                value = type(self)._CONTENT(value)
            self._texts[name] = value
            setattr(self.handle, name, self._show(name, value))
        elif name == "value":
            self.put(value)
        else:
            setattr(self.handle, name, value)

    def put(self, value: Any) -> bool:
        """Write the widget's value, unless a value the browser sent is on its way to this widget's callback
        (:mod:`tpm_viz.viserkit.inputs`: a redraw, a deferred build or a restore never writes over an input; its
        callback applies it, or refuses it and writes the state again). -> whether it was written."""
        if not writable(self.handle):
            return False
        self.handle.value = value
        return True

    def __enter__(self) -> Worded:
        self.handle.__enter__()
        return self

    def __exit__(self, *args: object) -> None:
        self.handle.__exit__(*args)

    def _show(self, name: str, value: Any) -> Any:
        return show_text(self._gui.lang, self._AS.get(name, name), value)

    def relabel(self) -> None:
        """Write every text again in the language of its :class:`TabGui`."""
        for name, value in self._texts.items():
            if value is not None:
                setattr(self.handle, name, self._show(name, value))

    def remove(self) -> None:
        self.handle.remove()

    # -- callbacks: the event's target is this handle -----------------------------------------------------------
    def _wrap(self, func: Callable[[Any], Any]) -> Callable[[Any], Any]:
        def event_of(event: Any) -> Any:
            quiet = self._quiet and getattr(event, "client", None) is None
            return None if quiet else dataclasses.replace(event, target=self)

        if inspect.iscoroutinefunction(func):

            async def run_async(event: Any) -> None:
                if (ours := event_of(event)) is not None:
                    if getattr(event, "client", None) is not None:
                        with running(self.handle):  # awaited by viser on the loop at once: nothing came between
                            pass
                    await func(ours)

            return run_async

        def run(event: Any) -> None:
            if (ours := event_of(event)) is None:
                return
            if getattr(event, "client", None) is None:  # the server's own write, echoed: no input applied
                func(ours)
                return
            with running(self.handle, event):  # the inputs arrived so far are this call's (viserkit/inputs.py)
                func(ours)

        return run

    def on_update(self, func: Callable[[Any], Any]) -> Callable[[Any], Any]:
        self.handle.on_update(self._wrap(func))
        return func

    def on_click(self, func: Callable[[Any], Any]) -> Callable[[Any], Any]:
        self.handle.on_click(self._wrap(func))
        return func

    def on_upload(self, func: Callable[[Any], Any]) -> Callable[[Any], Any]:
        self.handle.on_upload(self._wrap(func))
        return func

    def on_submit(self, func: Callable[[Any], Any]) -> Callable[[Any], Any]:
        self.handle.on_submit(self._wrap(func))
        return func


class MarkdownElement(Worded):
    """A markdown element: its content shown as a whole text of the catalogue, as its label would be."""

    _AS: ClassVar[dict[str, str]] = {"content": "label"}
    _CONTENT: ClassVar[Any] = staticmethod(as_markdown)


class Choice(Worded):
    """A dropdown or a button group: ``value`` and ``options`` in English; the page shows and sends them in the
    tab's language. Options that would show alike stay English (each choice must map back to one option)."""

    def _show(self, name: str, value: Any) -> Any:
        if name == "options":
            options = show_text(self._gui.lang, name, value)
            return options if len(set(options)) == len(options) else tuple(value)
        return super()._show(name, value)

    @property
    def value(self) -> Any:
        """The English option chosen (the page's choice mapped back; a value of no option as it is; in its own
        callback, the one its event brought)."""
        raw, english = sent(self.handle, self.handle.value), tuple(self._texts["options"])
        if raw in english and self._gui.lang is Lang.EN:
            return raw
        options = tuple(self.handle.options)
        if raw in options and len(options) == len(english):
            return english[options.index(raw)]
        for lang in Lang:  # a choice that arrived in another language (sent just before a switch)
            for option in english:
                if show_text(lang, "options", (option,))[0] == raw:
                    return option
        return raw

    @value.setter
    def value(self, value: Any) -> None:
        self.put(value)

    def put(self, value: Any) -> bool:
        """Write the English option ``value`` (shown in the tab's language), unless an input is on its way."""
        english = tuple(self._texts["options"])
        options = tuple(self.handle.options)
        if value in english and len(options) == len(english):
            value = options[english.index(value)]
        return super().put(value)

    def relabel(self) -> None:
        """Options first, then the value (the same English option), then the other texts."""
        value = self.value
        object.__setattr__(self, "_quiet", True)
        try:
            self.handle.options = self._show("options", self._texts["options"])
            self.value = value
        finally:
            object.__setattr__(self, "_quiet", False)
        for name, text in self._texts.items():
            if name != "options" and text is not None:
                setattr(self.handle, name, self._show(name, text))


class Tab(Worded):
    """One tab of a tab group or panel (``with tab:`` fills it); its label follows the tab's language."""

    def __setattr__(self, name: str, value: Any) -> None:
        if name == "label":
            self._texts["label"] = value
            self.relabel()
        else:
            super().__setattr__(name, value)

    def relabel(self) -> None:
        relabel_tab(self.handle, self._show("label", self._texts["label"]))


class Tabs(Worded):
    """A tab group or a panel: :meth:`add_tab` makes a :class:`Tab` labelled in the tab's language."""

    def add_tab(self, label: str, icon: Any = None) -> Tab:
        handle = self.handle.add_tab(show_text(self._gui.lang, "label", label), icon=icon)
        return self._gui.keep(Tab(self._gui, handle, {"label": label}))


W = TypeVar("W", bound=Worded)


class TabGui:
    """``client.gui`` of one tab, creating every element in the tab's language ``lang`` (see the module docstring).
    Other attributes (``main_panel``, ``configure_theme``) are viser's; an ``add_*`` not listed here is refused,
    so that nothing is created untranslated."""

    def __init__(self, gui: viser.GuiApi, lang: Lang = Lang.EN) -> None:
        self.gui = gui
        self.lang = lang
        """The language the tab's elements are shown in (:meth:`relabel` changes it)."""
        self._elements: list[Worded] = []
        self._prune_at = 256
        self._lock = threading.Lock()  # elements are made under the hub's lock, and by the app on connect

    def __getattr__(self, name: str) -> Any:
        if name.startswith("add_"):
            raise AttributeError(f"TabGui has no {name}: add it to tpm_viz/ui/worded.py with its texts")
        return getattr(self.gui, name)

    def keep(self, element: W) -> W:
        """Remember ``element`` for :meth:`relabel` (the removed ones are forgotten now and then)."""
        with self._lock:
            self._elements.append(element)
            if len(self._elements) > self._prune_at:
                self._elements = [e for e in self._elements if not removed(e.handle)]
                self._prune_at = 2 * len(self._elements) + 256
        return element

    def relabel(self, lang: Lang) -> None:
        """Show every live element in ``lang``."""
        with self._lock:
            self.lang = lang
            self._elements = live = [e for e in self._elements if not removed(e.handle)]
        for element in live:
            element.relabel()

    def _show(self, name: str, value: Any) -> Any:
        return show_text(self.lang, name, value)

    def _new(self, kind: type[W], handle: Any, **texts: Any) -> W:
        return self.keep(kind(self, handle, texts))

    # -- containers ---------------------------------------------------------------------------------------------
    def add_folder(self, label: str | None, **kw: Any) -> Worded:
        return self._new(Worded, self.gui.add_folder(self._show("label", label), **kw), label=label)

    def add_form(self, label: str | None, **kw: Any) -> Worded:
        return self._new(Worded, self.gui.add_form(self._show("label", label), **kw), label=label)

    def add_tab_group(self, **kw: Any) -> Tabs:
        return self._new(Tabs, self.gui.add_tab_group(**kw))

    def add_panel(self, **kw: Any) -> Tabs:
        return self._new(Tabs, self.gui.add_panel(**kw))

    # -- texts and charts ---------------------------------------------------------------------------------------
    def add_markdown(self, content: Markdown | str, **kw: Any) -> MarkdownElement:
        """A Markdown element: ``content`` as Markdown if it is a :class:`~tpm_viz.core.markup.Markdown`, else as
        text."""
        content = as_markdown(content)
        handle = self.gui.add_markdown(self._show("label", content), **kw)
        return self._new(MarkdownElement, handle, content=content)

    def add_html(self, content: Html | str, **kw: Any) -> Worded:
        """An HTML element: ``content`` as markup if it is an :class:`~tpm_viz.core.markup.Html`, else as text."""
        content = as_html(content)
        return self._new(Worded, self.gui.add_html(self._show("content", content), **kw), content=content)

    def add_uplot(
        self, data: Any, series: Sequence[Any], *, title: str | None = None, axes: Any = None, **kw: Any
    ) -> Worded:
        shown_series, shown_title = self._show("series", tuple(series)), self._show("title", title)
        handle = self.gui.add_uplot(data, shown_series, title=shown_title, axes=self._show("axes", axes), **kw)
        return self._new(Worded, handle, series=tuple(series), title=title, axes=axes)

    # -- inputs ---------------------------------------------------------------------------------------------------
    def add_button(self, label: str, *, hint: str | None = None, **kw: Any) -> Worded:
        handle = self.gui.add_button(self._show("label", label), hint=self._show("hint", hint), **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_upload_button(self, label: str, *, hint: str | None = None, **kw: Any) -> Worded:
        handle = self.gui.add_upload_button(self._show("label", label), hint=self._show("hint", hint), **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_checkbox(self, label: str, initial_value: bool, *, hint: str | None = None, **kw: Any) -> Worded:
        handle = self.gui.add_checkbox(self._show("label", label), initial_value, hint=self._show("hint", hint), **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_text(self, label: str, initial_value: str, *, hint: str | None = None, **kw: Any) -> Worded:
        handle = self.gui.add_text(self._show("label", label), initial_value, hint=self._show("hint", hint), **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_number(self, label: str, initial_value: float, *, hint: str | None = None, **kw: Any) -> Worded:
        handle = self.gui.add_number(self._show("label", label), initial_value, hint=self._show("hint", hint), **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_slider(
        self,
        label: str,
        min: float,
        max: float,
        step: float,
        initial_value: float,
        *,
        hint: str | None = None,
        **kw: Any,
    ) -> Worded:
        shown_label, shown_hint = self._show("label", label), self._show("hint", hint)
        handle = self.gui.add_slider(shown_label, min, max, step, initial_value, hint=shown_hint, **kw)
        return self._new(Worded, handle, label=label, hint=hint)

    def add_dropdown(
        self,
        label: str,
        options: Sequence[str],
        initial_value: str | None = None,
        *,
        hint: str | None = None,
        **kw: Any,
    ) -> Choice:
        choice = Choice(self, None, {"label": label, "hint": hint, "options": tuple(options)})
        shown_options = choice._show("options", tuple(options))
        first = initial_value
        if initial_value is not None and initial_value in options:
            first = shown_options[list(options).index(initial_value)]
        handle = self.gui.add_dropdown(
            self._show("label", label), shown_options, initial_value=first, hint=self._show("hint", hint), **kw
        )
        object.__setattr__(choice, "handle", handle)
        return self.keep(choice)

    def add_button_group(self, label: str, options: Sequence[str], *, hint: str | None = None, **kw: Any) -> Choice:
        choice = Choice(self, None, {"label": label, "hint": hint, "options": tuple(options)})
        shown_label, shown_hint = self._show("label", label), self._show("hint", hint)
        handle = self.gui.add_button_group(shown_label, choice._show("options", tuple(options)), hint=shown_hint, **kw)
        object.__setattr__(choice, "handle", handle)
        return self.keep(choice)
