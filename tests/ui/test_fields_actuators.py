"""Typed actuator positions d1, d2 through a real server (issue 13, "numbers as typed"): a protocol-level client sends
what a browser sends (the whole text of a field at each keystroke, Enter as the form's submit).

Expected values are the numbers the texts spell (``1.5e2`` mm = 0.15 m, ``0.15 m``, ``2e2`` mm = 0.2 m) and the
paper's stroke ``Δd = 300 mm`` (Table 1) as the accepted range. The sliders stay, for dragging, without viser's
number box.
"""

from __future__ import annotations

import html
import time

import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.app import transitions
from tpm_viz.core.words import Lang, catalogue
from tpm_viz.ui.widgets.typed import QUIET
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = Params.paper()
HOME_D = 0.482 - 0.092 - 0.260  # a - b - l_a: both actuators at p = 0 (eq. 4), m


def _state(view):
    with view.hub.lock:
        return view.session.state


def _note(view) -> str:
    return html.unescape(view.panel.d_typed.note.handle.content)


def test_enter_applies_a_number_in_scientific_notation_and_keeps_the_text(connect):
    client, view = connect()
    box = view.panel.d_typed
    assert box.inputs["d1"].value == "130.0" and box.inputs["d2"].value == "130.0"  # in use, mm, as the readout
    client.enter(box, {"d1": "1.5e2"})
    wait_for(lambda: _state(view).pose.d[0] == 0.15, what="d1 = 150 mm")
    assert _state(view).pose.d[1] == pytest.approx(HOME_D, abs=1e-15)  # d2 was not typed: unchanged
    wait_for(lambda: view.panel.d[0].value == pytest.approx(150.0), what="the slider follows")
    assert box.inputs["d1"].value == "1.5e2"  # what was typed stays: it means the value in use
    assert _note(view) == ""  # nothing to say


def test_metres_and_a_decimal_comma(connect):
    client, view = connect()
    client.enter(view.panel.d_typed, {"d1": "0.2 m", "d2": "150,5"})
    wait_for(lambda: list(_state(view).pose.d) == pytest.approx([0.2, 0.1505], abs=1e-15), what="both at once")


def test_out_of_the_stroke_is_refused_under_the_box_as_the_fix_in_mm(connect):
    client, view = connect()
    version = _state(view)
    client.enter(view.panel.d_typed, {"d2": "0.5 m"})
    wait_for(lambda: "type a value from 0 to 300 mm" in _note(view), what="the refusal under d1, d2")
    assert "d2: 500 mm is out of range" in _note(view) and "(in use: 130.0 mm)" in _note(view)
    assert _state(view) is version  # the last good state stays
    assert view.panel.d_typed.inputs["d2"].value == "0.5 m"  # the field keeps what was typed
    client.enter(view.panel.d_typed, {"d2": "abc"})
    wait_for(lambda: "'abc' is not a number" in _note(view), what="not a number")
    client.enter(view.panel.d_typed, {"d2": "300"})  # the stroke end itself is fine
    wait_for(lambda: _state(view).pose.d[1] == pytest.approx(0.3, abs=1e-15), what="d2 = 300 mm")
    wait_for(lambda: _note(view) == "", what="the refusal cleared by the success")


def test_keystrokes_apply_once_after_the_quiet_time_never_a_prefix(connect):
    client, view = connect()
    seen = []
    original = transitions.drive_both
    field = view.panel.d_typed.inputs["d2"]
    client.set_value(field, "")
    try:
        transitions.drive_both = lambda state, d_mm: seen.append(tuple(d_mm)) or original(state, d_mm)
        for k in range(1, 4):  # "2", "2e", "2e2"
            client.set_value(field, "2e2"[:k])
            time.sleep(0.05)
        time.sleep(0.5 * QUIET)
        assert seen == []  # "2" (mm) was never applied
        wait_for(lambda: _state(view).pose.d[1] == 0.2, timeout=QUIET + 5, what="d2 = 200 mm after the quiet time")
        time.sleep(0.3)
        assert [d2 for _d1, d2 in seen] == [200.0]
    finally:
        transitions.drive_both = original


def test_the_slider_still_drives_and_the_typed_field_shows_its_value(connect):
    client, view = connect()
    client.set_value(view.panel.d[0], 250.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.25) < 1e-12, what="d1 = 250 mm by the slider")
    wait_for(lambda: view.panel.d_typed.inputs["d1"].value == "250.0", what="the typed field shows it")
    uuids = [widget_uuid(handle) for handle in view.panel.d]
    css = view.panel.d_css.content
    assert all(f'[id="{u}"] ~ *' in css for u in uuids) and "display: none" in css  # no number box beside them


def test_a_longer_stroke_widens_the_range(connect):
    client, view = connect()
    client.enter(view.panel.params, {"stroke": "320"})
    wait_for(lambda: _state(view).params.stroke == pytest.approx(0.32), what="the stroke 320 mm")
    client.enter(view.panel.d_typed, {"d1": "310"})
    wait_for(lambda: _state(view).pose.d[0] == pytest.approx(0.31, abs=1e-15), what="d1 = 310 mm")
    client.enter(view.panel.d_typed, {"d1": "330"})
    wait_for(lambda: "type a value from 0 to 320 mm" in _note(view), what="the new range in the refusal")


def test_an_internal_error_is_reported_in_the_tabs_language(connect):
    client, view = connect()
    client.set_value(view.words.selector, "한국어")
    wait_for(lambda: view.lang is Lang.KO, what="Korean")
    original = transitions.drive_both

    def broken(state, d_mm):
        raise RuntimeError("a bug")

    transitions.drive_both = broken
    try:
        client.enter(view.panel.d_typed, {"d1": "140"})
        korean = catalogue(Lang.KO)["internal error ({kind}), logged on the server"].format(kind="RuntimeError")
        wait_for(lambda: korean in view.panel.message.content, what="the report in Korean")
    finally:
        transitions.drive_both = original
    assert _state(view).pose.d[0] == pytest.approx(HOME_D, abs=1e-15)
