"""Speed and size of clips and reports (a benchmark, not a test): prints medians, 95th percentiles and sizes.

1. One frame of the CLI's top-view renderer (:class:`tpm_viz.media.clips.ClipRenderer`) at 640×360, 800×450 and
   1920×1080, and of the app's 3D renderer through a tab's camera (:class:`tpm_viz.media.views3d.View3dRenderer`, the
   app's default camera pose, 75° vertical field of view) at 640×360 and 1920×1080.
2. A whole clip of the paper's circle (401 frames, 800×450, 20 frames/s) as GIF and MP4: render + encode time and
   bytes, and the app's recording of it through the tab's camera in jobs of
   :data:`tpm_viz.ui.teaching.takeout.recording.CHUNK_FRAMES` frames (one job's time is what another tab's job may wait
   behind it).
3. The lab report of the circle (with the Pinocchio forces).

Run: ``python benchmarks/bench_clip.py`` (``--quick`` for fewer samples).
"""

from __future__ import annotations

import argparse
import datetime
import math
import statistics
import sys
import time
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))

from timing import p95, samples_seconds

from tpm_viz import Params
from tpm_viz.app.runs import Source, build_run
from tpm_viz.media.clips import ClipRenderer
from tpm_viz.media.report import report_html
from tpm_viz.media.videos import encode_clip
from tpm_viz.media.views3d import Camera, View3dRenderer
from tpm_viz.multibody.model import inverse_dynamics
from tpm_viz.ui.scene import camera_pose
from tpm_viz.ui.teaching.takeout.recording import CHUNK_FRAMES, SCENE_COLOURS, Material, Recording


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true")
    args = parser.parse_args()
    run = build_run(Params.paper(), Source.paper("circle"), inverse_dynamics)
    frames = 60 if args.quick else 200
    for size in ((640, 360), (800, 450), (1920, 1080)):
        renderer = ClipRenderer(run, run.source.label, size)
        k = iter(range(10**9))
        times = samples_seconds(lambda r=renderer, k=k: r.frame(next(k) % len(r)), frames)
        print(
            f"one frame {size[0]}x{size[1]:<5} median {statistics.median(times) * 1e3:7.1f} ms   "
            f"p95 {p95(times) * 1e3:7.1f} ms"
        )
    position, look_at = camera_pose(run.params)
    camera = Camera.looking_at(position, look_at, (0.0, 0.0, 1.0), math.radians(75.0), 16 / 9)
    for size in ((640, 360), (1920, 1080)):
        view = View3dRenderer(run, run.source.label, size, camera, SCENE_COLOURS)
        k = iter(range(10**9))
        times = samples_seconds(lambda r=view, k=k: r.frame(next(k) % len(r)), frames)
        print(
            f"one 3D frame {size[0]}x{size[1]:<5} median {statistics.median(times) * 1e3:7.1f} ms   "
            f"p95 {p95(times) * 1e3:7.1f} ms"
        )
    renderer = ClipRenderer(run, run.source.label, (800, 450))
    for fmt in ("gif", "mp4"):
        t0 = time.process_time()
        data = encode_clip(fmt, renderer.frame, len(renderer), 20)
        print(f"circle {fmt}, 401 frames 800x450: {time.process_time() - t0:6.1f} s CPU, {len(data) / 2**20:5.2f} MiB")
    material = Material(run, run.source.label, "bench", lambda: (run, ()))
    recording = Recording(material, (800, 450), "gif", 20, camera)
    steps: list[float] = []
    while True:
        t0 = time.perf_counter()
        finished = recording.step()
        steps.append(time.perf_counter() - t0)
        if finished:
            break
    body = steps[1:-1]
    print(
        f"app recording, one job of {CHUNK_FRAMES} frames   median {statistics.median(body) * 1e3:7.1f} ms   "
        f"p95 {p95(body) * 1e3:7.1f} ms   set-up {steps[0] * 1e3:.0f} ms   last (GIF encode) {steps[-1] * 1e3:.0f} ms"
    )
    print(
        f"app recording (3D, 800x450, 401 frames): {sum(steps):6.1f} s, {len(recording.data or b'') / 2**20:5.2f} MiB"
    )
    times = samples_seconds(lambda: report_html(run, "en", datetime.date(2026, 1, 1)), 3 if args.quick else 10)
    size = len(report_html(run, "en", datetime.date(2026, 1, 1)).encode())
    print(f"report of the circle   median {statistics.median(times) * 1e3:7.1f} ms   {size / 2**10:.0f} KiB")


if __name__ == "__main__":
    main()
