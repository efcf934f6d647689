"""*Record clip* and *Download report* in the Player, Control and Planner tabs, without a browser: a protocol-level
client sets its camera and clicks, the downloads viser would send are caught and decoded (frames, size, rate, the
forces drawn, the platform where the tab's camera sees it), the page answers while a clip records, and the bounds
(one clip per tab, the server's slots) refuse with one line."""

from __future__ import annotations

import html.parser
import io
import math

import av
import numpy as np
import pytest
import scipy.ndimage
from PIL import Image

from tests.support.protocol import CAMERA, wait_for
from tpm_viz.core.words import Lang, say
from tpm_viz.drawing.meshes import PLATFORM_Z
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.media.views3d import Camera, View3dRenderer
from tpm_viz.ui.teaching.takeout.buttons import tab_camera
from tpm_viz.ui.teaching.takeout.recording import APP_FRAMES, SCENE_COLOURS, SLOTS, frames_of

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

BLUE, RED = (31, 119, 180), (214, 39, 40)  # the bars of τ1 and τ2 (tpm_viz.media.clips.BAR_COLOURS)


def _catch(view) -> list[tuple[str, bytes]]:
    sent: list[tuple[str, bytes]] = []
    view.client.send_file_download = lambda name, data, **kw: sent.append((name, data))
    return sent


def _refusals(view) -> list[str]:
    """What the tab is told it was refused (English), caught on its way to the panel."""
    told: list[str] = []
    refuse = view.refuse

    def spy(what, *args, **kwargs):
        told.append(say(Lang.EN, what))
        return refuse(what, *args, **kwargs)

    view.refuse = spy
    return told


def _takeout(view, where: str):
    return next(t for t in view.teaching.takeouts if t.where == where)


def _bar(frame: np.ndarray, row: int, colour, zero_x: float, half: float) -> float:
    lo = round(zero_x - half)  # only the bar's own columns: the 3D view may hold a colour like the bar's
    cols = np.flatnonzero(np.abs(frame[row, lo : round(zero_x + half)].astype(int) - np.array(colour)).sum(axis=1) < 90)
    if cols.size == 0:
        return 0.0
    cols = cols + lo
    left, right = cols.min(), cols.max() + 1
    return float(right - zero_x) if abs(right - zero_x) > abs(left - zero_x) else float(left - zero_x)


def _check_bars(frames, clip, size, camera, tol_px: float) -> None:
    renderer = View3dRenderer(clip, "geometry", size, camera, SCENE_COLOURS)
    geometry = renderer.geometry()
    half = renderer.scale * geometry.px_per_newton
    for k in range(0, len(frames), 40):
        for i, colour in enumerate((BLUE, RED)):
            drawn = _bar(frames[k], geometry.rows[i], colour, geometry.zero_x, half) / geometry.px_per_newton
            assert drawn == pytest.approx(clip.tau[k, i], abs=tol_px / geometry.px_per_newton), (k, i)


def _look(client, view, position, look_at, up) -> Camera:
    """Send the camera a browser sends after an orbit (the same canvas: the app does not frame it again)."""
    aspect = CAMERA["image_width"] / CAMERA["image_height"]
    camera = Camera.looking_at(position, look_at, up, CAMERA["fov"], aspect)
    client.send(**{**CAMERA, "position": position, "look_at": look_at, "up_direction": up, "wxyz": camera.wxyz})
    wait_for(lambda: np.allclose(view.client.camera.position, position), what="the tab's camera")
    return camera


def _top_view_pixel(p, camera_xy, height: float, size) -> tuple[float, float]:
    """Where a camera ``height`` [m] over ``camera_xy`` looking straight down (+y up on the screen, the vertical
    field of view of :data:`CAMERA`) sees the platform's top face centre over ``p`` [px], by the pinhole formula."""
    f = size[1] / 2 / math.tan(CAMERA["fov"] / 2)
    depth = height - PLATFORM_Z[1]
    return size[0] / 2 + f * (p[0] - camera_xy[0]) / depth, size[1] / 2 - f * (p[1] - camera_xy[1]) / depth


def _platform(frame: np.ndarray) -> tuple[float, float]:
    """Centre [px] of the box around the platform's top face: the largest patch of its colour (lit from above; the
    sides are darker, anti-aliased text may pass through that colour)."""
    near = np.abs(frame.astype(int) - np.array(PALETTE["platform"])).sum(axis=2) < 40
    patches, count = scipy.ndimage.label(near)
    assert count > 0, "the platform is not in the frame"
    rows, cols = np.nonzero(patches == 1 + np.argmax(np.bincount(patches.ravel())[1:]))
    assert rows.size > 100, "the platform is not in the frame"
    return (cols.min() + cols.max() + 1) / 2, (rows.min() + rows.max() + 1) / 2


class _Numbers(html.parser.HTMLParser):
    def __init__(self, text: str) -> None:
        super().__init__()
        self.values: dict[str, float] = {}
        self.cells: list[float] = []
        self._key = None
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "tr":
            self._key = a.get("data-key")
        if tag == "td" and "data-value" in a:
            self.cells.append(float(a["data-value"]))
            if self._key:
                self.values[self._key] = float(a["data-value"])


def test_player_records_a_gif_through_the_tabs_camera_and_stays_usable(connect):
    client, view = connect()
    client.set_value(view.teaching.player.choice, "line (Fig. 4)")
    wait_for(lambda: view.teaching.services.runs.of(view.session).run is not None, what="the line")
    run = view.teaching.services.runs.of(view.session).run
    take = _takeout(view, "player")
    sent, told = _catch(view), _refusals(view)
    client.set_value(take.size, "640×360")
    client.set_value(take.rate, "10")
    wait_for(lambda: take.size.value == "640×360" and take.rate.value == "10", what="the clip settings")
    over = (0.02, -0.01)  # the tab looks straight down from 0.9 m over this point
    camera = _look(client, view, (*over, 0.9), (*over, 0.0), (0.0, 1.0, 0.0))
    client.click(take.record)
    wait_for(lambda: take.recording is not None and take.recording.done > 0, timeout=60, what="the first frames")
    _look(client, view, (0.3, -0.6, 0.5), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0))  # the view moves: the clip does not
    client.click(take.record)  # one recording per tab
    wait_for(lambda: any("already being recorded" in t for t in told), what="the refusal")
    client.set_value(view.teaching.player.time, 0.1)  # the page answers meanwhile
    wait_for(lambda: abs(view.session.state.trajectory.t - 0.1) < 1e-6, what="the seek during the recording")
    assert take.recording is not None and take.recording.done < take.recording.total
    assert "Recording the clip" in take.line.content
    wait_for(lambda: sent and "Clip ready" in take.line.content, timeout=300, what="the clip and its line")
    name, data = sent[0]
    assert name == "tpm-line-T0.2s-640x360-10fps.gif"
    im = Image.open(io.BytesIO(data))
    assert (im.n_frames, im.size) == (len(run.t), (640, 360)) == (401, (640, 360))
    frames = []
    for k in range(im.n_frames):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB")))
        assert im.info["duration"] == 100
    assert np.abs(frames[0].astype(int) - frames[-1]).sum() > 0
    for k in (0, 200, 400):  # the platform moves along the line, where the tab's camera at the click sees it
        assert _platform(frames[k]) == pytest.approx(_top_view_pixel(run.p[k], over, 0.9, (640, 360)), abs=1.0)
    _check_bars(frames, run, (640, 360), camera, tol_px=1.5)
    assert take.recording is None and SLOTS._value == 3  # the slot came back


def test_control_records_an_mp4_of_the_actual_motion(connect):
    client, view = connect()
    cv = view.teaching.control
    client.click(cv.simulate)
    wait_for(lambda: cv.run is not None and not cv.busy, timeout=30, what="the simulation")
    take = _takeout(view, "control")
    sent = _catch(view)
    client.set_value(take.format, "MP4 (H.264)")
    client.set_value(take.size, "640×360")
    wait_for(lambda: take.format.value == "MP4 (H.264)" and take.size.value == "640×360", what="the settings")
    with view.hub.lock:  # the server points the tab's camera (viser works out its orientation)
        view.client.camera.up_direction = (0.0, 0.0, 1.0)
        view.client.camera.position = (0.25, -0.5, 0.45)
        view.client.camera.look_at = (0.02, 0.03, 0.0)
    camera = tab_camera(view.client)
    mine = Camera.looking_at((0.25, -0.5, 0.45), (0.02, 0.03, 0.0), (0.0, 0.0, 1.0), camera.fov, camera.aspect)
    assert abs(float(np.dot(camera.wxyz, mine.wxyz))) == pytest.approx(1.0, abs=1e-9)  # viser's convention is ours
    client.click(take.record)
    wait_for(lambda: sent, timeout=300, what="the clip")
    name, data = sent[0]
    clip = frames_of(cv.player.motion.params, cv.run.t, cv.run.p, cv.run.tau)
    assert name.startswith("tpm-control-ctc") and name.endswith("-640x360-20fps.mp4")
    with av.open(io.BytesIO(data)) as container:
        stream = container.streams.video[0]
        frames = [f.to_ndarray(format="rgb24") for f in container.decode(stream)]
        assert float(stream.average_rate) == 20.0 and stream.codec_context.name == "h264"
    assert len(frames) == len(clip.t) == min(len(cv.run.t), APP_FRAMES)
    assert frames[0].shape == (360, 640, 3)
    _check_bars(frames, clip, (640, 360), camera, tol_px=3.0)


def test_reports_of_the_player_and_the_planner(connect):
    client, view = connect()
    sent = _catch(view)
    client.set_value(view.teaching.player.choice, "circle (Fig. 5)")
    wait_for(lambda: view.teaching.services.runs.of(view.session).run is not None, what="the circle")
    run = view.teaching.services.runs.of(view.session).run
    client.click(_takeout(view, "player").report)
    wait_for(lambda: sent, timeout=60, what="the player's report")
    name, data = sent[0]
    numbers = _Numbers(data.decode("utf-8"))
    assert name == "tpm-circle-T0.5s-report.html"
    assert numbers.values["peak"] == run.peak and numbers.values["max_diff"] == run.max_diff

    pv = view.teaching.planner
    wait_for(lambda: pv.result is not None, timeout=30, what="the first plan")
    client.click(_takeout(view, "planner").report)
    wait_for(lambda: len(sent) == 2, timeout=60, what="the planner's report")
    text = sent[1][1].decode("utf-8")
    assert "<h2>Planner</h2>" in text
    assert pytest.approx(pv.result.cycle_time, rel=1e-12) in _Numbers(text).cells


def test_nothing_to_record_and_no_free_slot_are_refused_in_one_line(connect):
    client, view = connect()
    take, control, told = _takeout(view, "planner"), _takeout(view, "control"), _refusals(view)
    client.click(control.record)
    wait_for(lambda: any("nothing to record yet" in t for t in told), what="the refusal")
    taken = [SLOTS.acquire(blocking=False) for _ in range(3)]
    try:
        wait_for(lambda: view.teaching.planner.result is not None, timeout=30, what="the first plan")
        client.click(take.record)
        wait_for(lambda: any("recording other clips" in t for t in told), what="the busy refusal")
        assert take.recording is None
    finally:
        for ok in taken:
            if ok:
                SLOTS.release()
