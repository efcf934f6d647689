"""Words in two languages: English and Korean, chosen per browser tab (``docs/languages.md``).

gettext's model, small: the **English template is the key**. Code that writes words for people builds a
:class:`Phrase` (a template with ``str.format`` fields and the values to put in them) instead of an f-string; the
UI renders it in the tab's language with :func:`say`; ``str(phrase)`` is the English text (command line, logs).
The Korean templates live in ``assets/words/ko.toml`` (``"English template" = "Korean template"``); the same
fields must appear in both, which ``tests/core/test_words.py`` checks, together with "no template used in the
code is missing from the Korean catalogue" (it reads every ``Phrase("...")``, ``say(..., "...")`` and ``T("...")``
literal from the source, as ``xgettext`` does).

Errors carry phrases too: ``raise InputError(Phrase("... {x} ...", x=1))`` keeps ``str(exc)`` English, and
:func:`say` renders the phrase of an exception in the tab's language.

Texts that are fixed when a widget is built (labels, hints, options, tab names, static markdown) stay English in
the code; the tab's connection shows them in its language (:mod:`tpm_viz.ui.language`) with :func:`shown` (a whole
text) and :func:`shown_html` (each text between two tags). :func:`preferred` reads a browser's
``Accept-Language`` header.

Base layer: standard library only.
"""

from __future__ import annotations

import enum
import functools
import html
import re
import string
import tomllib
from collections.abc import Mapping
from dataclasses import dataclass, field
from importlib import resources
from types import MappingProxyType
from typing import Any

__all__ = ["Lang", "Phrase", "T", "catalogue", "fields_of", "preferred", "say", "shown", "shown_html"]


class Lang(enum.Enum):
    """The languages of the UI (``value``: the BCP-47 tag)."""

    EN = "en"
    KO = "ko"

    @property
    def label(self) -> str:
        """The language's own name, as the language selector shows it."""
        return {"en": "English", "ko": "한국어"}[self.value]

    @classmethod
    def parse(cls, text: object, default: Lang | None = None) -> Lang:
        """The language of a tag (``"ko"``, ``"ko-KR"``, ``"한국어"``, ``"English"``); ``default`` (English) else."""
        tag = str(text or "").strip().lower()
        for lang in cls:
            if tag == lang.label.lower() or tag.split("-")[0] == lang.value:
                return lang
        return default if default is not None else cls.EN


@dataclass(frozen=True)
class Phrase:
    """Words to show: an English ``template`` with ``str.format`` fields, and the ``values`` that fill them.

    Values may be phrases themselves (rendered in the same language). ``str(phrase)`` is the English text.
    """

    template: str
    values: Mapping[str, object] = field(default_factory=lambda: MappingProxyType({}))

    def __init__(self, template: str, /, **values: object) -> None:
        object.__setattr__(self, "template", str(template))
        object.__setattr__(self, "values", MappingProxyType(dict(values)))

    def render(self, lang: Lang = Lang.EN) -> str:
        """The text in ``lang`` (English when the catalogue has no entry: never an error, never empty)."""
        template = self.template if lang is Lang.EN else catalogue(lang).get(self.template, self.template)
        values = {k: (v.render(lang) if isinstance(v, Phrase) else v) for k, v in self.values.items()}
        for text in (template, self.template):  # a broken translation falls back to the English template
            try:
                return text.format(**values)
            except (KeyError, IndexError, ValueError, AttributeError, TypeError):
                continue
        return self.template  # braces that are not fields (a style rule): the text as written

    def __str__(self) -> str:
        return self.render(Lang.EN)

    def __reduce__(self) -> tuple[Any, tuple[str, dict[str, object]]]:
        """Pickled as its template and values (a design row crosses to a worker process with its reason)."""
        return _phrase, (self.template, dict(self.values))

    def __hash__(self) -> int:
        return hash((self.template, tuple(sorted((k, repr(v)) for k, v in self.values.items()))))

    def __eq__(self, other: object) -> bool:
        return isinstance(other, Phrase) and (self.template, dict(self.values)) == (other.template, dict(other.values))


def _phrase(template: str, values: dict[str, object]) -> Phrase:
    return Phrase(template, **values)


def T(template: str) -> Phrase:
    """A phrase without fields: a label, a button, a heading (``T("Apply parameters")``)."""
    return Phrase(template)


def say(lang: Lang, what: object, **values: object) -> str:
    """``what`` in ``lang``: a :class:`Phrase`, an exception whose first argument is a phrase, or a template string
    (filled with ``values``); any other object is shown with ``str``."""
    if isinstance(what, BaseException):
        what = what.args[0] if what.args and isinstance(what.args[0], Phrase) else str(what)
    if isinstance(what, Phrase):
        return what.render(lang)
    if isinstance(what, str):
        return Phrase(what, **values).render(lang)
    return str(what)


@functools.cache
def catalogue(lang: Lang) -> Mapping[str, str]:
    """The templates of ``lang``, keyed by their English template (``assets/words/<tag>.toml``; empty for English)."""
    if lang is Lang.EN:
        return MappingProxyType({})
    path = resources.files("tpm_viz.assets") / "words" / f"{lang.value}.toml"
    with path.open("rb") as f:
        table = tomllib.load(f)
    return MappingProxyType({str(k): str(v) for k, v in table.items()})


def fields_of(template: str) -> frozenset[str]:
    """The names of the ``str.format`` fields of a template (``"{x:.1f} mm"`` -> ``{"x"}``)."""
    return frozenset(name for _, name, _, _ in string.Formatter().parse(template) if name)


def shown(lang: Lang, text: str) -> str:
    """``text`` in ``lang`` if it is a whole template without fields of the catalogue (a label, an option), else
    ``text`` itself: what a tab's connection shows for a text fixed in the code."""
    return text if lang is Lang.EN else catalogue(lang).get(text, text)


_TEXT_NODE = re.compile(r">([^<>]+)<")


def shown_html(lang: Lang, markup: str) -> str:
    """``markup`` with every text between two tags that is a whole template of the catalogue (trimmed, HTML
    entities decoded) in ``lang``; the rest as it is."""
    if lang is Lang.EN or "<" not in markup:
        return markup
    words = catalogue(lang)

    def one(match: re.Match[str]) -> str:
        raw = match.group(1)
        key = html.unescape(raw).strip()
        if key not in words:
            return match.group(0)
        lead, trail = raw[: len(raw) - len(raw.lstrip())], raw[len(raw.rstrip()) :]
        return f">{lead}{html.escape(words[key], quote=False)}{trail}<"

    return _TEXT_NODE.sub(one, markup)


def preferred(accept_language: object, default: Lang = Lang.EN) -> Lang:
    """The UI language a browser asks for first in its ``Accept-Language`` header (``"ko-KR,ko;q=0.9,en;q=0.8"``
    -> Korean), among those of :class:`Lang`; ``default`` when it names none of them (or there is no header)."""
    ranked: list[tuple[float, int, Lang]] = []
    for index, item in enumerate(str(accept_language or "").split(",")[:32]):
        tag, _, params = item.strip().partition(";")
        q = 1.0
        for param in params.split(";"):
            name, _, value = param.strip().partition("=")
            if name.strip().lower() == "q":
                try:
                    q = float(value)
                except ValueError:
                    q = 0.0
        primary = tag.strip().lower().split("-")[0]
        lang = next((lang for lang in Lang if lang.value == primary), None)
        if lang is not None and q > 0:
            ranked.append((-q, index, lang))
    return min(ranked)[2] if ranked else default
