"""Honest panels through the app (issue 25), with a protocol client sending what a browser sends.

After a control run the platform rests on the run's sample: the banner says whose dynamic load the forces are (run
and time). Moved by hand it shows the static load of the pose; a saved session never carries the run's load, so
after a restart the forces are the static load too. The expected forces are the paper's closed form at zero
velocity and acceleration (:func:`tpm_viz.paper.dynamics.inverse_dynamics`), not the app's readout code.
"""

from __future__ import annotations

import html
import re

import numpy as np
import pytest

from tests.support.fixtures import open_tab
from tests.support.protocol import wait_for
from tpm_viz.app.readouts import Load
from tpm_viz.classroom import sessionfile
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.teaching.stage import CONTROL, front


def _state(view):
    with view.hub.lock:
        return view.session.state


def _tau(view) -> np.ndarray:
    """τ₁, τ₂ [N] as the dashboard prints them (two decimals)."""
    with view.hub.lock:
        text = view.panel.dashboard.content
    return np.array([float(re.search(rf'data-q="tau{i}">([^<]*)<', text).group(1)) for i in (1, 2)])


def _banner(view) -> str:
    with view.hub.lock:
        return html.unescape(re.sub("<[^>]+>", " ", view.panel.dashboard.content))


def _at_rest(params, p) -> np.ndarray:
    return inverse_dynamics(params, p, (0.0, 0.0), (0.0, 0.0), f_ext=(0.0, 0.0))


def _control_run(client, view):
    cv = view.teaching.control
    client.click(cv.simulate)
    wait_for(lambda: cv.run is not None and not cv.busy, timeout=30, what="the simulation")
    wait_for(lambda: _state(view).trajectory.kind.startswith("control#"), what="the run's start on the mechanism")
    return cv


def test_after_a_control_run_the_banner_names_the_run_and_a_move_shows_the_static_load(connect):
    client, view = connect()
    cv = _control_run(client, view)
    state = _state(view)
    assert state.load.mode == "dynamic" and front(view) == CONTROL
    wait_for(lambda: "dynamic load of the control run at t = 0.000 s" in _banner(view), what="the run's line")
    moving = inverse_dynamics(state.params, state.pose.p, state.load.dp, state.load.ddp)
    np.testing.assert_allclose(_tau(view), moving, atol=0.006)  # the run's load, said to be so
    assert np.max(np.abs(moving - _at_rest(state.params, state.pose.p))) > 5.0  # the phantom of the issue

    owner = str(view.client.client_id)
    client.drag(view.scene.gizmo, owner, [(0.02, 0.01, 0.09)])  # back on Move: the platform moved by hand
    wait_for(lambda: _state(view).load == Load(), what="the static load")
    after = _state(view)
    assert after.trajectory.kind == "none"
    wait_for(lambda: "control run" not in _banner(view), what="the run's line gone")
    wait_for(lambda: np.allclose(_tau(view), _at_rest(after.params, after.pose.p), atol=0.006), what="τ at rest")
    assert cv.run is not None  # the run stays in its tab, to play again


def test_a_saved_session_after_a_control_run_reopens_at_rest(app, connect):
    client, view = connect()
    _control_run(client, view)
    saved = _state(view)
    text = app.room.session_json()  # what *Save session* downloads
    raw = sessionfile.json.loads(text)["shared"]
    assert raw["load"]["mode"] == "static" and raw["sample"]["kind"] == "none"  # the run's load is not saved

    server = build_server("127.0.0.1", 0)  # a restart: a new server opens the file
    second = TpmApp(server)
    opened: list = []
    try:
        _client2, view2 = open_tab(second, opened)
        second.room.open_session(view2, text.encode())
        wait_for(lambda: np.allclose(_state(view2).pose.p, saved.pose.p, atol=1e-12), what="the saved pose")
        assert _state(view2).load == Load()
        p = _state(view2).pose.p
        wait_for(lambda: np.allclose(_tau(view2), _at_rest(saved.params, p), atol=0.006), what="τ at rest")
    finally:
        for c in opened:
            c.close()
        second.stop()


def test_new_parameters_discard_the_control_run_and_say_so(connect):
    client, view = connect()
    cv = _control_run(client, view)
    client.set_value(view.panel.params.inputs["m_p"], "2.5")
    client.click(view.panel.apply)
    wait_for(lambda: _state(view).params.m_p == pytest.approx(2.5), what="m_p = 2.5 kg")
    wait_for(lambda: cv.run is None and "discarded" in cv.summary.content, what="the run discarded, and said so")
    assert "the control run was discarded" in cv.summary.content
    assert not cv.nodes.ghost.visible and not any(h.visible for h in cv.nodes.paths.values())
    after = _state(view)
    assert after.load == Load() and after.trajectory.kind == "none"
    wait_for(lambda: np.allclose(_tau(view), _at_rest(after.params, after.pose.p), atol=0.006), what="τ at rest")


def _shown(handle) -> bool:
    return handle is not None and bool(handle.visible)


def test_the_floor_shows_the_run_of_the_tab_used_last(connect):
    """The Planner tab showed the control lab's ghost and paths (and an uploaded path) over the planned path: the
    floor shows one run's drawing, the one of the tab used last."""
    client, view = connect()
    pv, player = view.teaching.planner, view.teaching.player
    wait_for(lambda: pv.result is not None and _shown(pv._path), timeout=30, what="the default plan")
    client.set_value(player.choice, "line (Fig. 4)")
    wait_for(lambda: _shown(player.trace.path), timeout=30, what="the player's path")
    cv = _control_run(client, view)
    wait_for(lambda: all(_shown(h) for h in cv.nodes.paths.values()), what="the control paths")
    assert _shown(cv.nodes.ghost) and not _shown(pv._path) and not _shown(player.trace.path)

    client.set_value(pv.controls, "Play")  # the Planner tab is used: its plan plays
    wait_for(lambda: _shown(pv._path) and not _shown(cv.nodes.ghost), what="the planned path in front")
    assert not any(_shown(h) for h in cv.nodes.paths.values()) and not _shown(player.trace.path)
