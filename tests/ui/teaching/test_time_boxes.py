"""The *Time t (s)* boxes of the Player and of the Control lab's playback read numbers like every typed field (issue
40, item 1), through a real server: a protocol-level client sends what the browser sends (the whole text of the field
at each keystroke, Enter as a line break at its end).

Expected values: the circle of the paper at t = 0.2 s from its closed form (:func:`tpm_viz.paper.trajectories
.circle_state`, the run's own route is the app's player), the refusals as the app's sentences written out here
(the range is the run's duration: 0.5 s for the circle, the 0.2 s line of the lab before a run).
"""

from __future__ import annotations

import html

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz.paper.trajectories import circle_state

pytestmark = pytest.mark.slow


def _state(view):
    with view.hub.lock:
        return view.session.state


def _note(typed) -> str:
    return html.unescape(str(typed.box.note.handle.content))


def test_the_players_time_box_reads_2e_1_and_refuses_1e9_abc_and_minus_5(connect):
    client, view = connect()
    pv = view.teaching.player
    client.set_value(pv.choice, "circle (Fig. 5)")
    wait_for(
        lambda: (r := view.teaching.services.runs.of(view.session).run) is not None and r.source.kind == "circle",
        what="the circle loaded",
    )
    wait_for(lambda: pv.time.max == 0.5, what="the time box spanning the circle's 0.5 s")
    typed = pv.time_typed
    client.set_value(typed.field, "2")
    client.set_value(typed.field, "2e-1\n")  # was 0.500 s (the end): viser's number box read "2e-1" as 2
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.2, abs=1e-12), what="the circle at t = 0.2 s")
    p, _dp, _ddp = circle_state(np.array([0.2]), 0.5)
    np.testing.assert_allclose(_state(view).pose.p, p[0], atol=1e-9)
    assert pv.time.value == pytest.approx(0.2) and typed.field.value == "2e-1" and _note(typed) == ""

    for text, want in (
        ("1e9", "t: 1e+09 s is out of range; type a value from 0 to 0.5 s (in use: 0.2 s)"),  # was "90.5" shown
        ("abc", "t [s]: 'abc' is not a number (examples: 0.25, 0,25, -1.5e-3) (in use: 0.2 s)"),  # was a blank
        ("-5", "t: -5 s is out of range; type a value from 0 to 0.5 s (in use: 0.2 s)"),  # was clamped to 0
    ):
        client.set_value(typed.field, f"{text}\n")
        wait_for(lambda w=want: w in _note(typed), what=f"{text} refused under the box")
        assert typed.field.value == text  # the text typed stays, with the value in use under it
        assert _state(view).trajectory.t == pytest.approx(0.2, abs=1e-12) and pv.time.value == pytest.approx(0.2)
    client.set_value(typed.field, "0,35 s\n")  # a decimal comma and the unit
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.35, abs=1e-12), what="t = 0.35 s")
    wait_for(lambda: _note(typed) == "", what="the refusal gone")
    assert view.panel.message.content == ""  # next to the box, not at the top of the panel


def test_the_players_time_box_without_a_run_says_so_and_keeps_the_slider(connect):
    client, view = connect()
    pv = view.teaching.player
    typed = pv.time_typed
    client.set_value(typed.field, "0.1\n")
    wait_for(lambda: "load a trajectory first" in _note(typed), what="the refusal under the box")
    assert pv.time.value == 0.0


def test_the_control_labs_time_box_refuses_60_before_a_run_and_reads_a_time_after_one(connect):
    client, view = connect()
    cv = view.teaching.control
    typed = cv.time_typed
    client.set_value(typed.field, "60\n")  # was 0.2 s, silently
    want = "t: 60 s is out of range; type a value from 0 to 0.2 s (in use: 0 s)"
    wait_for(lambda: want in _note(typed), what="60 refused under the box")
    assert cv.time.value == 0.0
    client.set_value(typed.field, "0.1\n")  # in range, but nothing to play yet
    wait_for(lambda: "nothing to play yet: compute it first" in _note(typed), what="no run yet")
    assert cv.time.value == 0.0

    client.click(cv.simulate)  # the paper's line, T = 0.2 s
    wait_for(lambda: cv.run is not None and not cv.busy, timeout=30, what="the simulation")
    end = float(cv.run.t[-1])
    wait_for(lambda: cv.time.max == pytest.approx(end), what="the box spanning the run")
    client.set_value(typed.field, "1e-1\n")
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.1, abs=1e-12), what="the run at t = 0.1 s")
    k = int(np.argmin(np.abs(cv.run.t - 0.1)))
    np.testing.assert_allclose(_state(view).pose.p, cv.run.p[k], atol=1e-9)
    client.set_value(typed.field, "−5\n")  # the Unicode minus is read, and refused for the range
    wait_for(lambda: "t: -5 s is out of range" in _note(typed), what="-5 refused")
    assert "(in use: 0.1 s)" in _note(typed)
