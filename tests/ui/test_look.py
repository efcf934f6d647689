"""Presentation mode and the camera framed for a tab's canvas (:mod:`tpm_viz.ui.look`), through viser's protocol:
what a tab is sent, and where its camera is put, checked with a pinhole camera written here.
"""

from __future__ import annotations

import math
import time

import numpy as np
import pytest
import viser
import viser.transforms as tf

from tests.support.protocol import CAMERA, ProtocolClient, wait_for
from tpm_viz.drawing import meshes


def _fractions(camera, points) -> np.ndarray:
    """Canvas fractions (x from the left, y from the top) of world points [m] in a viser camera (OpenCV axes)."""
    rot = tf.SO3(np.asarray(camera.wxyz)).as_matrix()
    xc = (np.asarray(points, dtype=float) - np.asarray(camera.position)) @ rot
    assert np.all(xc[:, 2] > 0)
    focal = 0.5 / math.tan(camera.fov / 2)
    aspect = camera.image_width / camera.image_height
    return np.stack([0.5 + focal * xc[:, 0] / xc[:, 2] / aspect, 0.5 + focal * xc[:, 1] / xc[:, 2]], axis=1)


def _corners(params) -> np.ndarray:
    lo, hi = meshes.base_extent(params)
    return np.array([[x, y, z] for x in (lo, hi) for y in (lo, hi) for z in (-0.012, meshes.PIN_Z[1])])


def _camera(width: int, height: int, position=(0.0, -1.0, 1.0), look_at=(0.0, 0.0, 0.0)) -> dict:
    """A camera message of a canvas ``width`` x ``height`` device pixels looking from ``position``."""
    z = np.asarray(look_at, float) - np.asarray(position, float)
    z /= np.linalg.norm(z)
    x = np.cross(z, (0.0, 0.0, 1.0))
    x /= np.linalg.norm(x)
    rot = np.stack([x, np.cross(z, x), z], axis=1)
    wxyz = tf.SO3.from_matrix(rot).wxyz
    return {
        **CAMERA,
        "image_width": width,
        "image_height": height,
        "position": tuple(position),
        "look_at": tuple(look_at),
        "wxyz": tuple(float(v) for v in wxyz),
    }


def _fills_the_canvas(view) -> bool:
    uv = _fractions(view.client.camera, _corners(view.session.state.params))
    inside = uv.min() >= 0.0 and uv.max() <= 1.0
    return bool(inside and (uv[:, 0].max() - uv[:, 0].min() > 0.85 or uv[:, 1].max() - uv[:, 1].min() > 0.85))


def test_the_camera_is_framed_for_the_canvas_when_its_aspect_changes_not_when_the_viewer_orbits(connect):
    client, view = connect()
    wait_for(lambda: _fills_the_canvas(view), what="the first framing, for the 1280 x 720 canvas")
    client.send(**_camera(390, 464))  # a phone held upright: the canvas above the sheet
    wait_for(lambda: view.client.camera.image_width == 390, what="the new canvas size on the server")
    wait_for(lambda: _fills_the_canvas(view), what="the framing for the upright canvas")
    framed = np.array(view.client.camera.position)
    assert not np.allclose(framed, CAMERA["position"])

    orbit = (0.4, -0.9, 0.7)  # the viewer orbits: same canvas, another pose, kept
    client.send(**_camera(390, 464, position=orbit))
    wait_for(lambda: np.allclose(view.client.camera.position, orbit), what="the orbit received")
    time.sleep(0.5)
    assert np.allclose(view.client.camera.position, orbit)

    client.send(**_camera(391, 464, position=orbit))  # a pixel of rounding: no new framing
    time.sleep(0.5)
    assert np.allclose(view.client.camera.position, orbit)


def _own(client, view) -> dict[str, dict]:
    """The scene nodes this tab was sent in its own scope, by name."""
    owner = str(view.client.client_id)
    return {name: node for (name, who), node in client.nodes.items() if who == owner}


def test_presentation_mode_styles_this_tabs_lines_and_labels_only(connect):
    client, view = connect()
    other_client, other = connect()
    shared = view.scene.shared
    lines = {h.name: h for h in shared.styled() if isinstance(h, viser.LineSegmentsHandle)}
    labels = {h.name: h for h in shared.styled() if isinstance(h, viser.LabelHandle)}
    assert set(lines) >= {"/tpm/loci/inverse", "/tpm/loci/direct", "/tpm/slider1/circle", "/tpm/slider2/circle"}
    assert len(labels) == 7

    client.set_value(view.panel.presentation, True)
    wait_for(lambda: set(lines) | set(labels) <= set(_own(client, view)), what="this tab's styled copies")
    copies = view.scene._styled
    for name, handle in lines.items():
        assert copies[name].thickness == pytest.approx(2.0 * handle.thickness) and copies[name].thickness >= 4.0
        np.testing.assert_array_equal(copies[name].points, handle.points)
    for name, handle in labels.items():
        assert copies[name].font_screen_scale >= 1.5 and copies[name].text == handle.text
    assert all(h.thickness < 3.0 for h in lines.values())  # the broadcast drawing is untouched
    assert view.look.style.content.count("<style>") == 2  # the phone sheet, and presentation's type sizes
    time.sleep(0.2)
    assert not (set(lines) | set(labels)) & set(_own(other_client, other)) and not other.look.presentation

    client.set_value(view.panel.show_toggles["labels"], False)  # hidden wins over styled
    wait_for(lambda: client.shadows() == set(labels), what="the labels hidden in this tab")
    assert not set(labels) & set(view.scene._styled)
    client.set_value(view.panel.show_toggles["labels"], True)
    wait_for(lambda: set(labels) <= set(view.scene._styled), what="the labels styled again")

    client.enter(view.panel.params, {"l_a": "280"})  # the shared drawing is rebuilt: its copies too
    wait_for(lambda: view.session.state.params.l_a == pytest.approx(0.28), what="l_a = 280 mm")

    def copied_again() -> bool:
        with view.hub.lock:  # the shared drawing and its copies are rebuilt under the lock: read them whole
            c = view.scene._styled.get("/tpm/loci/direct")
            return c is not None and bool(shared.loci) and np.array_equal(c.points, shared.loci[-1].points)

    wait_for(copied_again, what="the direct locus copied again for the new links")

    client.set_value(view.panel.own_copy, True)  # a private copy is styled in place, no copy left over the shared
    wait_for(lambda: view.scene.private is not None, what="own copy")
    private = view.scene.private

    def widths() -> list[float]:
        with view.hub.lock:  # not in the middle of a change
            return [h.thickness for h in private.styled() if isinstance(h, viser.LineSegmentsHandle)]

    wait_for(lambda: min(widths()) >= 4.0, what="the private copy's lines thicker")
    assert view.scene._styled == {}

    client.set_value(view.panel.presentation, False)
    wait_for(lambda: not view.look.presentation, what="presentation mode off")
    wait_for(lambda: max(widths()) < 3.0, what="the private copy's lines back to normal")
    assert view.look.style.content.count("<style>") == 1
    client.set_value(view.panel.own_copy, False)
    wait_for(lambda: view.scene.private is None, what="back to the shared mechanism")
    assert view.scene._styled == {}
    wait_for(lambda: client.shadows() == set(), what="nothing over the shared drawing in this tab")


class _Page(ProtocolClient):
    """A page whose canvas was resized by the panel without telling the server (viser's page reports a resize with
    the drawing buffer's old size): it answers a field-of-view write with its camera at the canvas's real size."""

    def __init__(self, port: int) -> None:
        self.canvas = (1280, 720)
        self.fov_writes = 0
        self.pose = {"position": CAMERA["position"], "look_at": CAMERA["look_at"]}
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        super().take(m, now)
        kind = m.get("type")
        if kind == "SetCameraPositionMessage" and not m.get("initial", False):
            self.pose = {**self.pose, "position": tuple(m["position"])}
        elif kind == "SetCameraLookAtMessage" and not m.get("initial", False):
            self.pose = {**self.pose, "look_at": tuple(m["look_at"])}
        elif kind == "SetCameraFovMessage" and not m.get("initial", False):
            self.fov_writes += 1
            self.send(**{**_camera(*self.canvas, **self.pose), "fov": float(m["fov"])})


def test_after_presentation_mode_the_tab_is_asked_for_its_canvas_and_framed_for_its_real_size(app):
    before = set(app.views)
    page = _Page(app.port)
    try:
        new = wait_for(lambda: set(app.views) - before, what="the app to build a view for the page")
        view = app.views[next(iter(new))]
        wait_for(lambda: _fills_the_canvas(view), what="the first framing, for the 1280 x 720 canvas")
        page.canvas = (1004, 720)  # the wider panel took 276 device pixels: the page does not say so by itself
        page.set_value(view.panel.presentation, True)
        wait_for(lambda: page.fov_writes >= 1, what="the server asking the page for its camera again")
        wait_for(lambda: view.client.camera.image_width == 1004, what="the real canvas size on the server")

        def in_view() -> bool:  # the whole mechanism on the real canvas (presentation mode keeps a band free below)
            uv = _fractions(view.client.camera, _corners(view.session.state.params))
            return bool(uv.min() >= 0.0 and uv.max() <= 1.0 and np.ptp(uv, axis=0).max() > 0.6)

        wait_for(in_view, what="the framing for the canvas beside the wider panel")
        assert abs(view.client.camera.fov - CAMERA["fov"]) < 1e-4 * CAMERA["fov"]  # the question shows nothing
    finally:
        page.close()
