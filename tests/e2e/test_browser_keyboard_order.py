"""The Tab order of the page is the one ``docs/keyboard.md`` lists (issue 40, item 8), in headless Chromium at
1366×768: Tab is pressed from the top of a new page and the focused element named each time (its ``aria-label``, its
text, or the label of its row); the names the doc writes in italics in its numbered list must come in that order,
each one focused before the next (the numbers between them, a tab's fields, are the panel's own order)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from tests.e2e.test_browser_layout import chromium, served  # noqa: F401  (fixtures)
from tests.e2e.test_browser_stage import _open

pytestmark = pytest.mark.browser

DOC = Path(__file__).resolve().parents[2] / "docs" / "keyboard.md"
NAME = """() => { const e = document.activeElement; if (!e || e === document.body) return '';
  const row = e.closest('[class*="Flex-root"]'); const label = row && row.querySelector('label');
  return (e.getAttribute('aria-label') || (e.tagName === 'INPUT' && label ? label.textContent : '') ||
          e.textContent || '').replace(/\\s+/g, ' ').trim(); }"""


def documented_order() -> list[str]:
    """The italic names of the doc's numbered list of the Tab order, in order."""
    text = DOC.read_text(encoding="utf-8")
    block = text[text.index("`Tab` goes through the page") :]
    items = re.findall(r"^\d+\. (.*(?:\n {3}.*)*)", block.split("\n\nthen round again")[0], flags=re.M)
    return [name for item in items for name in re.findall(r"\*([^*]+)\*", item)]


def test_the_tab_order_is_the_documented_one(served, chromium):  # noqa: F811
    names = documented_order()
    assert names[:4] == ["Close", "3D view", "Collapse panel area", "Settings"] and "Frame the mechanism" in names
    context, page, _view = _open(served, chromium, (1366, 768))
    try:
        page.locator("[data-guide]").wait_for()  # a new browser: the guide (and its Got it) is shown
        focused = []
        for _ in range(40):
            page.keyboard.press("Tab")
            focused.append(page.evaluate(NAME))
        print(focused)
        at = 0
        for name in names:
            if name == "Close" and not any(f == "Close" for f in focused[:2]):
                continue  # a computer with a GPU has no software-WebGL notice
            hit = next((k for k in range(at, len(focused)) if focused[k].startswith(name)), None)
            assert hit is not None, f"{name!r} not focused after {focused[at - 1] if at else 'the start'}: {focused}"
            at = hit + 1
    finally:
        context.close()
