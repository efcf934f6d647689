"""Speed of the browser app (benchmarks, not tests): prints medians and 95th percentiles.

1. Server side, one drag update: clamped inverse kinematics, both dynamic models (closed form and Pinocchio),
   the scene and panel push and the flush, exactly as a gizmo event runs it (``Dragging.drain``),
   with 1, 10 and 30 tabs on the shared mechanism (protocol-level clients), and one tab on its own copy.
2. End to end in headless Chromium: from a browser input to the scene update arriving in the page (decoded by
   viser's websocket worker), for a gizmo drag with the real mouse and for a typed actuator position.
3. Start-up: ``python app.py --port 0`` to the first line, and to a served page (HTTP 200 on ``/``).

Run: ``python benchmarks/bench_ui.py`` (add ``--quick`` for fewer samples, ``--server-only`` for part 1). Needs
/usr/bin/chromium for part 2.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
import urllib.request
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the repository root: tests.support

from tests.support.browser import CHROMIUM, CHROMIUM_ARGS, WORKER_LOG_JS
from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.classroom.dragging import Dragging
from tpm_viz.classroom.drags import PendingDrag
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.viserkit.probe import widget_uuid


def _stats(name: str, seconds) -> None:
    ms = np.asarray(seconds) * 1e3
    print(f"  {name:<46} median {np.median(ms):7.2f} ms   p95 {np.percentile(ms, 95):7.2f} ms   (n={len(ms)})")


def _connect(app: TpmApp, n: int) -> list:
    clients, views = [], []
    for _ in range(n):
        before = set(app.views)
        clients.append(ProtocolClient(app.port))
        new = wait_for(lambda before=before: set(app.views) - before, what="a view")
        views.append(app.views[next(iter(new))])
    return clients, views


def _drag_times(app: TpmApp, view, samples: int, pause: float = 0.0) -> list[float]:
    """Seconds each of ``samples`` drag updates of ``view`` takes to commit (around a 90 mm circle)."""
    times = []
    for k in range(samples):
        angle = 2 * np.pi * k / samples
        target = np.array([0.09 * np.cos(angle), 0.09 * np.sin(angle), 0.09])
        view.session.drags.push(view, PendingDrag("update", target, next(app.hub.arrivals)))
        t0 = time.perf_counter()
        view.drags.drain()
        times.append(time.perf_counter() - t0)
        time.sleep(pause)
    return times


def bench_server(samples: int) -> None:
    print("1. Server-side cost of one drag update (drag_to + closed form + Pinocchio + scene/panel push + flush)")
    for tabs in (1, 10, 30):
        app = TpmApp(build_server("127.0.0.1", 0))
        clients, views = _connect(app, tabs)
        view = views[0]
        _stats(f"{tabs} tab(s) on the shared mechanism", _drag_times(app, view, samples))
        if tabs == 1:  # the same tab on its own copy (a student's drag: its scene, panel and teaching layer)
            with app.hub.lock:
                view.switch(True)
            # a browser's next event comes later: the loop sends in between
            _stats("1 tab on its own copy", _drag_times(app, view, samples, pause=0.002))
        for c in clients:
            c.close()
        app.stop()


_LATENCY_JS = """
(name) => {
  // Pair each outgoing input with the first later incoming update of scene node `name`.
  const log = window.__viserLog;
  const out = [];
  for (let i = 0; i < log.length; i++) {
    const m = log[i];
    if (m.dir !== "out" || !(m.type === "TransformControlsUpdateMessage" || m.type === "GuiUpdateMessage")) continue;
    for (let j = i + 1; j < log.length; j++) {
      const r = log[j];
      if (r.dir === "in" && r.name === name && r.type === "SetPositionMessage") { out.push([m.t, r.t]); break; }
      if (r.dir === "out" && r.type === m.type) break;  // next input came first: unpaired
    }
  }
  return out;
}
"""


def bench_browser(samples: int) -> None:
    print("2. End-to-end latency in headless Chromium (input sent by the page -> scene update decoded in the page)")
    if not os.path.exists(CHROMIUM):
        print(f"  skipped: {CHROMIUM} not found")
        return
    import viser.transforms as tf
    from playwright.sync_api import sync_playwright

    received: list[float] = []
    flushed: list[float] = []
    original_on_drag, original_drain = Dragging.on_drag, Dragging.drain

    async def on_drag(self, event):  # timestamp each gizmo message as the server receives it
        received.append(time.perf_counter())
        await original_on_drag(self, event)

    def drain(self):
        start = received[-1] if received else time.perf_counter()
        original_drain(self)
        flushed.append(time.perf_counter() - start)

    Dragging.on_drag, Dragging.drain = on_drag, drain
    app = TpmApp(build_server("127.0.0.1", 0))
    with tempfile.TemporaryDirectory() as profile, sync_playwright() as pw:
        ctx = pw.chromium.launch_persistent_context(
            profile,
            executable_path=CHROMIUM,
            args=CHROMIUM_ARGS,
            headless=True,
            viewport={"width": 1400, "height": 860},
        )
        page = ctx.new_page()
        page.add_init_script(WORKER_LOG_JS)
        page.goto(f"http://127.0.0.1:{app.port}/")
        page.wait_for_function("() => (window.__viserLog||[]).some(m => m.type === 'ReplayDoneMessage')")
        page.wait_for_selector("[data-q=p1]")
        view = wait_for(lambda: next(iter(app.views.values()), None))
        wait_for(lambda: view.client.camera.image_width > 0)
        time.sleep(1.0)

        # (a) Gizmo drag with the mouse, back and forth along x.
        cam = view.client.camera
        rot = tf.SO3(np.asarray(cam.wxyz)).as_matrix()
        point = np.asarray(view.scene.gizmo.position) + np.array([0.08, 0.0, 0.0])
        xc = rot.T @ (point - np.asarray(cam.position))
        focal = (cam.image_height / 2) / np.tan(cam.fov / 2)
        x0, y0 = cam.image_width / 2 + focal * xc[0] / xc[2], cam.image_height / 2 + focal * xc[1] / xc[2]
        page.evaluate(
            "() => { window.__viserLog.length = 0; window.__frames = [];"
            " const f = (t) => { window.__frames.push(t); requestAnimationFrame(f); }; requestAnimationFrame(f); }"
        )
        flushed.clear()
        page.mouse.move(x0, y0)
        page.mouse.down()
        for k in range(samples):
            dx = 60 * np.sin(2 * np.pi * k / 40)
            page.mouse.move(x0 + dx, y0)
            time.sleep(0.03)
        page.mouse.up()
        time.sleep(0.5)
        pairs = page.evaluate(_LATENCY_JS, "/tpm/platform")
        _stats("gizmo drag: update sent -> platform moved", [(b - a) / 1e3 for a, b in pairs])
        _stats("  of which server: message received -> flushed", flushed)
        frames = np.diff(page.evaluate("() => window.__frames")) / 1e3
        _stats("  page frame interval during the drag", frames)

        # (b) Typed actuator position d1 (the number field beside the slider).
        page.evaluate("() => { window.__viserLog.length = 0; }")
        field = (
            page.locator(f'label[for="{widget_uuid(view.panel.d[0])}"]')
            .locator("xpath=ancestor::div[contains(@class,'mantine-Flex-root')][1]")
            .locator("input.mantine-NumberInput-input")
        )
        for k in range(max(samples // 4, 10)):
            field.fill(f"{120 + 40 * (k % 2)}")
            field.press("Tab")
            time.sleep(0.12)
        time.sleep(0.5)
        pairs = page.evaluate(_LATENCY_JS, "/tpm/slider1")
        _stats("typed d1: update sent -> slider moved", [(b - a) / 1e3 for a, b in pairs])
        ctx.close()
    app.stop()
    Dragging.on_drag, Dragging.drain = original_on_drag, original_drain


def bench_startup(runs: int) -> None:
    print("3. Start-up: python app.py --port 0")
    to_line, to_page = [], []
    for _ in range(runs):
        t0 = time.perf_counter()
        proc = subprocess.Popen(
            [sys.executable, str(ROOT / "app.py"), "--port", "0"],
            stdout=subprocess.PIPE,
            stderr=subprocess.DEVNULL,
            text=True,
            cwd=ROOT,
        )
        try:
            line = proc.stdout.readline().strip()
            to_line.append(time.perf_counter() - t0)
            url = line.rsplit(" ", 1)[-1]
            while True:
                try:
                    with urllib.request.urlopen(url + "/", timeout=2) as resp:
                        if resp.status == 200 and resp.read(100):
                            break
                except OSError:
                    time.sleep(0.01)
            to_page.append(time.perf_counter() - t0)
        finally:
            proc.terminate()
            proc.wait(timeout=10)
    _stats("to the printed URL line", to_line)
    _stats("to a served page (HTTP 200 on /)", to_page)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer samples")
    parser.add_argument("--server-only", action="store_true", help="part 1 only (no browser, no start-up)")
    args = parser.parse_args()
    n = 100 if args.quick else 500
    bench_server(n)
    if not args.server_only:
        bench_browser(60 if args.quick else 200)
        bench_startup(3 if args.quick else 5)
    print(f"({statistics.__name__} of {os.cpu_count()} CPU(s); python {sys.version.split()[0]})")


if __name__ == "__main__":
    main()
