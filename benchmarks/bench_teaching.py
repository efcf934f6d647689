"""Speed of the teaching layer (a benchmark, not a test): prints medians and 95th percentiles.

1. Computing: a floor map for a new parameter set (workspace_map 200 x 200 + three colourings, in the
   background worker), a trajectory run (401 samples, closed form + Pinocchio, once per load).
2. Dragging is not stalled by a map: tab A drags the shared mechanism at 20 Hz (``Dragging.drain``, lock
   wait included) while tab B, on its own copy with a map shown, applies a new link length every 0.3 s. Four
   cases: B idle; the worker computing maps back to back (nobody else holding the lock); B applying parameters
   with its maps computed in the background worker (the app); the same with the maps computed inside the hub's
   lock (what the worker avoids).
3. Playback: server time per frame with 1 and 10 tabs on the shared mechanism, and the bytes one tab receives
   per second while the circle plays (3D every frame, charts and trace at most 5 times a second).

Run: ``python benchmarks/bench_teaching.py`` (``--quick`` for fewer samples).
"""

from __future__ import annotations

import argparse
import os
import sys
import threading
import time
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))  # the repository root: tests.support

from timing import median_seconds, report

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz import Params
from tpm_viz.app.runs import Source, build_run
from tpm_viz.app.transitions import apply_params
from tpm_viz.classroom.drags import PendingDrag
from tpm_viz.multibody.model import inverse_dynamics as pinocchio
from tpm_viz.ui.app import TpmApp, build_server
from tpm_viz.ui.teaching import explorer as explorer_module

P = Params.paper()


def _stats(name: str, seconds) -> None:
    ms = np.asarray(seconds) * 1e3
    print(
        f"  {name:<58} median {np.median(ms):7.2f} ms   p95 {np.percentile(ms, 95):7.2f} ms"
        f"   max {np.max(ms):7.2f} ms   (n={len(ms)})"
    )


class CountingClient(ProtocolClient):
    """A protocol client that also counts the bytes it receives."""

    def _drain(self) -> None:
        self.bytes = 0
        while not self._stop.is_set():
            try:
                msg = self.ws.recv(timeout=0.2)
                self.received += 1
                self.bytes += len(msg)
            except TimeoutError:
                continue
            except Exception:
                return


def _connect(app: TpmApp, n: int, cls=ProtocolClient):
    clients, views = [], []
    for _ in range(n):
        before = set(app.views)
        clients.append(cls(app.port))
        new = wait_for(lambda before=before: set(app.views) - before, what="a view")
        view = app.views[next(iter(new))]
        wait_for(lambda view=view: view.session.readout is not None, what="the first render")
        views.append(view)
    return clients, views


def bench_compute(repeat: int) -> None:
    print("1. Computation (median of fresh parameter sets)")
    service = explorer_module.MapService(worker=None)
    sets = iter(P.replace(l_a=0.25 + 1e-5 * k) for k in range(10_000))
    report(
        "floor map: workspace_map 200 x 200 + 3 colourings",
        median_seconds(lambda: service._compute(next(sets)), repeat=repeat),
        50e-3,
        "ms",
        1e3,
    )
    for kind, duration in (("line", 0.2), ("circle", 0.5)):
        report(
            f"trajectory run, {kind}: 401 samples, closed form + Pinocchio",
            median_seconds(
                lambda kind=kind, d=duration: build_run(P, Source.paper(kind, d), pinocchio), repeat=max(3, repeat // 3)
            ),
            None,
            "ms",
            1e3,
        )
    report(
        "trajectory run, circle: closed form only",
        median_seconds(lambda: build_run(P, Source.paper("circle")), repeat=repeat),
        None,
        "ms",
        1e3,
    )


def _drag_during_param_changes(samples: int, mode: str) -> list[float]:
    app = TpmApp(build_server("127.0.0.1", 0))
    clients, (a, b) = _connect(app, 2)
    b_client = clients[1]
    b_client.set_value(b.panel.own_copy, True)
    wait_for(lambda: not b.session.shared, what="B's own copy")
    with b.hub.lock:
        b.teaching.explorer.set(kind="det_jx")
    service = b.teaching.services.maps
    if mode == "in the lock":  # what the worker avoids: compute the map synchronously inside the callback
        original = service.get

        def inline(params):
            images = original(params)
            if images is None:
                images = service._compute(params)
                service._done(params, images)
            return images

        service.get = inline
    stop = threading.Event()
    applies: list[float] = []

    def b_applies() -> None:
        k = 0
        while mode == "maps only" and not stop.is_set():  # the worker busy with maps, nobody holds the lock
            k += 1
            service.get(P.replace(l_a=0.2 + 1e-5 * k))
            wait_for(lambda: service.worker.idle(), what="the map")
        while mode != "maps only" and not stop.is_set():
            k += 1
            raw = {"l_a": 250.0 + (k % 20) * 0.5}
            t0 = time.perf_counter()
            with b.hub.lock:
                new = apply_params(b.session.state, raw)
                b._commit(new)
            applies.append(time.perf_counter() - t0)
            stop.wait(0.3)

    thread = threading.Thread(target=b_applies, daemon=True)
    if mode != "idle":
        thread.start()
    times = []
    for k in range(samples):
        angle = 2 * np.pi * k / 40
        target = np.array([0.08 * np.cos(angle), 0.08 * np.sin(angle), 0.09])
        a.session.drags.push(a, PendingDrag("update", target, next(a.hub.arrivals)))
        t0 = time.perf_counter()
        a.drags.drain()
        times.append(time.perf_counter() - t0)
        time.sleep(max(0.0, 0.05 - (time.perf_counter() - t0)))
    stop.set()
    if mode != "idle":
        thread.join()
        wait_for(lambda: service.worker is None or service.worker.idle(), timeout=30, what="the worker")
    if applies:
        _stats(f"  (B's Apply: commit incl. its own scene rebuild, {mode})", applies)
    for c in clients:
        c.close()
    app.stop()
    return times


def bench_stall(samples: int) -> None:
    print("2. Tab A's drag update (lock wait included) while tab B changes its parameters every 0.3 s")
    for mode in ("idle", "maps only", "background worker", "in the lock"):
        times = _drag_during_param_changes(samples, mode)
        _stats(f"A's drag, B {mode}", times)


def _playback(tabs: int, seconds: float) -> None:
    app = TpmApp(build_server("127.0.0.1", 0))
    clients, views = _connect(app, tabs, CountingClient)
    view = views[0]
    runs = view.teaching.services.runs
    runs.load(view.session, Source.paper("circle"))
    wait_for(
        lambda: runs.of(view.session).run is not None and view.session.state.trajectory.kind == "circle", what="the run"
    )
    commit_times: list[float] = []
    original = view.hub.commit

    def timed(session, state, origin=None, dragging=False):
        t0 = time.perf_counter()
        original(session, state, origin, dragging)
        commit_times.append(time.perf_counter() - t0)

    view.hub.commit = timed
    time.sleep(0.5)
    start_bytes = clients[0].bytes
    t0 = time.perf_counter()
    runs.play(view.session, 0.1, loop=True)
    time.sleep(seconds)
    runs.pause(view.session)
    elapsed = time.perf_counter() - t0
    rate = (clients[0].bytes - start_bytes) / elapsed / 1e3
    _stats(f"{tabs} tab(s): one playback frame (commit + draw in every tab)", commit_times[1:])
    print(f"  {tabs} tab(s): {len(commit_times) / elapsed:5.1f} frames/s; one tab receives {rate:6.1f} kB/s")
    view.hub.commit = original
    for c in clients:
        c.close()
    app.stop()


def bench_playback(seconds: float) -> None:
    print("3. Playback of the circle (T = 0.5 s) at 0.1x")
    for tabs in (1, 10):
        _playback(tabs, seconds)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="fewer samples")
    args = parser.parse_args()
    bench_compute(7 if args.quick else 21)
    bench_stall(100 if args.quick else 300)
    bench_playback(3.0 if args.quick else 8.0)
    print(f"({os.cpu_count()} CPU(s); python {sys.version.split()[0]})")


if __name__ == "__main__":
    main()
