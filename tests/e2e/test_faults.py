"""Faults: a tab that vanishes mid-drag, a callback or a drawing that raises, a parameter change while a trajectory
plays. In each case the server logs what happened, the other tabs keep working and the mechanism stays consistent
(a valid pose for its parameters, the same state object on every tab of the shared session).
"""

from __future__ import annotations

import contextlib
import logging
import socket
import threading
import time

import numpy as np
import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tests.ui.test_client_reliability import assert_valid
from tpm_viz import Params
from tpm_viz.app import transitions
from tpm_viz.classroom.guard import ACTIVITY, guarded

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = Params.paper()


def _state(view):
    with view.hub.lock:
        return view.session.state


def _consistent(*views) -> None:
    with views[0].hub.lock:
        state = views[0].hub.shared.state
        assert_valid(state)
        for v in views:
            if v.session.shared:
                assert v.session.state is state
                np.testing.assert_allclose(v.scene.platform.position[:2], state.pose.p)


def test_tabs_that_disconnect_mid_drag(app, connect, caplog):
    """Twenty tabs each start a drag and vanish before its end (half of them without a closing handshake),
    while another tab keeps dragging."""
    keeper, kv = connect()
    errors = ACTIVITY.snapshot()[1]
    stop = threading.Event()

    def keep_dragging() -> None:
        owner, k = str(kv.client.client_id), 0
        while not stop.is_set():
            angle = k / 10
            keeper.drag(kv.scene.gizmo, owner, [(0.05 * np.cos(angle), 0.05 * np.sin(angle), 0.09)], end=False)
            k += 1
            time.sleep(0.02)

    thread = threading.Thread(target=keep_dragging)
    with caplog.at_level(logging.WARNING, logger="tpm_viz"):
        thread.start()
        try:
            for k in range(20):
                rogue = ProtocolClient(app.port)
                view = wait_for(lambda: next((v for v in list(app.views.values()) if v is not kv), None), what="tab")
                wait_for(lambda view=view: view.session.readout is not None, what="its first render")
                points = [(0.01 * j, -0.01 * j, 0.09) for j in range(1, 6 + k % 5)]
                rogue.drag(view.scene.gizmo, str(view.client.client_id), points, end=False)
                if k % 2:
                    rogue.ws.socket.shutdown(socket.SHUT_RDWR)  # gone mid-drag, no closing handshake
                    rogue.ws.socket.close()
                else:
                    rogue.ws.close()
                wait_for(lambda view=view: view.closed, what="the tab to be dropped")
                with contextlib.suppress(Exception):
                    rogue.close()
        finally:
            stop.set()
            thread.join()
    keeper.drag(kv.scene.gizmo, str(kv.client.client_id), [(0.02, 0.03, 0.09)])
    wait_for(lambda: np.allclose(_state(kv).pose.p, (0.02, 0.03)), what="the keeper's drag end")
    assert ACTIVITY.wait_idle()
    assert ACTIVITY.snapshot()[1] == errors
    server_side = [r for r in caplog.records if r.name != "websockets.client"]  # not the rogue tabs' own library,
    assert not [r for r in server_side if r.levelno >= logging.ERROR]  # which reports the socket the test shut down
    assert list(app.views.values()) == [kv] and app.hub.shared.views == [kv]
    _consistent(kv)


def test_a_tab_that_drags_while_it_is_being_built(app, caplog, monkeypatch):
    """The first tab of a fresh server (viser's client id 0) sends gizmo updates from its first message on, while
    the server is still building its scene and panel (a fast browser, or a reload in the middle of a drag)."""
    join = app.hub.join

    def slow_join(*args, **kwargs):  # widen the window between wiring the gizmo and joining the session
        time.sleep(0.2)
        return join(*args, **kwargs)

    monkeypatch.setattr(app.hub, "join", slow_join)
    errors = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.ERROR, logger="tpm_viz"):
        client = ProtocolClient(app.port)
        k = 0
        while 0 not in app.views or k < 50:  # until the tab is built, and a little longer
            x = 0.03 * np.sin(k / 20)
            client.send(
                type="TransformControlsUpdateMessage",
                name="/gizmo",
                wxyz=(1.0, 0.0, 0.0, 0.0),
                position=(float(x), 0.0, 0.09),
                owner="0",
            )
            k += 1
            time.sleep(0.0005)
            assert k < 20_000, "the tab was never built"
        view = app.views[0]
        client.drag(view.scene.gizmo, "0", [(0.02, 0.01, 0.09)])
        wait_for(lambda: np.allclose(_state(view).pose.p, (0.02, 0.01)), what="the drag after the build")
    assert ACTIVITY.wait_idle() and ACTIVITY.snapshot()[1] == errors, caplog.text
    _consistent(view)
    client.close()
    wait_for(lambda: not app.views, what="the tab to leave")


def test_a_callback_that_raises_is_logged_told_and_survived(app, connect, monkeypatch, caplog):
    client, view = connect()
    other_client, other = connect()
    before = _state(view)

    def boom(state):
        raise RuntimeError("boom in a callback")

    monkeypatch.setattr(transitions, "switch", boom)
    with caplog.at_level(logging.ERROR, logger="tpm_viz.ui"):
        client.click(view.panel.switch_mode)
        wait_for(lambda: "internal error (RuntimeError)" in view.panel.message.content, what="the report")
    assert "boom in a callback" in caplog.text and "Traceback" in caplog.text  # logged with its traceback
    assert _state(view) is before and other.panel.message.content == ""
    other_client.set_value(other.panel.d[0], 190.0)  # the lock was released: others keep working
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.19) < 1e-9, what="another tab's change")
    _consistent(view, other)


def test_a_callback_registered_without_the_guard_is_still_logged(app, connect, caplog):
    """The safety net: viser's callback pool is guarded as a whole (``guard.guard_executor``)."""
    client, view = connect()
    button = view.client.gui.add_button("unguarded")
    button.on_click(lambda event: 1 / 0)  # e.g. a new feature that forgot @guarded
    errors = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.ERROR, logger="tpm_viz.ui"):
        client.click(button)
        wait_for(lambda: ACTIVITY.snapshot()[1] == errors + 1, what="the counted failure")
        wait_for(lambda: "ZeroDivisionError" in caplog.text, what="the logged failure")
    assert "Traceback" in caplog.text
    client.set_value(view.panel.d[0], 175.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.175) < 1e-9, what="the app to keep working")


def test_a_drag_whose_update_raises_is_survived(app, connect, monkeypatch, caplog):
    client, view = connect()
    owner = str(view.client.client_id)
    calls = {"n": 0}
    real = transitions.drag

    def flaky(state, position):
        calls["n"] += 1
        if calls["n"] == 1:
            raise ZeroDivisionError("flaky drag")
        return real(state, position)

    monkeypatch.setattr(transitions, "drag", flaky)
    with caplog.at_level(logging.ERROR, logger="tpm_viz.ui"):
        client.drag(view.scene.gizmo, owner, [(0.01, 0.0, 0.09)], end=False)
        wait_for(lambda: "flaky drag" in caplog.text, what="the logged failure")
        time.sleep(0.05)
        client.drag(view.scene.gizmo, owner, [(0.03, 0.01, 0.09)])
        wait_for(lambda: np.allclose(_state(view).pose.p, (0.03, 0.01)), what="the next drag")
    _consistent(view)


def test_a_tab_whose_drawing_raises_does_not_stop_the_others(app, connect, caplog):
    client, view = connect()
    _b, broken = connect()
    _c, third = connect()

    def fail(*_args, **_kwargs):
        raise OSError("this tab's socket broke")

    broken.panel.show = fail  # e.g. a connection that died while its panel was being written
    with caplog.at_level(logging.ERROR, logger="tpm_viz.ui"):
        client.set_value(view.panel.d[0], 210.0)
        wait_for(lambda: abs(third.session.state.pose.d[0] - 0.21) < 1e-9, what="the change")
        wait_for(lambda: "this tab's socket broke" in caplog.text, what="the logged failure")
    np.testing.assert_allclose(third.scene.sliders[0].position[0], 0.21 - P.a)  # drawn after the broken tab
    _consistent(view, third)
    assert broken.session.state is view.session.state  # one state for all; only the drawing failed


def test_guarded_async_and_sync_wrappers():
    seen = []

    class Owner:
        @guarded(on_error=lambda self, exc: seen.append(type(exc).__name__))
        def sync(self, x):
            return 1 / x

        @guarded(on_error=lambda self, exc: 1 / 0)  # the error report itself fails: logged, not raised
        async def coro(self, x):
            return 1 / x

    import asyncio

    owner = Owner()
    calls, errors, _ = ACTIVITY.snapshot()
    assert owner.sync(2) == 0.5 and owner.sync(0) is None and seen == ["ZeroDivisionError"]
    assert asyncio.run(owner.coro(4)) == 0.25 and asyncio.run(owner.coro(0)) is None
    after = ACTIVITY.snapshot()
    assert after[0] == calls + 4 and after[1] == errors + 3 and after[2] == 0


def _player(view):
    with view.hub.lock:
        return view.teaching.services.runs.of(view.session)


def _worker_idle(view) -> bool:
    return view.teaching.services.runs.worker.idle()


@pytest.mark.parametrize(
    ("changes", "unreachable"),
    [({"l_a": 280.0}, False), ({"stroke": 150.0, "a": 400.0}, True)],
    ids=["still-reachable", "circle-now-unreachable"],
)
def test_a_parameter_change_during_playback(app, connect, capfd, changes, unreachable):
    """The paper's circle plays on the shared mechanism; another tab applies new parameters in the middle."""
    c1, v1 = connect()
    c2, v2 = connect()
    errors = ACTIVITY.snapshot()[1]
    player = v1.teaching.player
    c1.set_value(player.choice, "circle (Fig. 5)")
    wait_for(lambda: (run := _player(v1).run) is not None and run.source.kind == "circle", what="the circle run")
    c1.set_value(player.speed, "0.05×")  # T = 0.5 s lasts 10 s
    time.sleep(0.06)
    c1.set_value(player.controls, "Play")
    wait_for(lambda: _player(v1).playing and _state(v1).trajectory.t > 0.01, what="playback under way")

    c2.enter(v2.panel.params, {name: f"{value:g}" for name, value in changes.items()})
    wait_for(lambda: _state(v1).params.l_a == pytest.approx(changes.get("l_a", 260.0) / 1e3), what="the change")
    wait_for(lambda: _state(v1).params.stroke == pytest.approx(changes.get("stroke", 300.0) / 1e3), what="stroke")
    wait_for(lambda: not _player(v1).playing, what="the playback to stop")
    wait_for(lambda: _worker_idle(v1), what="the run to be recomputed for the new mechanism")
    ps = _player(v1)
    if unreachable:
        assert ps.run is None and "unloaded" in str(ps.status)  # told, not crashed
    else:
        assert ps.run is not None and ps.run.params == _state(v1).params
    t_stopped = _state(v1).trajectory.t
    time.sleep(0.3)
    assert _state(v1).trajectory.t == t_stopped  # no playback thread left behind
    _consistent(v1, v2)

    c1.set_value(player.controls, "Play")  # playing again: on the new run, or refused with a message
    if unreachable:
        note = player.note.handle  # under the player's controls
        wait_for(lambda: "load a trajectory first" in note.content, what="the refusal")
    else:
        wait_for(lambda: _player(v1).playing, what="playback on the new mechanism")
        c1.set_value(player.controls, "Pause")
        wait_for(lambda: not _player(v1).playing, what="the pause")
    c2.set_value(v2.panel.d[0], 150.0)  # both tabs keep working
    wait_for(lambda: abs(_state(v1).pose.d[0] - 0.15) < 1e-9 or _state(v1).note, what="a later change")
    _consistent(v1, v2)
    assert ACTIVITY.wait_idle() and ACTIVITY.snapshot()[1] == errors
    captured = capfd.readouterr()
    assert "Traceback" not in captured.err and "Traceback" not in captured.out


def test_a_background_thread_that_dies_is_logged(monkeypatch, caplog):
    """``main()`` routes uncaught exceptions of threads (playback, worker) to the app's log and counts them."""
    from tpm_viz.ui.app import _thread_died

    monkeypatch.setattr(threading, "excepthook", _thread_died)
    errors = ACTIVITY.snapshot()[1]
    with caplog.at_level(logging.ERROR, logger="tpm_viz.ui"):
        thread = threading.Thread(target=lambda: 1 / 0, name="tpm-viz-play")
        thread.start()
        thread.join()
    assert ACTIVITY.snapshot()[1] == errors + 1
    assert "thread tpm-viz-play failed: ZeroDivisionError" in caplog.text and "Traceback" in caplog.text


def test_a_bug_in_a_background_job_is_logged_and_the_worker_carries_on(caplog):
    """The worker (maps, trajectory runs) logs a job's bug with its traceback through the guard and keeps going."""
    from tpm_viz.classroom.guard import ACTIVITY
    from tpm_viz.classroom.worker import Worker

    worker, results = Worker(), []
    errors_before = ACTIVITY.snapshot()[1]
    with caplog.at_level("ERROR", logger="tpm_viz"):
        worker.submit("bad", lambda: 1 / 0, lambda result, error: results.append(("bad", result, error)))
        worker.submit("good", lambda: 42, lambda result, error: results.append(("good", result, error)))
        wait_for(lambda: len(results) == 2 and worker.idle(), what="both jobs done")
    assert isinstance(results[0][2], ZeroDivisionError) and results[1] == ("good", 42, None)
    assert ACTIVITY.snapshot()[1] == errors_before + 1
    assert any("background job failed: ZeroDivisionError" in r.getMessage() and r.exc_info for r in caplog.records)
