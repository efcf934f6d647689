"""The *Control* tab without a browser: a protocol-level client sends what a browser sends; the figures shown are
checked against :func:`tpm_viz.multibody.control.simulate` run here with the same setup."""

from __future__ import annotations

import re
import time
import uuid

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.paper.control import ControllerKind, Gains
from tpm_viz.paper.trajectories import trajectory_from_samples
from tpm_viz.viserkit.probe import widget_uuid

P = Params.paper()


def _state(view):
    with view.hub.lock:
        return view.session.state


def _q(html: str, key: str) -> str:
    m = re.search(rf"data-q='{key}'>([^<]*)<|data-q=\"{key}\">([^<]*)<", html)
    assert m, f"{key} not in {html[:300]}"
    return m.group(1) if m.group(1) is not None else m.group(2)


def _simulated(view, kinds=1):
    cv = view.teaching.control
    wait_for(lambda: len(cv.table) >= kinds and not cv.busy, timeout=20, what="the simulation")
    wait_for(lambda: _state(view).trajectory.kind.startswith("control#"), what="the run's start on the mechanism")
    return cv


def test_simulate_shows_the_run_its_charts_and_its_row_equal_to_the_library(connect):
    client, view = connect()
    cv = view.teaching.control
    assert "K_p = ω² = <span data-q='kp'>15791</span>" in cv.gains.content  # (2π 20)², shown from the start
    client.set_value(cv.wn, 15.0)
    client.set_value(cv.payload, 0.5)
    wait_for(lambda: cv.wn.value == 15.0 and cv.payload.value == 0.5, what="the sliders")
    # viser stores a value when it arrives and runs the callback later, in its pool: wait for the gains it writes
    wait_for(lambda: "K_p = ω² = <span data-q='kp'>8883</span>" in cv.gains.content, what="K_p")  # (2π 15)² = 8882.6
    client.click(cv.simulate)
    _simulated(view)
    expected = simulate(P, "line", ControlSetup(controller="ctc", gains=Gains(15.0, 1.0), payload=0.5))
    run = cv.run
    np.testing.assert_array_equal(run.p, expected.p)
    table = cv.table_html.content
    assert _q(table, "rms-ctc") == f"{expected.rms_error * 1e6:.2f}"
    assert _q(table, "max-ctc") == f"{expected.max_error * 1e6:.2f}"
    assert _q(table, "peak-ctc") == f"{expected.peak_force:.1f}"
    assert _q(cv.summary.content, "run-rms") == f"{expected.rms_error * 1e6:.2f}"
    assert float(_q(cv.summary.content, "sim-ms")) > 0
    for chart in (cv.error_chart, cv.force_chart):
        assert chart.handle.visible and all(np.all(np.isfinite(a)) for a in chart.handle.data)
    np.testing.assert_allclose(_state(view).pose.p, expected.p[0], atol=1e-12)  # t = 0: the actual platform
    wait_for(lambda: ("/control/ghost", client_owner(view)) in client.nodes, what="the ghost in the tab's scope")
    assert cv.nodes.ghost.visible
    np.testing.assert_allclose(cv.nodes.ghost.position[:2], expected.p_ref[0], atol=1e-9)

    client.set_value(cv.controller, "PD")  # a second controller on the same setup: a second row
    time.sleep(0.05)
    client.click(cv.simulate)
    wait_for(lambda: ControllerKind.PD in cv.table, timeout=20, what="the PD row")
    pd = simulate(P, "line", ControlSetup(controller="pd", gains=Gains(15.0, 1.0), payload=0.5))
    wait_for(lambda: "rms-pd" in cv.table_html.content, what="the PD row shown")
    assert _q(cv.table_html.content, "rms-pd") == f"{pd.rms_error * 1e6:.2f}"
    assert "rms-ctc" in cv.table_html.content


def client_owner(view) -> str:
    """The scope of this tab's own scene nodes (viser's client id)."""
    return str(view.client.client_id)


def test_the_lesson_runs_all_three_and_words_its_numbers(connect):
    client, view = connect()
    cv = view.teaching.control
    client.set_value(cv.wn, 10.0)
    wait_for(lambda: cv.wn.value == 10.0, what="ω_n")
    client.click(cv.lesson)
    _simulated(view, kinds=3)
    assert cv.payload.value == 1.0  # the lesson's payload, unknown to the controllers
    text, table = cv.lesson_text.content, cv.table_html.content
    for kind in ControllerKind:
        expected = simulate(P, "line", ControlSetup(controller=kind, gains=Gains(10.0, 1.0), payload=1.0))
        assert _q(table, f"rms-{kind.value}") == f"{expected.rms_error * 1e6:.2f}"
        assert f"{expected.rms_error * 1e6:.1f} µm" in text
    assert "payload of 1.00 kg" in text and "Smallest error here" in text


def test_play_moves_the_actual_platform_and_the_ghost_follows_the_reference(connect):
    client, view = connect()
    cv = view.teaching.control
    client.set_value(cv.wn, 5.0)  # a soft loop: errors of millimetres
    wait_for(lambda: cv.wn.value == 5.0, what="ω_n")
    client.click(cv.simulate)
    _simulated(view)
    run = cv.run
    client.set_value(cv.time, 0.1)
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.1), what="t = 0.1 s")
    k = int(np.argmin(np.abs(run.t - 0.1)))
    np.testing.assert_allclose(_state(view).pose.p, run.p[k], atol=1e-9)
    np.testing.assert_allclose(cv.nodes.ghost.position[:2], run.p_ref[k], atol=1e-9)
    client.set_value(cv.magnify, "×10")
    want = run.p_ref[k] + 10 * (run.p[k] - run.p_ref[k])
    wait_for(lambda: np.allclose(_state(view).pose.p, want, atol=1e-9), what="the error magnified ten times")

    client.set_value(cv.speed, "0.5×")
    time.sleep(0.05)
    client.set_value(cv.controls, "To start")
    wait_for(lambda: _state(view).trajectory.t == 0.0, what="the start")
    client.set_value(cv.controls, "Play")
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(run.t[-1]), timeout=10, what="the end of the run")
    wait_for(lambda: not cv.player.playing, what="stopped at the end")
    np.testing.assert_allclose(cv.nodes.ghost.position[:2], run.p_ref[-1], atol=1e-9)


def test_an_unstable_loop_is_refused_in_one_line_and_the_last_run_stays(connect):
    client, view = connect()
    cv = view.teaching.control
    client.click(cv.simulate)
    _simulated(view)
    good = cv.run
    client.set_value(cv.wn, 60.0)
    client.set_value(cv.rate, 100.0)  # 60 Hz loop sampled at 100 Hz: diverges
    wait_for(lambda: cv.rate.value == 100.0 and cv.wn.value == 60.0, what="the sliders")
    client.click(cv.simulate)
    wait_for(lambda: "Refused" in view.panel.message.content, timeout=20, what="the refusal")
    assert "\n" not in view.panel.message.content and "l_a" in view.panel.message.content
    wait_for(lambda: "Simulation refused" in cv.summary.content, what="the refusal in the tab")
    assert cv.run is good


def _csv_upload(client, view, name: str, content: bytes) -> None:
    """What viser's upload button sends (one part): a transfer start, then the content."""
    transfer = str(uuid.uuid4())
    uid = widget_uuid(view.teaching.player.upload)
    client.send(
        type="FileTransferStartUpload",
        source_component_uuid=uid,
        transfer_uuid=transfer,
        filename=name,
        mime_type="text/csv",
        part_count=1,
        size_bytes=len(content),
    )
    client.send(
        type="FileTransferPart", source_component_uuid=uid, transfer_uuid=transfer, part_index=0, content=content
    )


def test_the_players_uploaded_csv_is_a_reference(connect):
    client, view = connect()
    t = np.linspace(0.0, 1.0, 21)
    p = np.stack([0.06 * np.sin(np.pi * t), 0.03 * np.sin(2 * np.pi * t)], -1)
    text = "t,p1,p2\n" + "".join(f"{a},{b},{c}\n" for a, (b, c) in zip(t, p, strict=True))
    _csv_upload(client, view, "wave.csv", text.encode())
    cv = view.teaching.control
    wait_for(lambda: "your CSV: wave.csv" in cv.reference.options, what="the upload among the references")
    client.set_value(cv.reference, "your CSV: wave.csv")
    wait_for(lambda: cv.reference.value == "your CSV: wave.csv", what="the choice")
    client.click(cv.simulate)
    _simulated(view)
    with view.hub.lock:
        knots = view.teaching.services.runs.of(view.session).uploaded.knots
    expected = simulate(P, trajectory_from_samples(*knots, name="wave.csv"), ControlSetup(gains=Gains(20.0, 1.0)))
    assert cv.run.name == "wave.csv" and cv.run.t[-1] == pytest.approx(1.0)
    assert _q(cv.table_html.content, "rms-ctc") == f"{expected.rms_error * 1e6:.2f}"
