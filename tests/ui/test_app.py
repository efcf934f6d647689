"""Wiring of the app, without a browser: a protocol-level client sends what a browser would send, and the tests
check that each control changes the right state and the right scene and panel handles.
"""

from __future__ import annotations

import io
import itertools
import re
import socket
import threading
import time
from contextlib import redirect_stderr, redirect_stdout

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params, forward_kinematics_both, inverse_kinematics
from tpm_viz.classroom.network import is_loopback
from tpm_viz.ui.app import main
from tpm_viz.ui.scene import COLORS
from tpm_viz.viserkit.probe import share_tunnel

P = Params.paper()


def _state(view):
    """The view's state, read under the hub's lock: once a new state is visible, its render is complete."""
    with view.hub.lock:
        return view.session.state


def _readout(view):
    with view.hub.lock:
        return view.session.readout


def _settle(view, quiet: float = 0.3) -> None:
    """Wait until the view's state has not changed for ``quiet`` seconds (pending events all applied)."""
    last = [_state(view).version, time.monotonic()]

    def still() -> bool:
        version = _state(view).version
        if version != last[0]:
            last[:] = [version, time.monotonic()]
        return time.monotonic() - last[1] > quiet

    wait_for(still, what="the state to settle")


def _dashboard(view) -> str:
    with view.hub.lock:
        return view.panel.dashboard.content


def _q(view, name: str) -> str:
    match = re.search(rf'data-q="{name}"[^>]*>([^<]*)<', _dashboard(view))
    assert match, f"no {name} in the dashboard"
    return match.group(1)


def test_main_prints_one_line_with_the_real_port_and_moves_on_when_busy():
    with socket.socket() as busy:
        busy.bind(("127.0.0.1", 0))
        busy.listen()
        port = busy.getsockname()[1]
        out = io.StringIO()
        with redirect_stdout(out):
            app = main(host="127.0.0.1", port=port, block=False)
        try:
            lines = out.getvalue().splitlines()
            assert lines == [f"tpm-viz serving at http://127.0.0.1:{app.port}"]
            assert app.port != port
        finally:
            app.stop()


def test_loopback_detection_and_warning(monkeypatch):
    assert is_loopback("127.0.0.1") and is_loopback("localhost") and is_loopback("::1")
    assert not is_loopback("0.0.0.0") and not is_loopback("192.168.1.10")
    import tpm_viz.ui.app as app_module

    class Fake:
        def __init__(self, server, **kwargs):
            self.port = 1234

    monkeypatch.setattr(app_module, "build_server", lambda host, port, *more: None)
    monkeypatch.setattr(app_module, "TpmApp", Fake)
    err, out = io.StringIO(), io.StringIO()
    with redirect_stderr(err), redirect_stdout(out):
        main(host="0.0.0.0", port=8080, block=False, addresses=lambda: ["192.0.2.7", "127.0.0.1"])
    assert "warning" in err.getvalue() and "0.0.0.0" in err.getvalue()
    lines = out.getvalue().splitlines()  # any non-loopback host is classroom mode: the URLs students type
    assert lines[0] == "tpm-viz serving at http://127.0.0.1:1234"
    assert [line for line in lines if line.startswith("Students open")] == ["Students open: http://192.0.2.7:1234/"]


def test_share_url_tunnel_is_disabled(app, connect):
    client, view = connect()
    assert app.server.request_share_url() is None
    client.send(type="ShareUrlRequest")
    client.set_value(view.panel.d[0], 150.0)  # a later message: the request above was handled by then
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.15) < 1e-9, what="d1 after the share request")
    assert share_tunnel(app.server) is None


def test_first_render_shows_the_home_pose(connect):
    _client, view = connect()
    assert _q(view, "p1") == "0.0" and _q(view, "d1") == "130.0" and _q(view, "det_jx") == "1.0000"
    np.testing.assert_allclose(view.scene.sliders[0].position, (-P.a + 0.13, 0.0, 0.0))
    assert "nan" not in _dashboard(view).lower() and "inf" not in _dashboard(view).lower()


def test_actuator_slider_drives_forward_kinematics(connect):
    client, view = connect()
    client.set_value(view.panel.d[0], 250.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.25) < 1e-12, what="d1 = 250 mm")
    p = forward_kinematics_both(P, (0.25, 0.13)).plus
    np.testing.assert_allclose(_state(view).pose.p, p)
    np.testing.assert_allclose(view.scene.sliders[0].position, (0.25 - P.a, 0.0, 0.0))
    np.testing.assert_allclose(view.scene.platform.position[:2], p)
    assert _q(view, "d1") == "250.0" and _q(view, "p1") == f"{p[0] * 1e3:.1f}"
    texts = [h.value for h in view.panel.p.inputs.values()]  # the value in use, as the readout shows it (0.1 mm)
    assert texts == [f"{x * 1e3:.1f}" for x in p]


def test_actuator_slider_out_of_range_is_clamped_with_a_reason(connect):
    client, view = connect()
    client.set_value(view.panel.d[1], 7000.0)  # the browser does not range-check
    wait_for(lambda: _state(view).note, what="a clamp note")
    assert _state(view).pose.d[1] == pytest.approx(P.stroke)
    assert "actuator 2" in _q(view, "banner") or "actuator 2" in _dashboard(view)
    assert view.panel.d[1].value == pytest.approx(300.0)


def test_gizmo_drag_moves_every_part_and_clamps_at_the_stroke(connect):
    client, view = connect()
    owner = str(view.client.client_id)
    client.drag(view.scene.gizmo, owner, [(0.02, 0.01, 0.09)], end=False)
    wait_for(lambda: abs(_state(view).pose.p[0] - 0.02) < 1e-12, what="the drag update")
    np.testing.assert_allclose(_state(view).pose.d, inverse_kinematics(P, (0.02, 0.01)))
    np.testing.assert_allclose(view.scene.platform.position[:2], (0.02, 0.01))
    client.drag(view.scene.gizmo, owner, [(0.5, 0.0, 0.09)])
    wait_for(lambda: "stopped" in str(_state(view).note), what="the clamp")
    wait_for(lambda: np.allclose(view.scene.gizmo.position[:2], _state(view).pose.p), what="gizmo written back")
    assert _state(view).pose.d[0] == pytest.approx(P.stroke, abs=1e-5)
    assert "stopped" in str(_state(view).note)


def test_typed_platform_position(connect):
    client, view = connect()
    client.enter(view.panel.p, {"p1": "4e1", "p2": "-30,0"})
    wait_for(lambda: np.allclose(_state(view).pose.p, (0.04, -0.03)), what="p = (40, -30) mm")
    assert _q(view, "p2") == "-30.0"


def test_parameters_apply_rebuilds_and_a_bad_value_is_refused_for_its_tab_only(connect):
    client, view = connect()
    _other_client, other = connect()
    old_links = view.scene.links
    client.set_value(view.panel.params.inputs["l_a"], "280")
    client.set_value(view.panel.params.inputs["stroke"], "3.2e2")
    client.click(view.panel.apply)
    wait_for(lambda: _state(view).params.l_a == pytest.approx(0.28), what="l_a = 280 mm")
    assert _state(view).params.stroke == pytest.approx(0.32)
    assert view.scene.links is not old_links  # geometry re-added once
    assert view.panel.d[0].max == pytest.approx(320.0)
    assert _state(other).params.l_a == pytest.approx(0.28)  # shared by default
    wait_for(lambda: other.panel.params.inputs["l_a"].value == "280", what="the other tab's field")

    good = _state(view)
    note = view.panel.params.note.handle
    client.set_value(view.panel.params.inputs["b"], "-5")
    client.click(view.panel.apply)
    wait_for(lambda: "Refused" in note.content, what="the refusal under the Apply button")
    assert "b must be positive" in note.content and "b: in use 92 mm" in note.content
    assert view.panel.message.content == ""  # not at the top of the panel
    assert other.panel.params.note.handle.content == "" and other.panel.message.content == ""
    assert _state(view) is good
    assert view.panel.params.inputs["b"].value == "-5"  # the field keeps the text, the app the last good value
    client.set_value(view.panel.d[0], 200.0)  # the app keeps working
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.2) < 1e-12, what="d1 after a refusal")
    assert "Refused" in note.content  # another control's success does not clear it
    client.enter(view.panel.params, {"b": "9,2e1"})  # fixed, and Enter
    wait_for(lambda: "Refused" not in note.content, what="the refusal cleared by the next success")
    assert note.content == "" and view.panel.params.inputs["b"].value == "9,2e1"


def test_paper_values_button(connect):
    client, view = connect()
    client.enter(view.panel.params, {"m_p": "5"})
    wait_for(lambda: _state(view).params.m_p == 5.0, what="m_p = 5 kg")
    client.set_value(view.panel.params.inputs["a"], "abc")  # typed, never applied
    client.click(view.panel.paper)
    wait_for(lambda: _state(view).params == P, what="paper values")
    fields = view.panel.params.inputs
    wait_for(lambda: fields["a"].value == "482" and fields["m_p"].value == "2.21", what="the paper's values shown")


@pytest.mark.parametrize(
    ("kind", "check"),
    [
        ("inverse", lambda v: COLORS["inverse"] in [tuple(c) for c in v.scene.links.batched_colors]),
        ("direct", lambda v: tuple(v.scene.platform_body.color) == COLORS["direct"]),
        ("stroke", lambda v: COLORS["stroke"] in [tuple(b.color) for b in v.scene.slider_bodies]),
    ],
)
def test_demo_buttons_warn_and_recolour(connect, kind, check):
    client, view = connect()
    client.click(view.panel.demo[kind])
    wait_for(lambda: kind in {a.kind for a in _readout(view).alerts}, what=f"a {kind} alert")
    assert f'data-level="{kind}"' in _dashboard(view) or kind == "stroke"
    assert check(view)


def test_switch_assembly_mode_and_the_ghost(connect):
    client, view = connect()
    client.set_value(view.panel.d[0], 200.0)
    wait_for(lambda: abs(_state(view).pose.d[0] - 0.2) < 1e-12, what="d1")
    client.set_value(view.panel.d[1], 250.0)
    wait_for(lambda: abs(_state(view).pose.d[1] - 0.25) < 1e-12, what="d2")
    ghost = np.array(view.scene.ghost.position[:2])
    assert view.scene.ghost.visible
    client.click(view.panel.switch_mode)
    wait_for(lambda: _readout(view).mode == -1, what="the other mode")
    np.testing.assert_allclose(_state(view).pose.p, ghost)
    assert "−" in _q(view, "mode")


def test_static_and_dynamic_loads_show_forces_and_the_reference(connect):
    client, view = connect()
    client.enter(view.panel.f_ext, {"f_y": "-2e1"})
    wait_for(lambda: _state(view).load.f_ext == (0.0, -20.0), what="f_ext")
    assert _q(view, "tau2") == "20.00"  # at home J = I: τ = -f_ext
    assert _q(view, "tau2_ref") == "20.00"
    assert view.scene.forces[1].visible
    client.set_value(view.panel.load_mode, "dynamic")
    wait_for(lambda: _state(view).load.mode == "dynamic", what="dynamic mode")
    client.enter(view.panel.ddp, {"p̈1": "10"})
    wait_for(lambda: _state(view).load.ddp == (10.0, 0.0), what="ddp")
    tau1 = float(_q(view, "tau1"))
    assert tau1 > 0 and float(_q(view, "tau1_ref")) == pytest.approx(tau1, abs=0.01)
    assert abs(float(_q(view, "tau1_diff"))) < 1e-6


def test_view_toggles_are_per_tab(connect):
    """The shared mechanism is one broadcast drawing; a tab hides a family by shadowing its nodes with invisible
    nodes of its own scope (checked on the messages each tab receives), and the option survives an own copy."""
    client, view = connect()
    other_client, other = connect()
    labels = set(view.scene.shared.family("labels"))
    assert len(labels) == 7 and all((name, "") in client.nodes for name in labels)  # the broadcast labels
    client.set_value(view.panel.show_toggles["labels"], False)
    wait_for(lambda: client.shadows() == labels, what="this tab's labels shadowed")
    assert view.scene.hidden() == labels
    assert all(label.visible for label in view.scene.shared.labels)  # the shared drawing is untouched
    time.sleep(0.2)
    assert other_client.shadows() == set() and other.scene.hidden() == set()

    client.set_value(view.panel.own_copy, True)  # the copy is drawn with this tab's options
    wait_for(lambda: not view.session.shared, what="own copy")
    wait_for(lambda: client.shadows() == {"/tpm"}, what="the shared mechanism covered in this tab")
    assert view.scene.mechanism.root == "/own" and not any(label.visible for label in view.scene.labels)
    assert ("/own/platform", str(view.client.client_id)) in client.nodes
    client.set_value(view.panel.show_toggles["labels"], True)
    wait_for(lambda: all(label.visible for label in view.scene.labels), what="own labels shown")

    client.set_value(view.panel.own_copy, False)  # back: copy removed, shared drawing shown, no shadow left
    wait_for(lambda: view.session.shared, what="back to shared")
    wait_for(lambda: client.shadows() == set(), what="nothing hidden any more")
    assert not any(name.startswith("/own") for name, _ in client.nodes)


def test_classroom_shared_then_own_copy_then_back(connect):
    c1, v1 = connect()
    c2, v2 = connect()
    c1.set_value(v1.panel.d[0], 180.0)
    wait_for(lambda: abs(_state(v2).pose.d[0] - 0.18) < 1e-12, what="shared change reaches tab 2")
    np.testing.assert_allclose(v2.scene.sliders[0].position, v1.scene.sliders[0].position)
    assert v2.panel.d[0].value == pytest.approx(180.0)

    c2.set_value(v2.panel.own_copy, True)
    wait_for(lambda: not v2.session.shared, what="own copy")
    wait_for(lambda: "You see your own copy" in v2.panel.class_info.content, what="the classroom line")
    assert "1 on the shared mechanism" in v1.panel.class_info.content
    c2.set_value(v2.panel.d[0], 100.0)
    wait_for(lambda: abs(_state(v2).pose.d[0] - 0.1) < 1e-12, what="private change")
    assert _state(v1).pose.d[0] == pytest.approx(0.18)  # the shared mechanism did not move
    c1.set_value(v1.panel.d[1], 200.0)
    wait_for(lambda: abs(_state(v1).pose.d[1] - 0.2) < 1e-12, what="shared change")
    assert _state(v2).pose.d[1] == pytest.approx(0.13)  # the private copy did not follow

    c2.set_value(v2.panel.own_copy, False)
    wait_for(lambda: v2.session.shared, what="back to shared")
    assert _state(v2) is _state(v1)
    assert v2.panel.d[1].value == pytest.approx(200.0)
    wait_for(lambda: "2 on the shared mechanism" in v1.panel.class_info.content, what="the classroom line")


def test_simultaneous_drags_are_serialised_and_never_corrupt_state(app, connect):
    clients = [connect() for _ in range(3)]
    errors: list[BaseException] = []

    def drag(client, view, seed):
        rng = np.random.default_rng(seed)
        try:
            owner = str(view.client.client_id)
            points = [(*rng.uniform(-0.4, 0.4, 2), 0.09) for _ in range(40)]
            client.drag(view.scene.gizmo, owner, points)
        except BaseException as exc:  # pragma: no cover - reported below
            errors.append(exc)

    threads = [threading.Thread(target=drag, args=(c, v, k)) for k, (c, v) in enumerate(clients)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert not errors
    view = clients[0][1]
    _settle(view)
    state = _state(view)
    from tpm_viz.app.moves import check
    from tpm_viz.paper.status import PoseStatus

    assert check(state.params, state.pose) == PoseStatus.REGULAR
    np.testing.assert_allclose(state.pose.d, inverse_kinematics(P, state.pose.p))
    for _, v in clients:
        assert _state(v) is state
        np.testing.assert_allclose(v.scene.platform.position[:2], state.pose.p)
    assert "nan" not in _dashboard(view).lower()


def test_equations_tab_follows_the_state_but_not_every_drag_frame(connect):
    client, view = connect()
    client.enter(view.panel.f_ext, {"f_y": "-2e1"})
    wait_for(
        lambda: _state(view).load.f_ext == (0.0, -20.0) and "Errata" in view.panel.equations.content,
        what="f_ext, and the equations drawn for it",
    )
    assert "(a) Inverse kinematics" in view.panel.equations.content and "Errata" in view.panel.equations.content
    before = view.panel.equations.content
    owner = str(view.client.client_id)
    client.drag(view.scene.gizmo, owner, [(0.03, 0.0, 0.09)], end=False)
    wait_for(lambda: abs(_state(view).pose.p[0] - 0.03) < 1e-12, what="the drag")
    assert view.panel.equations.content == before  # not recomputed for intermediate drag frames
    client.drag(view.scene.gizmo, owner, [(0.03, 0.0, 0.09)])
    wait_for(lambda: view.panel.equations.content != before, what="refresh at the end of the drag")


def test_camera_reframes_after_a_large_geometry_change(connect):
    client, view = connect()
    before = np.array(view.client.camera.position)
    client.enter(view.panel.params, {"l_a": "500", "a": "900"})
    wait_for(lambda: _state(view).params.a == pytest.approx(0.9), what="a = 900 mm")
    wait_for(lambda: not np.allclose(view.client.camera.position, before), what="the camera to move")


def test_a_class_pulling_the_shared_platform_at_once_is_paced_and_the_latest_drag_wins(app, connect, monkeypatch):
    """Seven tabs pulling the shared mechanism at once: drag commits are at least SHARED_DRAG_INTERVAL
    apart (latest value wins in between), the mechanism is drawn once per commit in the broadcast scope whatever
    the number of tabs, every tab shows the same state, and no drag is left stranded."""
    from tpm_viz.classroom import dragging

    tabs = [connect() for _ in range(7)]
    hub = app.hub
    commits: list[tuple[float, float]] = []
    original_commit = hub.commit

    def counting_commit(session, state, origin=None, dragging=False):
        commits.append((time.monotonic(), session.drags.next_at))  # the next drain is not due before next_at
        return original_commit(session, state, origin, dragging)

    monkeypatch.setattr(hub, "commit", counting_commit)
    drawn = []
    original_update = hub.shared.scene.update
    monkeypatch.setattr(hub.shared.scene, "update", lambda frame: drawn.append(frame) or original_update(frame))

    def drag(k, client, view):
        rng = np.random.default_rng(k)
        points = [(*rng.uniform(-0.1, 0.1, 2), 0.09) for _ in range(25)]
        client.drag(view.scene.gizmo, str(view.client.client_id), points)

    threads = [threading.Thread(target=drag, args=(k, c, v)) for k, (c, v) in enumerate(tabs)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    view = tabs[0][1]
    _settle(view, quiet=0.5)
    sends = 25 * len(tabs)
    assert 2 <= len(commits) < sends  # merged: latest value wins
    # each drain sets the earliest time of the next one (its own start + the interval); a commit can start late
    # (the GIL), so the gaps between commits are not checked, the rule is: no commit before the time the last allowed
    # one drain may commit more than once (a tab's drag end is not merged into another tab's move): the commits of
    # one drain share its next_at, and the first commit of each drain is the one that may not come early
    firsts = [c for k, c in enumerate(commits) if k == 0 or c[1] != commits[k - 1][1]]
    for (_, allowed), (began, _) in itertools.pairwise(firsts):
        assert began >= allowed - 1e-3
    for began, due in commits:
        assert due - began <= dragging.SHARED_DRAG_INTERVAL + 1e-9  # next_at = the drain's start + the interval
    assert len({id(f) for f in drawn}) == len(drawn) <= len(commits)  # one broadcast drawing per commit
    assert not hub.shared.drags.scheduled

    client, last = tabs[-1]  # a drag after the storm: applied, shown everywhere, gizmos written back
    client.drag(last.scene.gizmo, str(last.client.client_id), [(0.03, -0.02, 0.09)])
    wait_for(lambda: np.allclose(_state(view).pose.p, (0.03, -0.02)), what="the last drag applied")
    _settle(view)
    state = _state(view)
    np.testing.assert_allclose(hub.shared.scene.platform.position[:2], state.pose.p)
    for _, v in tabs:
        assert _state(v) is state
        wait_for(lambda v=v: np.allclose(v.scene.gizmo.position[:2], state.pose.p), what="every gizmo on the platform")
