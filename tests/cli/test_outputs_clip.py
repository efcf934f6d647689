"""``tpm-viz clip``: the GIF and the MP4 decoded back (frames, size, rate, motion), the forces drawn in each frame
measured in pixels and compared with ``tpm-viz trajectory``'s forces at the same times, byte-identical reruns, and
one-line refusals. The clip of the docs (docs/images/clip.gif, shown by docs/media.md) is made by :data:`DOCS_CLIP`, run
here, the command the page states."""

from __future__ import annotations

import csv
import io
import json
import pathlib
import re

import av
import numpy as np
import pytest
from PIL import Image

from tests.support import cli
from tpm_viz.cli import main

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

ROOT = pathlib.Path(__file__).resolve().parents[2]
DOCS_CLIP = [
    "clip", "--trajectory", "circle", "--samples", "101", "--fps", "20", "--size", "640x360",
    "--output", str(ROOT / "docs" / "images" / "clip.gif"),
]  # fmt: skip
"""The command that makes the clip of docs/media.md (the circle of Fig. 5, 101 frames, 5 s at 20 frames/s)."""
BLUE, RED = (31, 119, 180), (214, 39, 40)  # tpm_viz.media.clips.BAR_COLOURS, written out: the test reads pixels


def trajectory_forces(kind: str, samples: int, capsys) -> tuple[np.ndarray, np.ndarray]:
    """``(t, tau)`` of ``tpm-viz trajectory`` (the closed form on the command line, not the app's runs)."""
    assert main(["trajectory", "--kind", kind, "--samples", str(samples)]) == 0
    rows = list(csv.DictReader(io.StringIO(capsys.readouterr().out)))
    t = np.array([float(r["t"]) for r in rows])
    return t, np.array([[float(r["tau1"]), float(r["tau2"])] for r in rows])


def clip(tmp_path: pathlib.Path, name: str, *extra: str) -> tuple[bytes, dict]:
    out, side = tmp_path / name, tmp_path / (name + ".json")
    assert main(["clip", "--output", str(out), "--sidecar", str(side), *extra]) == 0
    return out.read_bytes(), json.loads(side.read_text())


def gif_frames(data: bytes) -> tuple[list[np.ndarray], list[int]]:
    im = Image.open(io.BytesIO(data))
    frames, delays = [], []
    for k in range(im.n_frames):
        im.seek(k)
        frames.append(np.asarray(im.convert("RGB")))
        delays.append(im.info["duration"])
    return frames, delays


def mp4_frames(data: bytes) -> tuple[list[np.ndarray], float, str]:
    with av.open(io.BytesIO(data)) as container:
        stream = container.streams.video[0]
        frames = [f.to_ndarray(format="rgb24") for f in container.decode(stream)]
        return frames, float(stream.average_rate), stream.codec_context.name


def bar_length(frame: np.ndarray, row: int, colour, zero_x: float) -> float:
    """Signed length [px] of the bar of ``colour`` on ``row``, measured from the frame's pixels."""
    dist = np.abs(frame[row].astype(int) - np.array(colour)).sum(axis=1)
    cols = np.flatnonzero(dist < 90)
    if cols.size == 0:
        return 0.0
    left, right = cols.min(), cols.max() + 1
    return float(right - zero_x) if abs(right - zero_x) > abs(left - zero_x) else float(left - zero_x)


def check_forces(frames, side: dict, t_ref, tau_ref, tol_px: float) -> None:
    bars = side["bars"]
    scale = bars["px_per_newton"]
    for k in range(0, len(frames), 7):
        for i, colour in enumerate((BLUE, RED)):
            drawn = bar_length(frames[k], bars["rows"][i], colour, bars["zero_x"]) / scale
            assert drawn == pytest.approx(tau_ref[k, i], abs=tol_px / scale), (k, i)
    for k, (clock, *values) in enumerate(side["texts"]):  # the numbers printed in the frame
        assert float(re.search(r"t = ([-0-9.]+) s", clock).group(1)) == pytest.approx(t_ref[k], abs=1e-4)
        for i, text in enumerate(values):
            assert float(re.search(r"= ([-+0-9.]+) N", text).group(1)) == pytest.approx(tau_ref[k, i], abs=0.006)


def test_gif_of_the_line_decoded_back(tmp_path, capsys):
    data, side = clip(tmp_path, "line.gif", "--trajectory", "line", "--samples", "41", "--fps", "10")
    frames, delays = gif_frames(data)
    t_ref, tau_ref = trajectory_forces("line", 41, capsys)
    assert len(frames) == 41 == side["frames"]
    assert frames[0].shape == (450, 800, 3)
    assert set(delays) == {100}  # 10 frames/s
    assert np.abs(frames[0].astype(int) - frames[-1]).sum(axis=2).astype(bool).sum() > 2000  # the platform moved
    check_forces(frames, side, t_ref, tau_ref, tol_px=1.5)


def test_mp4_of_the_circle_decoded_back(tmp_path, capsys):
    data, side = clip(
        tmp_path, "circle.mp4", "--trajectory", "circle", "--samples", "51", "--fps", "25", "--size", "640x360"
    )
    frames, rate, codec = mp4_frames(data)
    t_ref, tau_ref = trajectory_forces("circle", 51, capsys)
    assert codec == "h264" and rate == 25.0
    assert len(frames) == 51 and frames[0].shape == (360, 640, 3)
    assert np.abs(frames[0].astype(int) - frames[-1]).sum(axis=2).max() > 200
    check_forces(frames, side, t_ref, tau_ref, tol_px=3.0)


@pytest.mark.end_to_end
@pytest.mark.parametrize("name", ["a.gif", "a.mp4"])
def test_the_same_inputs_give_the_same_bytes(tmp_path, name):
    """The installed command in a child process and the command in this one (two processes: hash seeds, caches and
    threads of their own) write the same bytes."""
    argv = ["clip", "--trajectory", "line", "--samples", "16", "--size", "320x180", "--set", "l_a=0.27"]
    done = cli.run_installed(*argv, "--output", str(tmp_path / ("1" + name)))
    assert done.returncode == 0, done.stderr
    assert main([*argv, "--output", str(tmp_path / ("2" + name))]) == 0
    assert (tmp_path / ("1" + name)).read_bytes() == (tmp_path / ("2" + name)).read_bytes()


def test_a_clip_of_your_own_csv(tmp_path, capsys):
    t = np.linspace(0.0, 0.4, 9)
    path = tmp_path / "path.csv"
    path.write_text("t,p1,p2\n" + "".join(f"{a},{0.05 * np.sin(5 * a)},{0.04 * a}\n" for a in t))
    data, side = clip(tmp_path, "own.gif", "--trajectory", str(path), "--samples", "12", "--size", "320x180")
    assert Image.open(io.BytesIO(data)).n_frames == 12 and side["t"][-1] == pytest.approx(0.4)


@pytest.mark.slow
def test_the_papers_circle_at_20_fps_is_under_5_mb(tmp_path):
    assert main(["clip", "--trajectory", "circle", "--fps", "20", "--output", str(tmp_path / "c.gif")]) == 0
    data = (tmp_path / "c.gif").read_bytes()
    assert len(data) < 5 * 2**20
    assert Image.open(io.BytesIO(data)).n_frames == 401


def test_the_docs_clip_is_made_by_the_command_its_page_states(capsys):
    stated = " ".join((ROOT / "docs" / "media.md").read_text().split())
    assert "tpm-viz " + " ".join(DOCS_CLIP[:-1]) + " docs/images/clip.gif" in stated
    assert main(DOCS_CLIP) == 0
    path = pathlib.Path(DOCS_CLIP[-1])
    im = Image.open(path)
    assert (im.n_frames, im.size) == (101, (640, 360))
    assert path.stat().st_size < 2**20
    assert "101 frames at 20 frames/s (5.0 s), 640x360" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--output", "x.avi"], "--output must end in .gif or .mp4"),
        (["--output", "x.gif", "--size", "10x10"], "the size must be from 320x180 to 1920x1080"),
        (["--output", "x.gif", "--size", "big"], "the size must be WIDTHxHEIGHT"),
        (["--output", "x.gif", "--fps", "0"], "the frame rate must be a whole number from 1 to 50"),
        (["--output", "x.mp4", "--size", "641x360", "--samples", "3"], "an MP4 needs an even width and height"),
        (["--output", "x.gif", "--samples", "1"], "--samples must be from 2 to 2001"),
        (["--output", "x.gif", "--duration", "0.001"], "duration must be from 0.01 s to 100 s"),
    ],
)
def test_bad_input_is_one_line(tmp_path, capsys, monkeypatch, extra, message):
    monkeypatch.chdir(tmp_path)
    assert main(["clip", "--trajectory", "line", *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1
    assert not list(tmp_path.iterdir())  # nothing written


def test_a_path_outside_the_workspace_is_refused_in_one_line(tmp_path, capsys):
    path = tmp_path / "far.csv"
    path.write_text("t,p1,p2\n0,0,0\n0.1,0.1,0\n0.2,0.2,0\n0.3,0.3,0\n")
    assert main(["clip", "--trajectory", str(path), "--output", str(tmp_path / "x.gif")]) == 2
    err = capsys.readouterr().err
    assert err.startswith("tpm-viz: error: the trajectory") and err.count("\n") == 1
    assert not (tmp_path / "x.gif").exists()
