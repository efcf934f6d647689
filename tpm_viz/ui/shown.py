"""What a tab's element shows: a text in the tab's language (:func:`show_text`), and an element's content as markup
only when the code built it as such (:func:`as_html`, :func:`as_markdown`; :mod:`tpm_viz.core.markup`). Used by
:mod:`.worded` for every element it makes."""

from __future__ import annotations

import functools
from typing import Any

from tpm_viz.core.markup import Html, Markdown, escape, markdown_text
from tpm_viz.core.words import Lang, shown, shown_html

__all__ = ["as_html", "as_markdown", "show_text"]


@functools.lru_cache(maxsize=512)
def _shown_content(lang: Lang, text: str) -> str:
    """An HTML or markdown text as ``lang`` shows it (memoised: every tab of a session in one language is sent the
    same dashboard and equations at each frame)."""
    whole = shown(lang, text)
    return whole if whole is not text else shown_html(lang, text)


def as_html(content: object) -> Html:
    """What an HTML element shows: an :class:`~tpm_viz.core.markup.Html` as markup, anything else as text (escaped:
    :mod:`tpm_viz.core.markup`)."""
    return content if isinstance(content, Html) else escape("" if content is None else content)


def as_markdown(content: object) -> Markdown:
    """What a Markdown element shows: a :class:`~tpm_viz.core.markup.Markdown` as Markdown, anything else as text
    (every Markdown and HTML character escaped)."""
    return content if isinstance(content, Markdown) else markdown_text("" if content is None else content)


def show_text(lang: Lang, name: str, value: Any) -> Any:
    """The value of the text property ``name`` as a tab in ``lang`` shows it (see the module docstring); a text is
    sent as a plain ``str`` (viser's encoder takes no subclass, e.g. :class:`~tpm_viz.core.markup.Html`)."""
    if isinstance(value, str):
        value = str(value)
    if lang is Lang.EN or value is None:
        return value
    if name == "content" and isinstance(value, str):
        return _shown_content(lang, value)
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
