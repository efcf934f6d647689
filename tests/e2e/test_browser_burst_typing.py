"""Numbers as typed, with quick hands, in headless Chromium (issue 25).

A number and Enter that arrive in one burst (``keyboard.type("60\\n", delay=0)``: a fast typist, a phone keyboard)
are applied whole, as is a pasted ``75⏎``: d1 ``60⏎`` is 60 mm (it was 6 mm: viser's page sends every GUI message
through one 50 ms throttle that keeps only the latest, and the form's submit replaced the held ``60``). Checked in
the server's state and in the 3D frame the page was sent (``/tpm/slider1`` at ``A_1 = (d1 - a) e1``, eq. 1). The
typed fields beside the Control sliders sit in the slider's row, after it in the Tab order, and refuse ``1e9``
with the app's sentence right under the row.
"""

from __future__ import annotations

import math

import pytest

from tests.support.browser import text_input
from tests.support.protocol import wait_for
from tests.support.scene_frames import node_positions, open_recorded
from tests.support.stage import open_tab
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

A = 0.482  # m, the paper's a (Table 1): rail i starts at -a e_i


def _slider1_x(page, frames: list[bytes]) -> float | None:
    """The last x [m] of the broadcast node ``/tpm/slider1`` in the frames the page received."""
    positions = node_positions(page, frames)
    return positions[-1][0] if positions else None


def test_a_number_and_enter_in_one_burst_apply_the_whole_number(app, browser):
    page, frames, errors, view = open_recorded(app, browser)

    field = text_input(page, view.panel.d_typed.inputs["d1"])
    for text, mm in (("60", 60.0), ("130", 130.0), ("2.5e2", 250.0)):
        field.click()
        field.press("Control+a")
        page.keyboard.type(text + "\n", delay=0)  # every key and Enter in one burst
        wait_for(lambda mm=mm: view.session.state.pose.d[0] == pytest.approx(mm * 1e-3, abs=1e-12), what=f"{mm} mm")
        wait_for(lambda mm=mm: _slider1_x(page, frames) == pytest.approx(mm * 1e-3 - A, abs=1e-12), what="A_1 in 3D")
        wait_for(lambda text=text: field.input_value() == text, what="the text, on one line")
    field.click()
    field.press("Control+a")
    page.keyboard.insert_text("75\n")  # pasted with its line break (a spreadsheet cell): applied, on one line
    wait_for(lambda: view.session.state.pose.d[0] == pytest.approx(0.075, abs=1e-12), what="75 mm pasted")
    wait_for(lambda: field.input_value() == "75", what="the pasted text, on one line")
    box = field.bounding_box()
    assert box["height"] < 40  # one line (viser's multi-line input is two rows high by itself)

    # The Control tab: ω_n's field beside its slider, next in the Tab order; 1e9 refused under the row.
    cv = view.teaching.control
    open_tab(page, "Control")
    wn = cv.typed["wn"]
    slider = page.locator(f'[id="{widget_uuid(wn.slider)}"]')
    typed = text_input(page, wn.field)
    typed.wait_for(timeout=10_000)
    s, t = slider.bounding_box(), typed.bounding_box()
    assert t["x"] >= s["x"] + s["width"] - 1  # to the right of the slider
    assert abs((t["y"] + t["height"] / 2) - (s["y"] + s["height"] / 2)) < 12  # in its row
    assert slider.evaluate("e => getComputedStyle(e.nextElementSibling).display") == "none"  # viser's box hidden
    page.locator(f'[id="{widget_uuid(wn.slider)}"] [role=slider]').focus()
    page.keyboard.press("Tab")
    assert typed.evaluate("e => e === document.activeElement")
    page.keyboard.press("Control+a")
    page.keyboard.type("1e9\n", delay=0)
    refusal = "ω_n: 1e+09 Hz is out of range; type a value from 1 to 60 Hz (in use: 20 Hz)"
    page.get_by_text(refusal).first.wait_for(timeout=10_000)
    below = page.get_by_text(refusal).first.bounding_box()
    assert 0 <= below["y"] - (t["y"] + t["height"]) < 40  # right under the row
    assert cv.wn.value == 20.0
    typed.click()
    page.keyboard.press("Control+a")
    page.keyboard.type("2.5e1\n", delay=0)
    kp = (2 * math.pi * 25.0) ** 2  # K_p = (2π ω_n)²
    wait_for(lambda: cv.wn.value == 25.0 and f"{kp:.0f}" in cv.gains.content, what="ω_n = 25 Hz and its K_p")
    wait_for(lambda: page.get_by_text(refusal).count() == 0, what="the refusal cleared")
    assert errors == []
