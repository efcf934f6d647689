"""The panel's tabs in a browser test: every tab sits in one of four groups (``tpm_viz.ui.panels.GROUPS``), so a test
opens the group first, then the tab (:func:`open_tab`); and measurements of the stage in the page (the canvas's share
of the window, the rows of tabs, the first control of the open tab)."""

from __future__ import annotations

GROUP_OF = {
    "Move": "Explore",
    "Forces": "Explore",
    "Explorer": "Explore",
    "Demos": "Teach",
    "Player": "Teach",
    "Equations": "Teach",
    "Exercises": "Teach",
    "Control": "Lab",
    "Planner": "Lab",
    "Design": "Lab",
    "Parameters": "Setup",
    "Class & view": "Setup",
}
"""The group (an English tab name) of each tab."""

PANEL_TABS = "[role=tab]:not([data-floating-window] *)"
"""The tabs of the control panel (not those of the floating box of live numbers)."""

STAGE = """
() => {
  const shown = e => e.getClientRects().length > 0 && getComputedStyle(e).visibility !== 'hidden';
  const outside = e => !e.closest('[data-floating-window]');
  const c = document.querySelector('canvas[data-engine]').getBoundingClientRect();
  const tabs = [...document.querySelectorAll('[role=tab]')].filter(shown).filter(outside);
  const rows = [...new Set(tabs.map(e => Math.round(e.getBoundingClientRect().top)))].sort((a, b) => a - b);
  let first = null;
  if (tabs.length) {
    const last = tabs.filter(e => Math.round(e.getBoundingClientRect().top) === rows[rows.length - 1]);
    const below = Math.max(...last.map(e => e.getBoundingClientRect().bottom));
    const left = Math.min(...tabs.map(e => e.getBoundingClientRect().left));
    const under = sel => [...document.querySelectorAll(sel)].filter(shown).filter(outside)
      .map(e => [e.getBoundingClientRect(), e])
      .filter(([r]) => r.width > 0 && r.top >= below - 1 && r.left >= left - 8)
      .sort((a, b) => a[0].top - b[0].top);
    let controls = under('button, input:not([type=hidden]), textarea, [role=slider], select');
    if (!controls.length) controls = under('p, table, li');  // a tab of text only (Equations): its first line
    if (controls.length) {
      const [r, e] = controls[0];
      first = {top: r.top, bottom: r.bottom, what: (e.getAttribute('aria-label') || e.textContent || e.tagName).trim()};
    }
  }
  return {canvas: [c.left, c.top, c.right, c.bottom], share: c.width * c.height / (innerWidth * innerHeight),
          rows, names: tabs.map(e => e.textContent.trim()), first, width: innerWidth, height: innerHeight};
}
"""
"""The stage as the page shows it: the canvas's box and its share of the window, the distinct tops of the panel's
tabs (its rows), and the first control under the last row of tabs (the open tab's first control), in CSS px."""


def open_tab(page, name: str, group: str | None = None) -> None:
    """Open the panel's tab ``name`` (its shown name; ``group``: its group's shown name, default the English one)."""
    page.get_by_role("tab", name=group or GROUP_OF[name], exact=True).first.click()
    page.get_by_role("tab", name=name, exact=True).first.click()
    page.wait_for_timeout(250)
