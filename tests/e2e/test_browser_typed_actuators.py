"""Typed actuator positions in headless Chromium, with the real keyboard (issue 13, "numbers as typed").

``1.5e2`` typed key by key into *d1 (mm)* and Enter: the actuator is at 150 mm, in the server's state and in the 3D
scene the page was sent. The scene is checked from an independent route: the websocket frames the page received
(decoded by tests/support/scene_frames.py), where the frame ``/tpm/slider1`` sits at ``A_1 = (d1 - a) e1`` (eq. 1
of the paper: d1 is the slider's distance along rail 1 from its base end at ``-a e1``). The slider beside it has no
number box of viser's, and a value beyond the stroke is refused right under the fields, in mm. All GUI inputs share
a 50 ms throttle in viser's client: we pause.
"""

from __future__ import annotations

import html
import time

import pytest

from tests.support.browser import text_input
from tests.support.protocol import wait_for
from tests.support.scene_frames import node_positions, open_recorded
from tpm_viz.ui.widgets.typed import QUIET
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.browser

A = 0.482  # m, the paper's a (Table 1): rail i starts at -a e_i
PAUSE = 0.08  # s, longer than the client's 50 ms input throttle


def test_typing_1_5e2_into_d1_puts_the_actuator_at_150_mm(app, browser):
    page, frames, errors, view = open_recorded(app, browser)
    wait_for(lambda: node_positions(page, frames), what="the slider's first position")
    assert node_positions(page, frames)[-1][0] == pytest.approx(0.130 - A, abs=1e-12)  # home: d1 = a - b - l_a

    # The slider is there to drag, without viser's number box beside it.
    slider = page.locator(f'[id="{widget_uuid(view.panel.d[0])}"]')
    assert slider.bounding_box()["width"] > 150
    assert slider.evaluate("e => getComputedStyle(e.nextElementSibling).display") == "none"

    field = text_input(page, view.panel.d_typed.inputs["d1"])
    assert field.input_value() == "130.0"  # one decimal, as the readout
    field.click()
    field.press("Control+a")
    started = time.monotonic()
    page.keyboard.type("1.5e2", delay=60)  # one key at a time, as a person types
    time.sleep(0.3)
    if time.monotonic() - started < 0.8 * QUIET:  # a loaded machine may stall the keys for longer than the quiet
        assert view.session.state.pose.d[0] == pytest.approx(0.13)  # time: then "1" was a pause (tests/ui checks it)
    field.press("Enter")
    wait_for(lambda: view.session.state.pose.d[0] == 0.15, what="d1 = 150 mm in the server's state")
    wait_for(lambda: node_positions(page, frames)[-1][0] == pytest.approx(0.150 - A, abs=1e-12), what="A_1 in 3D")
    x, y = node_positions(page, frames)[-1][:2]
    assert (x, y) == (pytest.approx(0.15 - A, abs=1e-12), pytest.approx(0.0, abs=1e-12))  # on rail 1, eq. (1)
    wait_for(lambda: page.locator("[data-q=d1]").first.inner_text().startswith("150.0"), what="the readout")
    wait_for(lambda: field.input_value() == "1.5e2", what="the text typed, kept: it means the value in use")

    # Beyond the stroke: refused under the fields, in mm; the actuator stays.
    time.sleep(PAUSE)
    field.click()
    field.press("Control+a")
    page.keyboard.insert_text("0.5 m")  # in one input: on a busy machine a stall after "0" would apply 0 mm (a pause)
    field.press("Enter")
    refusal = "d1: 500 mm is out of range; type a value from 0 to 300 mm"
    page.get_by_text(refusal).first.wait_for(timeout=10_000)
    below = page.get_by_text(refusal).first.bounding_box()
    d2 = text_input(page, view.panel.d_typed.inputs["d2"]).bounding_box()
    assert 0 <= below["y"] - (d2["y"] + d2["height"]) < 40  # right under the fields
    time.sleep(QUIET + 0.2)
    assert view.session.state.pose.d[0] == 0.15 and field.input_value() == "0.5 m"
    assert refusal in html.unescape(view.panel.d_typed.note.handle.content)
    assert errors == []
