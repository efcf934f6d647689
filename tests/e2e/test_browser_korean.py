"""Korean fits the panel: a tab opened by a browser set to Korean, in headless Chromium at 1024×768 (a laptop) and
390×844 (a phone), shows every tab of its panel in Korean with no text cut: no element of the panel that holds text
(a label, a button, a tab name, a paragraph) or an input (a dropdown's choice) is wider inside than its box.
The screenshots of each viewport are kept in a temporary folder (named in the test's output) to look at.

Korean glyphs need a font with Hangul on the test machine (Debian: ``fonts-nanum``); without one Chromium draws
boxes of another width and the measurement means nothing, so the first test asks for it.
"""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import tempfile

import pytest

from tests.support.browser import CHROMIUM, CHROMIUM_ARGS
from tests.support.protocol import wait_for
from tests.support.stage import GROUP_OF, open_tab
from tpm_viz.core.words import Lang, catalogue
from tpm_viz.ui.panels import GROUPS

HANGUL = re.compile("[\uac00-\ud7a3]")
CUT = """
() => {
  const panel = document.querySelector('.mantine-Paper-root');
  const out = [];
  for (const e of panel.querySelectorAll('*')) {
    if (e.clientWidth === 0) continue;
    const text = [...e.childNodes].some(n => n.nodeType === 3 && n.textContent.trim());
    const input = e.tagName === 'INPUT' && e.type !== 'hidden';
    if ((text || input) && e.scrollWidth > e.clientWidth + 1)
      out.push(`${e.tagName} ${e.scrollWidth} > ${e.clientWidth}: ${(input ? e.value : e.textContent).slice(0, 60)}`);
  }
  return out;
}
"""
"""Every element of the panel whose text (or input value) is wider than its box."""


def test_this_machine_has_a_font_with_hangul():
    fc_list = shutil.which("fc-list")
    if fc_list is None:
        pytest.skip("no fontconfig")
    fonts = subprocess.run([fc_list, ":lang=ko"], capture_output=True, text=True, check=False).stdout
    assert fonts.strip(), "no font with Hangul: apt-get install -y fonts-nanum (else Chromium draws boxes)"


@pytest.mark.browser
@pytest.mark.parametrize(("width", "height"), [(1024, 768), (390, 844)])
def test_a_korean_tab_fits_its_panel(app, width, height):
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    korean = set(catalogue(Lang.KO).values())
    shots = tempfile.mkdtemp(prefix=f"tpm-viz-korean-{width}-")
    with tempfile.TemporaryDirectory() as profile, sync_api.sync_playwright() as pw:
        context = pw.chromium.launch_persistent_context(
            profile,
            executable_path=CHROMIUM,
            args=CHROMIUM_ARGS,
            headless=True,
            locale="ko-KR",  # Accept-Language: ko-KR
            viewport={"width": width, "height": height},
        )
        try:
            page = context.new_page()
            page.goto(f"http://127.0.0.1:{app.port}/")
            page.get_by_text("언어", exact=True).wait_for(timeout=30_000)
            (view,) = wait_for(lambda: list(app.views.values()), what="the tab's view")
            assert view.lang is Lang.KO
            ko = catalogue(Lang.KO)
            groups = [ko[group] for group in GROUPS.values()]  # the row of groups, then the open group's tabs
            tabs = page.get_by_role("tab")
            names: list[str] = []
            for group in groups:
                handle = page.get_by_role("tab", name=group, exact=True)
                handle.click()
                wait_for(lambda h=handle: h.get_attribute("aria-selected") == "true", what=f"the {group} group open")
                shown = [tabs.nth(i).inner_text().strip() for i in range(tabs.count())]
                assert shown[: len(groups)] == groups, shown
                for name in shown[len(groups) :]:
                    open_tab(page, name, group=group)
                    assert page.evaluate(CUT) == [], f"cut in the {name} tab at {width}×{height}"
                    texts = page.locator(".mantine-Paper-root label").all_inner_texts()
                    assert any(HANGUL.search(t) for t in texts), f"no Korean label in the {name} tab"
                    page.screenshot(path=os.path.join(shots, f"{len(names):02d}.png"))
                    names.append(name)
            assert {ko[name] for name in GROUP_OF} <= set(names) <= korean, names
            print(f"screenshots: {shots}")
            with app.hub.lock:  # the check sees a cut text when there is one
                view.client.gui.add_button("가나다라마바사아자차카타파하" * 12)
                view.client.flush()
            wait_for(lambda: page.evaluate(CUT), what="the overlong button measured as cut")
        finally:
            context.close()
