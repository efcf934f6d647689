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
from conftest import ProtocolClient, wait_for
from test_reliability_app import assert_valid

from tpm_viz import Params
from tpm_viz.ui import transitions
from tpm_viz.ui.guard import ACTIVITY, guarded

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
    assert not [r for r in caplog.records if r.levelno >= logging.ERROR]
    assert list(app.views.values()) == [kv] and app.hub.shared.views == [kv]
    _consistent(kv)


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


@pytest.mark.skip(reason="pending: the trajectory player (issue 5) is being rewired; see test_faults in bench")
def test_parameter_change_during_playback():  # pragma: no cover - replaced once the player lands
    pass
