"""What a page saw, server side (issue 40, items 3 and 5): the requests of :data:`tpm_viz.viserkit.seen.SEEN_SCRIPT`
over real HTTP to the served app, the tabs protocol clients.

- ``touch`` makes the tab's handle the touch handle (viser's fixed-size gizmo, no arrows);
- ``tabs:planner`` after a control run, with the demo's ellipses on: the scene shows the Planner's path and its forces
  (the mechanism at the plan's start, its dynamic load), not the lab's green reference, its ghost or the ellipses;
  ``tabs:`` (the Planner left) brings the ellipses back;
- a forged nonce, another site's page, a malformed word and an older count are refused or ignored.

Expected: the plan's start and its ``ṗ, p̈`` at t = 0 from the library (:func:`tpm_viz.app.planning.solve`), the plan
being the planner's own default (pick-and-place at 200 N).
"""

from __future__ import annotations

import http
import secrets
import urllib.error
import urllib.request

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.app.planning import solve
from tpm_viz.ui.teaching.stage import PLAN, front
from tpm_viz.viserkit.seen import SEEN_PATH, seen_request, tab_marker

pytestmark = pytest.mark.slow

P = Params.paper()


def _get(port: int, query: str, origin: str | None = None) -> int:
    request = urllib.request.Request(f"http://127.0.0.1:{port}{SEEN_PATH}?{query}")
    if origin is not None:
        request.add_header("Origin", origin)
    try:
        with urllib.request.urlopen(request, timeout=10) as response:
            return response.status
    except urllib.error.HTTPError as exc:
        return exc.code


def _state(view):
    with view.hub.lock:
        return view.session.state


def test_the_wire_format_refuses_every_other_word() -> None:
    nonce = secrets.token_urlsafe(16)
    assert seen_request(f"{SEEN_PATH}?n={nonce}&w=tabs:planner,player&c=7").what == "tabs:planner,player"
    assert seen_request(f"{SEEN_PATH}?n={nonce}&w=tabs:&c=8").what == "tabs:"
    assert seen_request("/tpm-viz/key?n=x") is None
    for bad in (
        f"n={nonce}&w=tabs:Planner&c=1",
        f"n={nonce}&w=tab:planner&c=1",
        f"n={nonce}&w=touch&c=-1",
        f"n={nonce}&w=touch",
        f"n={nonce}&w=<script>&c=1",
        "n=short&w=touch&c=1",
    ):
        with pytest.raises(ValueError):
            seen_request(f"{SEEN_PATH}?{bad}")
    with pytest.raises(ValueError):
        tab_marker('planner" onload="x')


def test_a_coarse_pointer_gets_the_touch_handle_and_forgeries_are_refused(app, connect):
    _client, view = connect()
    nonce = app.keyboard.nonce_of(view)
    assert not view.scene.touch
    assert _get(app.port, f"n={secrets.token_urlsafe(16)}&w=touch&c=1") == http.HTTPStatus.FORBIDDEN
    assert _get(app.port, f"n={nonce}&w=touch&c=1", origin="http://evil.example") == http.HTTPStatus.FORBIDDEN
    assert _get(app.port, f"n={nonce}&w=pointer&c=1") == http.HTTPStatus.BAD_REQUEST
    assert not view.scene.touch
    assert _get(app.port, f"n={nonce}&w=touch&c=2") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: view.scene.touch and view.scene.gizmo.fixed and view.scene.gizmo.disable_axes, what="touch")


def test_a_coarse_pointer_told_before_the_open_tabs_holds_when_the_pool_answers_them_out_of_order(
    app, connect, monkeypatch
):
    """The page tells ``touch`` (count 1) and its open tabs (count 2) at once; the pool may apply the tabs first.
    Under load the tabs hid the pointer (the touch handle never came: tests/e2e/test_browser_touch_handle.py)."""
    _client, view = connect()
    nonce = app.keyboard.nonce_of(view)
    shown: list[frozenset] = []
    monkeypatch.setattr(view.teaching, "shown", shown.append)
    assert _get(app.port, f"n={nonce}&w=tabs%3Aexplore&c=2") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: shown == [frozenset({"explore"})], what="the open tabs applied")
    assert _get(app.port, f"n={nonce}&w=touch&c=1") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: view.scene.touch, what="the touch handle")
    assert _get(app.port, f"n={nonce}&w=tabs%3Aplayer&c=1") == http.HTTPStatus.ACCEPTED  # older than explore's
    assert _get(app.port, f"n={nonce}&w=tabs%3Aplanner&c=3") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: len(shown) == 2, what="the newer tabs applied")
    assert shown == [frozenset({"explore"}), frozenset({"planner"})]


def test_the_planner_opened_shows_its_path_and_forces_not_the_control_run(app, connect):
    client, view = connect()
    nonce = app.keyboard.nonce_of(view)
    cv, pv, explorer = view.teaching.control, view.teaching.planner, view.teaching.explorer
    client.set_value(explorer.ellipses, True)  # a demo's ellipses
    wait_for(lambda: explorer._ellipses and all(h.visible for h in explorer._ellipses.values()), what="ellipses")
    client.click(cv.simulate)
    wait_for(lambda: cv.run is not None and not cv.busy, timeout=30, what="the control run")
    wait_for(lambda: cv.nodes.ghost is not None and cv.nodes.ghost.visible, what="the green ghost")
    wait_for(lambda: pv.player.motion is not None, what="the plan loaded")
    assert "control run" in str(_state(view).note)

    assert _get(app.port, f"n={nonce}&w=tabs:planner&c=5") == http.HTTPStatus.ACCEPTED
    wait_for(lambda: front(view) == PLAN, what="the Planner in front")
    wait_for(lambda: _state(view).trajectory.kind.startswith("plan#"), what="the mechanism on the plan")
    expected = solve(P, "pick", 200.0, None, "")
    s = expected.plan.sample([0.0])
    state = _state(view)
    np.testing.assert_allclose(state.pose.p, s.p[0], atol=1e-9)  # the plan's start
    assert state.load.mode == "dynamic"
    np.testing.assert_allclose(state.load.dp, s.dp[0], atol=1e-9)
    np.testing.assert_allclose(state.load.ddp, s.ddp[0], atol=1e-9)
    assert "planned path" in str(state.note) and "control run" not in str(state.note)
    wait_for(lambda: pv._path is not None and pv._path.visible, what="the pick path drawn")
    wait_for(lambda: not cv.nodes.ghost.visible, what="the control ghost hidden")
    assert not any(h.visible for h in cv.nodes.paths.values())  # the lab's reference and actual paths
    assert not any(h.visible for h in explorer._ellipses.values())  # the demo's ellipses
    assert pv._bars is not None and pv._bars.visible  # its force bars over the sliders

    assert _get(app.port, f"n={nonce}&w=tabs:&c=4") == http.HTTPStatus.ACCEPTED  # older: ignored
    assert _get(app.port, f"n={nonce}&w=tabs:&c=6") == http.HTTPStatus.ACCEPTED  # the Planner left
    wait_for(lambda: all(h.visible for h in explorer._ellipses.values()), what="the ellipses back")
    assert view.teaching.open_tabs == frozenset()
