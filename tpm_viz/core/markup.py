"""Text that reaches a page as markup: one small escaping layer for every HTML and Markdown element of the UI.

viser shows an HTML element's content as raw HTML (``innerHTML``: ``<img src=x onerror=...>`` runs, an ``<iframe
srcdoc>`` runs script with the app's origin) and a Markdown element's content as GitHub Markdown with raw HTML passed
through unsanitised; its server also reads ``![...](path)`` images of Markdown from the disk. Labels, hints, options,
tab names and notifications are shown as text. So every string that reaches an HTML or Markdown element is one of:

- :class:`Html`: markup the code built: its literals, and every value in it escaped (:func:`escape`, :func:`html`,
  :func:`say_html`, :func:`join`);
- :class:`Markdown`: Markdown the code wrote (a literal of the code or of the word catalogue), values escaped
  (:func:`say_markdown`, :func:`markdown_text`);
- anything else: text, escaped by the element itself (:mod:`tpm_viz.ui.worded` does it for every element it
  makes): a share link's label, an upload's file name, a lesson's words, a refusal quoting what was typed are shown
  literally, never as markup.

A value is escaped for HTML by :func:`html.escape` (``& < > " '``); for Markdown every ASCII punctuation character
is backslash-escaped (CommonMark: then it is a literal character; no tag, link, image, autolink, emphasis or
heading can start) and line breaks become spaces. A :class:`~tpm_viz.core.words.Phrase` keeps its template as
markup (the code's) and escapes its values.

Base layer: standard library only.
"""

from __future__ import annotations

import html as _html
import string
from collections.abc import Iterable, Mapping
from typing import Any

from tpm_viz.core.words import Lang, Phrase, catalogue

__all__ = ["Html", "Markdown", "escape", "html", "join", "markdown_text", "say_html", "say_markdown"]

_PUNCTUATION = frozenset(string.punctuation)
_FORMATTER = string.Formatter()


class Html(str):
    """Markup built by the code (its literals, its values escaped): shown as HTML. ``Html + Html`` is markup;
    anything else added to it is text (escaped)."""

    __slots__ = ()

    def __add__(self, other: str) -> Html:
        return Html(str.__add__(self, escape(other)))

    def __radd__(self, other: str) -> Html:
        return Html(str.__add__(escape(other), self))


class Markdown(str):
    """Markdown written by the code (a literal of the code or of the catalogue, its values escaped)."""

    __slots__ = ()


def escape(value: object) -> Html:
    """``value`` as HTML text (an :class:`Html` as it is; a phrase in English)."""
    if isinstance(value, Html):
        return value
    return Html(_html.escape(str(value), quote=True))


def markdown_text(value: object) -> Markdown:
    """``value`` as Markdown text: shown literally (see the module docstring; a :class:`Markdown` as it is)."""
    if isinstance(value, Markdown):
        return value
    # one line; no leading spaces or tabs (four of them, or one tab, start a code block; a page shows none anyway)
    text = " ".join(str(value).splitlines()).lstrip(" \t")
    return Markdown("".join("\\" + c if c in _PUNCTUATION else c for c in text))


def join(separator: str, parts: Iterable[object]) -> Html:
    """The ``parts`` (each escaped unless :class:`Html`) joined by the literal ``separator``."""
    return Html(escape(separator).join(escape(p) for p in parts))


def html(template: str, /, **values: object) -> Html:
    """``template`` (markup written in the code, ``str.format`` fields) with every value escaped (an :class:`Html`
    or :class:`~tpm_viz.core.words.Phrase` value is rendered as markup: see :func:`say_html`)."""
    return Html(_fill(template, values, Lang.EN, escape))


def say_html(lang: Lang, what: object, **values: object) -> Html:
    """:func:`~tpm_viz.core.words.say` for an HTML element: the phrase's template (the code's, or the catalogue's in
    ``lang``) as markup, its values escaped; a template string likewise; an exception's phrase likewise, its message
    otherwise as text; any other object escaped as text."""
    return Html(_say(lang, what, values, escape))


def say_markdown(lang: Lang, what: object, **values: object) -> Markdown:
    """:func:`~tpm_viz.core.words.say` for a Markdown element: the template as Markdown, its values escaped."""
    return Markdown(_say(lang, what, values, markdown_text))


def _say(lang: Lang, what: object, values: Mapping[str, object], esc: Any) -> str:
    if isinstance(what, BaseException):  # its phrase, or its message as text (it may quote what was typed)
        what = what.args[0] if what.args and isinstance(what.args[0], Phrase) else esc(str(what))
    if isinstance(what, str) and not isinstance(what, (Html, Markdown)):
        what = Phrase(what, **values)
    if not isinstance(what, Phrase):
        return str(esc(what))
    template = what.template if lang is Lang.EN else catalogue(lang).get(what.template, what.template)
    for text in (template, what.template):  # a broken translation falls back to the English template
        try:
            return _fill(text, what.values, lang, esc)
        except (KeyError, IndexError, ValueError, AttributeError, TypeError):
            continue
    return str(esc(what.template))


def _fill(template: str, values: Mapping[str, object], lang: Lang, esc: Any) -> str:
    """``template.format(**values)`` with each value escaped by ``esc`` (after its conversion and format spec);
    a phrase value rendered in ``lang`` the same way."""
    out = []
    for literal, field, spec, conversion in _FORMATTER.parse(template):
        out.append(literal)
        if field is None:
            continue
        value, _key = _FORMATTER.get_field(field, (), dict(values))
        if isinstance(value, Phrase):
            out.append(_say(lang, value, {}, esc))
            continue
        if isinstance(value, (Html, Markdown)) and not spec and conversion is None:
            out.append(str(value))
            continue
        value = _FORMATTER.convert_field(value, conversion)
        out.append(str(esc(_FORMATTER.format_field(value, spec or ""))))
    return "".join(out)
