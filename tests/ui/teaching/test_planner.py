"""The *Planner* tab without a browser: the cycle time shown equals the library's plan at that limit, a limit
slider updates it within 200 ms (timed at the protocol client: the slider message sent -> the panel update
received), the motion plays with force bars, bad waypoints are refused in one line."""

from __future__ import annotations

import re
import threading
import time

import numpy as np
import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz import Params
from tpm_viz.app.paths import path_for
from tpm_viz.app.planner import Limits, plan_cycle, plan_path
from tpm_viz.app.planning import parse_waypoints, solve
from tpm_viz.viserkit.probe import widget_uuid

P = Params.paper()


class TimedClient(ProtocolClient):
    """A protocol client that also timestamps the GUI updates it receives (``(perf_counter, uuid, updates)``)."""

    def __init__(self, port: int) -> None:
        self.updates: list[tuple[float, str, dict]] = []
        self.lock = threading.Lock()
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        if m.get("type") == "GuiUpdateMessage":
            with self.lock:
                self.updates.append((now, m["uuid"], m["updates"]))
        else:
            super().take(m, now)

    def contents_after(self, uuid: str, since: float) -> list[tuple[float, str]]:
        with self.lock:
            return [(t, u["content"]) for t, k, u in self.updates if k == uuid and t >= since and "content" in u]


def _q(html: str, key: str) -> str | None:
    m = re.search(rf"data-q='{key}'>([^<]*)<", html)
    return None if m is None else m.group(1)


def _state(view):
    with view.hub.lock:
        return view.session.state


def _planned(view, force: float, kind: str = "pick"):
    pv = view.teaching.planner
    wait_for(
        lambda: (r := pv.result) is not None and r.kind == kind and r.plan.limits.force == force,
        timeout=20,
        what=f"the {kind} plan at {force} N",
    )
    return pv


def test_the_cycle_time_shown_is_the_library_plan_at_that_limit(connect):
    client, view = connect()
    pv = _planned(view, 200.0)  # planned at connection: pick-and-place, 200 N
    plan = plan_cycle(P, path_for(P, "pick"), Limits(200.0))
    assert _q(pv.result_html.content, "cycle-time") == f"{plan.duration:.3f}"
    assert _q(pv.result_html.content, "per-minute") == f"{60 / plan.duration:.0f}"
    sizing = pv.sizing.content
    assert _q(sizing, "peak-force-0") == f"{pv.result.sizing.peak_force[0]:.1f}"
    assert "cubic law" in sizing and "ABB IRB 360" in pv.industry.content and "150 picks/min" in pv.industry.content
    assert "nan" not in (pv.result_html.content + sizing).lower() and "inf" not in sizing.lower()
    handle = pv.chart.handle
    assert handle.visible and all(np.all(np.isfinite(a)) for a in handle.data)
    assert np.all(handle.data[3] == 200.0) and np.all(handle.data[4] == -200.0)  # ±F_max

    client.set_value(pv.path, "circle (Fig. 5)")
    _planned(view, 200.0, "circle")
    circle = plan_path(P, path_for(P, "circle"), Limits(200.0))  # one turn
    assert _q(pv.result_html.content, "cycle-time") == f"{circle.duration:.3f}"


def _measure(client, pv, base: float) -> tuple[list[float], list[float]]:
    """Latencies [s] of single moves of the force slider and of the last value of three drags."""
    uuid = widget_uuid(pv.result_html)

    def shown(t0: float, want: str) -> list[tuple[float, str]]:
        return [(t, c) for t, c in client.contents_after(uuid, t0) if _q(c, "plan-force") == want]

    single = []
    for force in (base + 150.0, base + 300.0, base + 450.0, base + 50.0):
        t0 = time.perf_counter()
        client.set_value(pv.force, force)
        hit = wait_for(lambda t0=t0, want=f"{force:.0f}": shown(t0, want), what=f"the cycle time at {force} N")
        single.append(hit[0][0] - t0)
        plan = plan_cycle(P, path_for(P, "pick"), Limits(force))
        assert _q(hit[0][1], "cycle-time") == f"{plan.duration:.3f}"  # the library's plan at that limit
    drags = []
    for k in range(3):  # a drag: 15 values 15 ms apart, timed from the last one
        values = [base + 400.0 + 20.0 * j + k for j in range(15)]
        t_last = 0.0
        for value in values:
            t_last = time.perf_counter()
            client.set_value(pv.force, value)
            time.sleep(0.015)
        hit = wait_for(lambda t0=t_last, want=f"{values[-1]:.0f}": shown(t0, want), what="the drag's last value")
        drags.append(hit[0][0] - t_last)
    return single, drags


def test_moving_and_dragging_the_force_limit_shows_the_librarys_cycle_time(app):
    """Every value shown is the library's plan at that limit, and a drag ends on its last value (latest wins). The
    latency (issue 15: within 200 ms) is measured by ``python benchmarks/bench_planner_ui.py``, not here."""
    before = set(app.views)
    client = TimedClient(app.port)
    try:
        view = app.views[next(iter(wait_for(lambda: set(app.views) - before, what="the view")))]
        pv = _planned(view, 200.0)
        single, drags = _measure(client, pv, 0.0)  # asserts the cycle times against plan_cycle
        assert len(single) == 4 and len(drags) == 3
    finally:
        count = len(app.views)
        client.close()
        wait_for(lambda: len(app.views) < count, what="the app to drop the tab")


def test_waypoints_are_planned_and_bad_ones_refused_in_one_line(connect):
    client, view = connect()
    pv = _planned(view, 200.0)
    client.set_value(pv.path, "waypoints")
    wait_for(lambda: pv.waypoints.visible, what="the waypoint field")
    _planned(view, 200.0, "waypoints")
    text = pv.waypoints.value
    expected = solve(P, "waypoints", 200.0, None, text)
    assert _q(pv.result_html.content, "cycle-time") == f"{expected.cycle_time:.3f}"
    np.testing.assert_allclose(parse_waypoints(text)[0], (-0.06, -0.04))
    client.set_value(pv.waypoints, "0,0; 400,0")  # out of reach
    wait_for(lambda: "No plan" in pv.result_html.content, what="the refusal")
    assert "valid region" in pv.result_html.content
    client.set_value(pv.waypoints, "0,0; banana")
    wait_for(lambda: "must be two numbers" in pv.result_html.content, what="the format refusal")


def _shift_click(client, x: float, y: float) -> None:
    """What the browser sends for a Shift+click whose ray hits the floor at (x, y) [m]."""
    origin = (x, y - 0.5, 1.0)
    client.send(
        type="ScenePointerMessage",
        event_type="click",
        ray_origin=origin,
        ray_direction=(0.0, 0.5 / 1.25**0.5, -1.0 / 1.25**0.5),
        screen_pos=((0.5, 0.5),),
        modifier="shift",
    )


def test_shift_clicks_on_the_floor_add_waypoints(connect):
    client, view = connect()
    pv = _planned(view, 200.0)
    client.click(pv.clear)
    wait_for(lambda: pv.path.value == "waypoints" and pv.waypoints.value == "", what="an empty list")
    for x, y in ((-0.05, -0.03), (0.0, 0.04), (0.05, -0.03)):
        _shift_click(client, x, y)
        time.sleep(0.05)
    wait_for(lambda: pv.waypoints.value == "-50,-30; 0,40; 50,-30", what="three clicked waypoints")
    _planned(view, 200.0, "waypoints")
    end = (0.05, -0.03)  # the last click: a plan of all three points (not one of the first two)
    wait_for(lambda: np.allclose(pv.result.plan.paths[0].evaluate(pv.result.plan.paths[0].length), end), what="it")
    expected = solve(P, "waypoints", 200.0, None, "-50,-30; 0,40; 50,-30")
    assert _q(pv.result_html.content, "cycle-time") == f"{expected.cycle_time:.3f}"


def test_shift_clicks_sent_at_once_each_add_their_waypoint(connect):
    """A burst of clicks (a double click, a busy machine): each click's point is added, none is written over."""
    client, view = connect()
    pv = _planned(view, 200.0)
    client.click(pv.clear)
    wait_for(lambda: pv.path.value == "waypoints" and pv.waypoints.value == "", what="an empty list")
    points = [(-0.06 + 0.02 * k, 0.01 * (k % 3)) for k in range(6)]
    for x, y in points:
        _shift_click(client, x, y)
    wait_for(lambda: str(pv.waypoints.value).count(";") == len(points) - 1, what="six waypoints")
    added = sorted(tuple(int(v) for v in item.split(",")) for item in str(pv.waypoints.value).split("; "))
    assert added == sorted((round(x * 1e3), round(y * 1e3)) for x, y in points)


def test_play_moves_the_platform_with_force_bars_at_the_limit(connect):
    client, view = connect()
    pv = _planned(view, 200.0)
    client.set_value(pv.play_speed, "0.5×")
    client.set_value(pv.loop, False)
    wait_for(lambda: pv.play_speed.value == "0.5×" and pv.loop.value is False, what="the settings")
    client.set_value(pv.controls, "Play")
    duration = pv.result.plan.duration
    wait_for(lambda: _state(view).trajectory.kind.startswith("plan#"), what="playing")
    wait_for(lambda: pv._bars is not None and pv._bars.visible, what="the force bars")
    wait_for(lambda: _state(view).trajectory.t == pytest.approx(duration), timeout=10, what="the end of the cycle")
    wait_for(lambda: not pv.player.playing, what="stopped")
    client.set_value(pv.controls, "To start")
    wait_for(lambda: _state(view).trajectory.t == 0.0, what="the start")
    s = pv.result.plan.sample([0.0])
    np.testing.assert_allclose(_state(view).pose.p, s.p[0], atol=1e-12)
    top = float(np.max(pv._bars.points[:, 1, 2]))
    assert top <= pv._ticks.points[0, 0, 2] + 1e-6  # never above the limit tick
