"""What the page sees and viser does not tell the server: a coarse pointer (a finger), and which tab of the panel is
open. A small script of its own (:data:`SEEN_SCRIPT`, put in the page with the page script by
:func:`~tpm_viz.viserkit.page.with_script`) tells it, with the tab's nonce (the ``data-tpmviz-keys`` element the
keyboard put in the panel: :mod:`tpm_viz.ui.keyboard`), as ``GET`` requests to :data:`SEEN_PATH`:

- ``touch``: the page's primary pointer is coarse (``(pointer: coarse)``: a phone or a tablet, whatever its user
  agent says), once per nonce (a reconnected tab has a new one);
- ``tabs:<name>,<name>``: the marked tabs of the panel now shown (:func:`tab_marker`, an element inside a tab; none:
  ``tabs:``), told when that changes: a click on a tab, the panel folded or unfolded. Looked at each click on a tab
  and every :data:`EVERY_MS` ms (bounded: one ``querySelectorAll`` of the markers).

The script also shows a tab the server asks for: a hidden element ``[data-tpmviz-show="STAMP"]`` whose ``data-path``
is the JSON list of the tabs' labels as the page shows them, outermost first (*Teach*, *Exercises*); it presses
Enter on each tab that is not selected yet (viser's dock tabs open on Enter or a press, not on a bare ``click()``),
one per look (every 250 ms; a stamp at most 120 looks), as a user would (:mod:`tpm_viz.ui.graded`: an exercise
launched from the LMS).

The server answers in :mod:`tpm_viz.ui.seen`. Nothing here is trusted beyond the nonce: a request only tells the
server what a tab shows, and :func:`seen_request` refuses any other word.
"""

from __future__ import annotations

import re
from dataclasses import dataclass
from importlib import resources

from tpm_viz.core.markup import Html
from tpm_viz.viserkit.keys import page_query

__all__ = ["EVERY_MS", "SEEN_PATH", "SEEN_SCRIPT", "SETTINGS", "SeenRequest", "seen_request", "tab_marker"]

SEEN_PATH = "/tpm-viz/seen"
"""The path the script tells the server what it sees at (``GET``, like a key)."""
EVERY_MS = 500
"""How often the script looks which marked tabs are shown [ms] (besides at each click on a tab)."""
_WHAT = re.compile(r"touch|tabs:(?:[a-z]{1,24}(?:,[a-z]{1,24}){0,15})?")


@dataclass(frozen=True)
class SeenRequest:
    """One thing a page told: the tab's ``nonce``, ``what`` (``touch`` or ``tabs:<name>,...``) and its ``count`` (the
    page counts what it tells: a later count is newer, whatever order the requests are answered in)."""

    nonce: str
    what: str
    count: int


def seen_request(path: str) -> SeenRequest | None:
    """The request for ``path`` (its query ``n``, ``w``, ``c``), or None when the path is not :data:`SEEN_PATH`. Raises
    ``ValueError`` (one line) for a malformed one."""
    fields = page_query(path, SEEN_PATH, ("n", "w", "c"), "request")
    if fields is None:
        return None
    nonce, what, count = fields
    if not _WHAT.fullmatch(what):
        raise ValueError("malformed request: what")
    if not (count.isdigit() and len(count) <= 9):
        raise ValueError("malformed request: count")
    return SeenRequest(nonce, what, int(count))


def tab_marker(name: str) -> Html:
    """The HTML of the marker of a tab of the panel (put inside the tab): ``name`` is what the script tells when the
    tab is shown (lower-case letters)."""
    if not re.fullmatch(r"[a-z]{1,24}", name):
        raise ValueError(f"a tab marker's name is 1-24 lower-case letters, not {name!r}")
    return Html(f'<div data-tpmviz-tab="{name}" style="height:0;margin:0;overflow:hidden"></div>')


SEEN_SCRIPT = resources.files("tpm_viz.viserkit").joinpath("seen.js").read_text(encoding="utf-8")
"""The script (``seen.js`` beside this module; its settings, :data:`SETTINGS`, come in the page script's JSON)."""
SETTINGS = {"path": SEEN_PATH, "every": EVERY_MS}
"""What ``seen.js`` reads (``CONFIG.seen`` of the page script's settings element)."""
