"""Wiring of the singularity explorer, without a browser: the floor map arrives from the background worker
(never inside a callback), follows parameter changes, and a slow map never stalls another tab's drag."""

from __future__ import annotations

import time

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.ui.teaching import explorer as explorer_module
from tpm_viz.viserkit.probe import image_bytes

P = Params.paper()


def _image(view):
    ex = view.teaching.explorer
    return ex._image if ex._image is not None and ex._image.visible else None


def _region_shown(view, client) -> bool | None:
    """Whether this tab shows the shared workspace floor (not shadowed), once the server's account and the messages
    the tab received agree; None while they differ (the message that shadows or unshadows it is on its way: poll
    with ``wait_for`` until the state wanted, never assert on one read)."""
    name = view.scene.shared.family("region")[0]
    hidden = name in view.scene.hidden()
    if hidden != (name in client.shadows()):
        return None
    return view.scene.shared.region.visible and not hidden


def test_a_map_is_drawn_on_the_floor_and_replaces_the_plain_workspace(connect):
    client, view = connect()
    other_client, other = connect()
    ex = view.teaching.explorer
    wait_for(lambda: _region_shown(view, client) is True, what="the floor shown in the new tab")
    assert _image(view) is None
    client.set_value(ex.map_kind, MAP_KINDS["det_jx"])
    wait_for(lambda: _image(view) is not None, what="the map image")
    image = _image(view)
    assert image_bytes(image)[:4] == b"\x89PNG" and image.render_width == pytest.approx(2 * P.l_a * 200 / 199)
    assert tuple(image.position) == pytest.approx((0.0, 0.0, explorer_module.MAP_Z))
    wait_for(lambda: _region_shown(view, client) is False, what="the floor hidden in this tab")
    assert _region_shown(other, other_client) is True  # only in this tab (nothing on its way to the other tab)
    assert "det J_x" in ex.legend.content and "nan" not in ex.legend.content.lower()
    client.set_value(ex.map_kind, MAP_KINDS["off"])
    wait_for(lambda: _image(view) is None, what="the map hidden")
    wait_for(lambda: _region_shown(view, client) is True, what="the floor back")
    client.set_value(ex.map_kind, MAP_KINDS["det_jx"])  # an own copy keeps the floor hidden under the map
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: view.scene.private is not None and not view.scene.private.region.visible, what="own floor hidden")


def test_a_parameter_change_regenerates_the_map_once_for_all_tabs(connect, monkeypatch):
    client, view = connect()
    _other_client, other = connect()
    service = view.teaching.services.maps
    assert other.teaching.services.maps is service
    computed = []
    original = service._compute
    monkeypatch.setattr(service, "_compute", lambda params: computed.append(params) or original(params))
    for tab, c in ((view, client), (other, _other_client)):
        c.set_value(tab.teaching.explorer.map_kind, MAP_KINDS["workspace"])
    wait_for(lambda: _image(view) is not None and _image(other) is not None, what="both maps")
    client.enter(view.panel.params, {"l_a": "220"})
    wait_for(
        lambda: all(
            _image(v) is not None and v.teaching.explorer._image_key[0].l_a == pytest.approx(0.22)
            for v in (view, other)
        ),
        what="the new map in both tabs",
    )
    assert _image(view).render_width == pytest.approx(0.44 * 200 / 199)
    assert sum(1 for p in computed if p.l_a == pytest.approx(0.22)) == 1  # computed once, shown twice


def test_a_slow_map_does_not_stall_another_tabs_drag(connect, monkeypatch):
    client, view = connect()
    other_client, other = connect()
    real = explorer_module.cached_map

    def slow(params, n):
        time.sleep(1.5)
        return real(params, n)

    monkeypatch.setattr(explorer_module, "cached_map", slow)
    client.set_value(view.teaching.explorer.map_kind, MAP_KINDS["cond"])
    wait_for(lambda: "Computing" in view.teaching.explorer.status.content, what="the map being computed")
    t0 = time.monotonic()
    other_client.enter(other.panel.p, {"p1": "30", "p2": "20"})  # a move from another tab meanwhile
    wait_for(lambda: np.allclose(other.session.state.pose.p, (0.03, 0.02)), what="the other tab's move")
    assert time.monotonic() - t0 < 0.7  # not behind the 1.5 s map
    wait_for(lambda: _image(view) is not None, timeout=10, what="the slow map, eventually")


def test_the_ellipses_follow_the_platform_and_say_their_axes(connect):
    client, view = connect()
    ex = view.teaching.explorer
    client.set_value(ex.ellipses, True)
    wait_for(lambda: "velocity ellipse" in ex.readout.content, what="the ellipse readout")
    vel = ex._ellipses["velocity"]
    assert vel.visible and vel.name.startswith("/explorer/")  # this tab's own scope, world coordinates
    r = np.linalg.norm(vel.points[:, 0, :2], axis=1)
    assert r == pytest.approx(np.full(len(r), explorer_module.ELLIPSE_SCALE), rel=1e-6)  # J = I at home
    client.enter(view.panel.p, {"p1": "-170", "p2": "-170"})  # towards the direct singularity
    wait_for(lambda: np.allclose(view.session.state.pose.p, (-0.17, -0.17)), what="the move")
    p = np.array([-0.17, -0.17])
    wait_for(lambda: np.allclose(vel.points[:, 0, :2].mean(axis=0), p, atol=1e-6), what="the ellipse at the platform")
    assert np.ptp(np.linalg.norm(vel.points[:, 0, :2] - p, axis=1)) > 0.1  # stretched near the singularity
    assert vel.points[:, 0, :2].mean(axis=0) == pytest.approx(p, abs=1e-6)  # centred on the platform
    assert "nan" not in ex.readout.content.lower()
    client.set_value(ex.ellipses, False)
    wait_for(lambda: not vel.visible and ex.readout.content == "", what="ellipses hidden, and their readout")
    assert ex.readout.content == ""


def test_a_map_that_cannot_be_computed_is_reported_not_retried(connect, monkeypatch):
    from tpm_viz import InputError

    client, view = connect()
    service = view.teaching.services.maps
    calls = []

    def broken(params):
        calls.append(params)
        raise InputError("grid too coarse")

    monkeypatch.setattr(service, "_compute", broken)
    client.set_value(view.teaching.explorer.map_kind, MAP_KINDS["cond"])
    wait_for(lambda: "Map unavailable: grid too coarse" in view.teaching.explorer.status.content, what="the report")
    client.enter(view.panel.p, {"p1": "10", "p2": "0"})  # more frames: no second attempt for the same parameters
    wait_for(lambda: np.allclose(view.session.state.pose.p, (0.01, 0.0)), what="a move")
    assert len(calls) == 1 and _image(view) is None
