"""The HTML the LTI service answers with, in English or Korean: a refusal's one line, the deep-linking picker, the
form that posts a response back to the platform, and the page that opens the app from inside an LMS frame.

Every text is escaped; every page is sent with :func:`headers`: a Content-Security-Policy that allows no script but
the page's own (by nonce), ``form-action`` limited to where the page's form goes, ``Referrer-Policy: no-referrer``
(an app URL with its ticket is never sent to anyone) and ``Cache-Control: no-store``.
"""

from __future__ import annotations

import html
import secrets
from collections.abc import Sequence
from urllib.parse import urlsplit

from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.lti.deeplinking import Item, Pick
from tpm_viz.lti.refusals import Refused

__all__ = ["Page", "autopost_page", "headers", "open_app_page", "picker_page", "refusal_page"]

_STYLE = (
    "body{font-family:system-ui,sans-serif;max-width:44em;margin:2em auto;padding:0 1em;color:#0f172a}"
    "h1{font-size:1.3em}label{display:block;margin:.3em 0}button{font-size:1em;padding:.4em 1em;margin:.5em .5em 0 0}"
    ".why{background:#fef2f2;border-left:4px solid #b91c1c;padding:.6em}.muted{color:#64748b;font-size:.9em}"
)


class Page:
    """An HTML page, the origins its form may post to and its script nonce (None: no script)."""

    def __init__(self, text: str, form_to: Sequence[str] = (), nonce: str | None = None) -> None:
        self.text, self.form_to, self.nonce = text, tuple(form_to), nonce


def _origin(url: str) -> str:
    parts = urlsplit(url)
    return f"{parts.scheme}://{parts.netloc}"


def headers(page: Page) -> dict[str, str]:
    """The security headers of ``page``."""
    script = f"'nonce-{page.nonce}'" if page.nonce else "'none'"
    forms = " ".join(["'self'", *(_origin(u) for u in page.form_to)])
    return {
        "Content-Security-Policy": (
            f"default-src 'none'; style-src 'unsafe-inline'; script-src {script}; form-action {forms}; base-uri 'none'"
        ),
        "Referrer-Policy": "no-referrer",
        "X-Content-Type-Options": "nosniff",
        "Cache-Control": "no-store",
    }


def _page(lang: Lang, title: Phrase, body: str) -> str:
    return (
        f'<!doctype html><html lang="{lang.value}"><head><meta charset="utf-8">'
        f'<meta name="viewport" content="width=device-width,initial-scale=1"><title>{html.escape(say(lang, title))}'
        f"</title><style>{_STYLE}</style></head><body>{body}</body></html>"
    )


def refusal_page(refused: Refused, lang: Lang) -> Page:
    """The one line of a refusal."""
    title = T("tpm-viz: the launch was refused")
    body = (
        f"<h1>{html.escape(say(lang, title))}</h1>"
        f'<p class="why" data-why="{html.escape(refused.why.value)}">{html.escape(say(lang, refused.phrase))}</p>'
    )
    return Page(_page(lang, title, body))


def picker_page(pick: Pick, items: Sequence[Item], action: str) -> Page:
    """The deep-linking picker: the lessons and the exercises, one checkbox (or radio) each."""
    lang, esc = pick.lang, html.escape
    kind = "checkbox" if pick.multiple else "radio"

    def rows(found: list[Item]) -> str:
        if not found:
            return f'<p class="muted">{esc(say(lang, T("None yet.")))}</p>'
        out = []
        for item in found:
            graded = ""
            if item.graded and item.score_maximum:
                points = say(lang, "graded, out of {points:g} points", points=item.score_maximum)
                graded = f' <span class="muted">({esc(points)})</span>'

            out.append(
                f'<label><input type="{kind}" name="item" value="{esc(item.value)}"> {esc(item.title(lang))}{graded}'
                "</label>"
            )
        return "".join(out)

    title = T("Choose what to add to the course")
    body = (
        f'<h1>{esc(say(lang, title))}</h1><form method="post" action="{esc(action)}">'
        f'<input type="hidden" name="pick" value="{esc(pick.token)}">'
        f"<h2>{esc(say(lang, T('Lessons')))}</h2>{rows([i for i in items if i.kind == 'lesson'])}"
        f"<h2>{esc(say(lang, T('Exercises')))}</h2>{rows([i for i in items if i.kind == 'exercise'])}"
        f'<button type="submit" name="do" value="add">{esc(say(lang, T("Add to the course")))}</button>'
        f'<button type="submit" name="do" value="cancel">{esc(say(lang, T("Cancel")))}</button></form>'
        f'<p class="muted">{esc(say(lang, T("Each item becomes a link in the course that opens it in tpm-viz.")))}</p>'
    )
    return Page(_page(lang, title, body))


def autopost_page(url: str, fields: dict[str, str], lang: Lang) -> Page:
    """A form that posts ``fields`` to ``url`` at once (and a button, for a browser without scripts)."""
    esc, nonce = html.escape, secrets.token_urlsafe(16)
    title = T("Sending your choice back to the course")
    inputs = "".join(f'<input type="hidden" name="{esc(k)}" value="{esc(v)}">' for k, v in fields.items())
    body = (
        f"<h1>{esc(say(lang, title))}</h1>"
        f'<form method="post" action="{esc(url)}">{inputs}<button type="submit">{esc(say(lang, T("Continue")))}'
        f'</button></form><script nonce="{nonce}">document.forms[0].submit();</script>'
    )
    return Page(_page(lang, title, body), form_to=[url], nonce=nonce)


def open_app_page(url: str, lang: Lang) -> Page:
    """From inside an LMS frame: a link that opens the app in a window of its own (its cookies work there)."""
    esc = html.escape
    title = T("Open tpm-viz")
    body = (
        f"<h1>{esc(say(lang, title))}</h1>"
        f'<p><a href="{esc(url)}" target="_blank" rel="noopener noreferrer"><button type="button">'
        f"{esc(say(lang, title))}</button></a></p>"
        f'<p class="muted">{esc(say(lang, T("tpm-viz opens in a window of its own; open it within 2 minutes.")))}</p>'
    )
    return Page(_page(lang, title, body))
