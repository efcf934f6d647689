"""Wiring of the trajectory player and the guided demonstrations, without a browser: a protocol-level client
sends what a browser sends (tests/conftest.py), the tests check state, charts, scene nodes and panel text."""

from __future__ import annotations

import csv
import io
import time

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.app.lessons import DEMOS
from tpm_viz.paper.trajectories import circle_state, line_state
from tpm_viz.ui.teaching.player.charts import CHART_POINTS
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = Params.paper()


def _state(view):
    with view.hub.lock:
        return view.session.state


def _ps(view):
    with view.hub.lock:
        return view.teaching.services.runs.of(view.session)


def _run(view):
    return _ps(view).run


def _choose(client, view, label: str, kind: str, duration: float):
    client.set_value(view.teaching.player.choice, label)
    wait_for(
        lambda: (r := _run(view)) is not None and r.source.kind == kind and r.duration == duration,
        what=f"the {kind} run",
    )
    wait_for(lambda: _state(view).trajectory.kind == kind, what="the start of the run")


def _csv_upload(client, view, name: str, content: bytes) -> None:
    """What viser's upload button sends: a transfer start, then the parts."""
    import uuid

    transfer = str(uuid.uuid4())
    uid = widget_uuid(view.teaching.player.upload)
    parts = [content[i : i + 65536] for i in range(0, len(content), 65536)] or []
    client.send(
        type="FileTransferStartUpload",
        source_component_uuid=uid,
        transfer_uuid=transfer,
        filename=name,
        mime_type="text/csv",
        part_count=len(parts),
        size_bytes=len(content),
    )
    for k, part in enumerate(parts):
        client.send(
            type="FileTransferPart", source_component_uuid=uid, transfer_uuid=transfer, part_index=k, content=part
        )


def test_choosing_the_circle_loads_it_with_its_default_duration_and_both_models(connect):
    client, view = connect()
    _choose(client, view, "circle (Fig. 5)", "circle", 0.5)
    run, state = _run(view), _state(view)
    np.testing.assert_allclose(state.pose.p, (0.1, 0.0), atol=1e-12)  # the start of the circle
    assert state.load.mode == "dynamic"
    assert run.tau_ref is not None and run.max_diff < 1e-9  # Pinocchio, once per run
    pl = view.teaching.player
    assert pl.duration.inputs["T"].value == "0.5" and pl.time.max == 0.5
    charts = pl.charts
    for handle in charts.handles:
        assert handle.visible and 100 < len(handle.data[0]) <= CHART_POINTS and handle.data[0][-1] == 0.5
        assert all(np.all(np.isfinite(arr)) for arr in handle.data)  # never NaN on the wire
    assert charts.forces.series[3]["show"] is True  # the Pinocchio (dotted) series
    assert "run-peak'>177.1<" in pl.summary.content
    assert view.teaching.player.trace.path.visible


def test_a_tab_that_connects_later_sees_the_loaded_run(connect):
    client, view = connect()
    _choose(client, view, "circle (Fig. 5)", "circle", 0.5)
    _late_client, late = connect()
    pl = late.teaching.player
    wait_for(
        lambda: pl.charts.forces.visible and pl.choice.value == "circle (Fig. 5)" and "T = 0.5 s" in pl.summary.content,
        what="the run in the new tab",
    )
    assert "circle (Fig. 5), T = 0.5 s" in pl.summary.content and pl.trace.path.visible


def test_scrubbing_moves_the_platform_the_marker_and_the_equations(connect):
    client, view = connect()
    _choose(client, view, "line (Fig. 4)", "line", 0.2)
    pl = view.teaching.player
    before = view.panel.equations.content
    client.set_value(pl.time, 0.05)
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.05), what="t = 0.05 s")
    p, dp, ddp = line_state(0.05, 0.2)
    np.testing.assert_allclose(_state(view).pose.p, p)
    np.testing.assert_allclose(_state(view).load.dp, dp)
    np.testing.assert_allclose(_state(view).load.ddp, ddp)
    np.testing.assert_allclose(view.scene.platform.position[:2], p)
    t_chart, marker = pl.charts.forces.data[0], pl.charts.forces.data[-1]
    assert t_chart[np.argmax(marker)] == pytest.approx(0.05, abs=0.001)  # the marker at the sample nearest 0.05 s
    assert marker.max() == 1.0 and marker.min() == -1.0 and np.count_nonzero(marker == 1.0) == 1
    assert pl.trace.trace.visible and len(pl.trace.trace.points) >= 2
    eq = view.panel.equations.content  # the equations follow the trajectory sample (not a drag frame)
    assert eq != before and "(e) Actuator forces" in eq
    d_mm = f"{_state(view).pose.d[0] * 1e3:.1f}"
    assert d_mm in eq


def test_play_runs_to_the_end_in_slow_motion_and_any_other_input_stops_it(connect):
    client, view = connect()
    _choose(client, view, "circle (Fig. 5)", "circle", 0.5)
    pl = view.teaching.player
    client.set_value(pl.speed, "0.5×")
    wait_for(lambda: pl.speed.value == "0.5×", what="the speed")
    time.sleep(0.08)
    t0 = time.monotonic()
    client.set_value(pl.controls, "Play")
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.5), timeout=10, what="the end of the circle")
    assert time.monotonic() - t0 > 0.8  # 0.5 s of motion at 0.5x takes 1 s of wall clock
    np.testing.assert_allclose(_state(view).pose.p, circle_state(0.5, 0.5)[0], atol=1e-12)
    wait_for(lambda: not _ps(view).playing and "paused" in pl.summary.content, what="stopped at the end, and said so")
    assert "paused" in pl.summary.content and np.argmax(pl.charts.forces.data[-1]) == len(pl.charts.forces.data[0]) - 1

    client.set_value(pl.speed, "0.01×")
    time.sleep(0.08)
    client.set_value(pl.controls, "Play")  # from the start again: it was at the end
    wait_for(lambda: _ps(view).playing and 0 < _state(view).trajectory.t < 0.5, what="playing")
    client.click(view.panel.home)
    wait_for(lambda: _state(view).trajectory.kind == "none", what="home")
    wait_for(lambda: not _ps(view).playing, what="the player to notice")
    version = _state(view).version
    time.sleep(0.25)  # several frames of the player
    assert _state(view).version == version
    assert "moved by hand" in pl.summary.content


def test_pause_keeps_the_sample_and_play_resumes_from_it(connect):
    client, view = connect()
    _choose(client, view, "line (Fig. 4)", "line", 0.2)
    pl = view.teaching.player
    client.set_value(pl.speed, "0.05×")
    time.sleep(0.08)
    client.set_value(pl.controls, "Play")
    wait_for(lambda: _state(view).trajectory.t > 0.02, what="some progress")
    client.set_value(pl.controls, "Pause")
    wait_for(lambda: not _ps(view).playing, what="paused")
    t = _state(view).trajectory.t
    time.sleep(0.2)
    assert _state(view).trajectory.t == t and 0 < t < 0.2
    client.set_value(pl.controls, "Play")
    wait_for(lambda: _state(view).trajectory.t > t + 0.005, what="resumed")
    assert _state(view).trajectory.t < 0.2


def test_a_good_upload_is_played_and_a_bad_one_is_refused_to_its_tab_only(connect):
    client, view = connect()
    _other_client, other = connect()
    t = np.linspace(0.0, 1.0, 21)
    p = np.stack([0.06 * np.sin(np.pi * t), 0.03 * np.sin(2 * np.pi * t)], -1)
    good = "t,p1,p2\n" + "".join(f"{a},{b},{c}\n" for a, (b, c) in zip(t, p, strict=True))
    _csv_upload(client, view, "wave.csv", good.encode())
    wait_for(
        lambda: (
            (r := _run(view)) is not None
            and r.source.kind == "csv"
            and view.teaching.player.choice.value == "your CSV: wave.csv"
        ),
        what="the uploaded run, shown",
    )
    assert _run(other).source.label == "wave.csv, T = 1 s"  # the shared mechanism: every tab sees it
    assert view.teaching.player.choice.value == "your CSV: wave.csv"
    assert view.teaching.player.duration.inputs["T"].disabled
    good_run = _run(view)

    bad = "t,p1,p2\n0,0,0\n0.1,0.1,0\n0.2,0.4,0\n0.3,0.1,0\n"  # 400 mm: out of reach
    _csv_upload(client, view, "far.csv", bad.encode())
    note = view.teaching.player.note.handle  # under the upload button
    wait_for(lambda: "Refused" in note.content, what="the refusal")
    assert "far.csv" in note.content and "out of reach" in note.content
    assert view.panel.message.content == "" and other.teaching.player.note.handle.content == ""  # that tab only
    assert _run(view) is good_run  # the last good trajectory stays

    _csv_upload(client, view, "bad.csv", b"time,x\n1,2\n")
    wait_for(lambda: "missing column" in note.content, what="the format refusal")
    assert _run(view) is good_run and "far.csv" not in note.content  # one refusal at a time

    _csv_upload(client, view, "wave2.csv", good.encode())  # a later good upload clears the refusal
    wait_for(lambda: (r := _run(view)) is not None and r.source.label.startswith("wave2.csv"), what="the new run")
    assert note.content == ""


def test_the_csv_and_png_exports_go_to_the_tab_that_asked(connect):
    client, view = connect()
    _choose(client, view, "line (Fig. 4)", "line", 0.2)
    sent = []
    view.client.send_file_download = lambda name, data, **kw: sent.append((name, data))
    client.click(view.teaching.player.export_csv)
    wait_for(lambda: len(sent) == 1, what="the CSV")
    name, data = sent[0]
    rows = list(csv.reader(io.StringIO(data.decode())))
    assert name == "tpm-run-line-T0.2s.csv" and rows[0][:3] == ["t", "p1", "p2"] and len(rows) == 402
    assert float(rows[-1][0]) == pytest.approx(0.2) and "nan" not in data.decode().lower()
    tau = np.array([[float(r[rows[0].index("tau1")]), float(r[rows[0].index("tau1_pinocchio")])] for r in rows[1:]])
    assert np.max(np.abs(tau[:, 0] - tau[:, 1])) < 1e-9
    client.click(view.teaching.player.export_png)
    wait_for(lambda: len(sent) == 2, timeout=20, what="the PNG")
    assert sent[1][0] == "tpm-forces-line-T0.2s.png" and sent[1][1][:4] == b"\x89PNG"


def test_a_parameter_change_recomputes_the_run_for_the_new_mechanism(connect):
    client, view = connect()
    _choose(client, view, "circle (Fig. 5)", "circle", 0.5)
    old = _run(view)
    client.set_value(view.panel.params.inputs["m_p"], "4")
    client.click(view.panel.apply)
    wait_for(lambda: (r := _run(view)) is not None and r.params.m_p == 4.0, what="the recomputed run")
    assert _run(view).peak > old.peak  # a heavier platform needs larger forces
    assert _run(view).source == old.source


def test_a_private_copy_keeps_the_run(connect):
    client, view = connect()
    _choose(client, view, "line (Fig. 4)", "line", 0.2)
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: not view.session.shared, what="own copy")
    wait_for(lambda: _run(view) is not None, what="the adopted run")
    client.set_value(view.teaching.player.time, 0.1)
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(0.1), what="a seek on the copy")


def test_demos_set_mechanism_trajectory_camera_and_explorer(connect):
    client, view = connect()
    dv = view.teaching.demos
    client.set_value(dv.steps, "Show this one")
    wait_for(lambda: (r := _run(view)) is not None and r.source.kind == "segment", what="the demo's path")
    assert view.teaching.explorer.kind == "det_jx" and view.teaching.explorer.ellipses_on
    assert view.teaching.player.choice.value.startswith("demo: ")
    assert "×7.0" in dv.text.content  # the effect line, backed by the numbers
    look = np.array(view.client.camera.look_at)
    np.testing.assert_allclose(look, DEMOS[0].camera.look_at, atol=1e-6)  # the lesson's own view: the canvas is free
    time.sleep(0.08)
    client.set_value(dv.steps, "Next")
    wait_for(lambda: _state(view).params.l_a == pytest.approx(0.2), what="the shorter links")
    assert view.teaching.explorer.kind == "workspace" and dv.play.disabled
    assert _run(view) is None and _ps(view).status == ""  # a still scene: the previous path is unloaded
    assert "No trajectory loaded" in view.teaching.player.summary.content
    time.sleep(0.08)
    client.set_value(dv.choice, DEMOS[4].title)  # straight to "two assembly modes"
    wait_for(lambda: np.allclose(_state(view).pose.d, (0.05, 0.05)), what="the modes demo")
    assert _state(view).params == P and view.scene.ghost.visible
    time.sleep(0.08)
    client.set_value(dv.steps, "Previous")
    wait_for(lambda: (r := _run(view)) is not None and r.source.kind == "line", what="the agreement demo")
    client.set_value(dv.play, True)
    wait_for(lambda: _ps(view).playing or _state(view).trajectory.t > 0, what="its motion playing")


def test_presenter_mode_refuses_player_inputs_from_students(app, connect):
    from tpm_viz.classroom.access import Access

    client, view = connect()
    app.hub.access = Access("secret")
    client.set_value(view.teaching.player.choice, "circle (Fig. 5)")
    note = view.teaching.player.note.handle
    wait_for(lambda: "Refused" in note.content, what="the refusal under the player's controls")
    assert "presenter" in note.content and _run(view) is None
