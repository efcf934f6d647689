"""Numbers as typed, everywhere (issue 25): the typed fields beside the Control and Planner sliders, and Enter as
part of a field's text, through a real server. A protocol-level client sends what the browser sends: the whole text
of a field at each keystroke, and Enter as a line break at the end of the text (the fields are multi-line text
inputs, so that Enter reaches the server in the same message as the text; viser's 50 ms throttle keeps only the
latest message, and a form's submit replaced the last keystrokes).

Expected values are the numbers the texts spell (``2.5e1`` Hz is 25 Hz, ``1,5e2`` N is 150 N), the gains of the
control law written from them (K_p = (2π ω_n)²) and the planner's cycle at that force limit computed here by the
library; the refusals are the app's sentences, written out here.
"""

from __future__ import annotations

import html
import math
import re
import time

import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz import Params
from tpm_viz.app.paths import path_for
from tpm_viz.app.planner import Limits, plan_cycle
from tpm_viz.ui.widgets.typed import QUIET
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = Params.paper()


def _note(typed) -> str:
    return html.unescape(typed.box.note.handle.content)


def _all(view) -> dict:
    """Every typed slider of the tab, by name (the control lab's, then the planner's)."""
    return {**view.teaching.control.typed, **view.teaching.planner.typed}


def test_every_typed_slider_refuses_1e9_abc_and_minus_5_with_the_apps_sentences(connect):
    """``1e9``, ``abc`` and ``-5`` with Enter, into each of the nine fields: refused right under the field with the
    value in use, the slider keeps its value (``-5`` is applied only where it is in range: a mass error of -5 %)."""
    client, view = connect()
    expected_range = {  # name, unit, range, value in use: as the labels and the lab's defaults say
        "wn": ("ω_n", " Hz", "1 to 60 Hz", "20 Hz"),
        "zeta": ("ζ", "", "0.1 to 2", "1"),
        "payload": ("payload", " kg", "0 to 5 kg", "0 kg"),
        "mass_error": ("mass error", " %", "-50 to 50 %", "0 %"),
        "force_limit": ("force limit", " N", "0 to 1000 N", "0 N"),
        "rate": ("controller rate", " Hz", "100 to 5000 Hz", "1000 Hz"),
        "noise": ("position noise", " µm", "0 to 50 µm", "0 µm"),
        "force": ("F_max", " N", "20 to 1000 N", "200 N"),
        "speed": ("speed limit", " m/s", "0 to 5 m/s", "0 m/s"),
    }
    typed = _all(view)
    assert set(typed) == set(expected_range)
    for name, (label, unit, span, in_use) in expected_range.items():
        field, before = typed[name].field, typed[name].slider.value
        client.set_value(field, "1e9\n")
        want = f"{label}: 1e+09{unit} is out of range; type a value from {span} (in use: {in_use})"
        wait_for(lambda t=typed[name], w=want: w in _note(t), what=f"{name}: 1e9 refused")
        assert field.value == "1e9"  # Enter's line break is not kept; the text typed is
        client.set_value(field, "abc\n")
        want = f"{label} [{unit.strip()}]: 'abc' is not a number" if unit else f"{label}: 'abc' is not a number"
        wait_for(lambda t=typed[name], w=want: w in _note(t), what=f"{name}: abc refused")
        assert f"(in use: {in_use})" in _note(typed[name])
        client.set_value(field, "-5\n")
        if name == "mass_error":
            wait_for(lambda: typed["mass_error"].slider.value == -5.0, what="a mass error of -5 %")
            wait_for(lambda: _note(typed["mass_error"]) == "", what="nothing to say")
            continue
        want = f"{label}: -5{unit} is out of range; type a value from {span} (in use: {in_use})"
        wait_for(lambda t=typed[name], w=want: w in _note(t), what=f"{name}: -5 refused")
        assert typed[name].slider.value == before
    assert view.panel.message.content == ""  # next to the fields, not at the top of the panel


def test_a_typed_omega_n_moves_the_slider_and_the_gains_and_a_drag_is_shown_in_the_field(connect):
    client, view = connect()
    cv = view.teaching.control
    wn = cv.typed["wn"]
    client.set_value(wn.field, "2")  # the first key, then the rest and Enter in one message (a burst)
    client.set_value(wn.field, "2.5e1\n")
    wait_for(lambda: cv.wn.value == 25.0, what="ω_n = 25 Hz")
    kp = (2 * math.pi * 25.0) ** 2  # K_p = ω², ω = 2π ω_n: 24674 1/s²
    wait_for(lambda: f"<span data-q='kp'>{kp:.0f}</span>" in cv.gains.content, what="K_p of 25 Hz")
    assert wn.field.value == "2.5e1" and _note(wn) == ""  # the text typed stays: it means the value in use
    client.set_value(cv.wn, 12.5)  # a drag of the slider: the field follows
    wait_for(lambda: wn.field.value == "12.5", what="the field showing the slider")
    wait_for(lambda: f"<span data-q='kp'>{(2 * math.pi * 12.5) ** 2:.0f}</span>" in cv.gains.content, what="K_p")


def test_a_typed_f_max_replans_with_the_librarys_cycle(connect):
    client, view = connect()
    pv = view.teaching.planner
    client.set_value(pv.typed["force"].field, "1,5e2 N\n")  # a decimal comma and the unit
    wait_for(lambda: pv.force.value == 150.0, what="F_max = 150 N")
    plan = plan_cycle(P, path_for(P, "pick"), Limits(150.0))

    def shown() -> str | None:
        m = re.search(r"data-q='plan-force'>([^<]*)<", pv.result_html.content)
        c = re.search(r"data-q='cycle-time'>([^<]*)<", pv.result_html.content)
        return c.group(1) if m and c and m.group(1) == "150" else None

    wait_for(lambda: shown() == f"{plan.duration:.3f}", timeout=30, what="the cycle time at 150 N")


def test_enter_as_a_line_break_applies_the_whole_text_at_once(connect):
    """d1: ``6`` (the first key, sent at once) then ``60`` and Enter in one message: 60 mm, and the field shows
    ``60`` without the line break; a caret in the middle (``7⏎0``) is the same. The Parameters have no quiet time
    (Enter or Apply only): a line break there is Enter, nothing else could apply it."""
    client, view = connect()
    field = view.panel.d_typed.inputs["d1"]
    client.set_value(field, "6")
    client.set_value(field, "60\n")
    wait_for(lambda: view.session.state.pose.d[0] == pytest.approx(0.060, abs=1e-12), what="d1 = 60 mm")
    wait_for(lambda: field.value == "60", what="the text without its line break")
    client.set_value(field, "7\r\n0")  # Enter typed with the caret after the 7 (a Windows line break)
    wait_for(lambda: view.session.state.pose.d[0] == pytest.approx(0.070, abs=1e-12), what="d1 = 70 mm")
    wait_for(lambda: field.value == "70", what="the text on one line")
    m_p = view.panel.params.inputs["m_p"]
    client.set_value(m_p, "2")
    time.sleep(QUIET + 0.3)
    assert view.session.state.params.m_p == P.m_p  # typed, never applied by itself
    client.set_value(m_p, "2,5\n")
    wait_for(lambda: view.session.state.params.m_p == 2.5, what="m_p = 2.5 kg on Enter")
    wait_for(lambda: m_p.value == "2,5", what="the text without its line break")


class _Recording(ProtocolClient):
    """A protocol client that keeps the texts the server writes into GUI inputs, by uuid."""

    def __init__(self, port: int) -> None:
        self.written: dict[str, list[object]] = {}
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        if m.get("type") == "GuiUpdateMessage" and "value" in (m.get("updates") or {}):
            self.written.setdefault(m["uuid"], []).append(m["updates"]["value"])


def test_keys_lost_in_the_throttle_leave_the_box_showing_what_is_applied(app):
    """The lost-field case: ``130`` typed into d1 and, within 50 ms, ``130⏎`` into d2: viser's page sent d1's ``1``
    at once and replaced ``13``, ``130`` by d2's messages, so the server never sees them. It cannot know; the group
    is applied with what arrived (d1 = 1 mm), and d1's text as the server has it is written back into the page, so
    the box shows ``1``, the value in use, not the ``130`` the page would otherwise keep showing."""
    client = _Recording(app.port)
    try:
        view = wait_for(lambda: next(iter(app.views.values()), None), what="the tab's view")
        wait_for(lambda: view.session.readout is not None, what="the first render")
        d1, d2 = view.panel.d_typed.inputs["d1"], view.panel.d_typed.inputs["d2"]
        client.set_value(d1, "1")  # what arrived of d1
        client.set_value(d2, "130\n")  # the latest message: d2's text and Enter
        wait_for(lambda: view.session.state.pose.d[0] == pytest.approx(0.001, abs=1e-12), what="d1 = 1 mm")
        wait_for(lambda: client.written.get(widget_uuid(d1), [])[-1:] == ["1"], what="d1's text written back")
        assert d1.value == "1" and d2.value == "130"
    finally:
        client.close()
