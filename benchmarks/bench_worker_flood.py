"""Do ten flooding tabs make another tab wait for its heavy jobs? (issue 23: "ten flooding tabs delay another tab's
trajectory load or map by at most 300 ms p95 and a dragging tab's p95 stays under 100 ms"). Run by hand:
``python benchmarks/bench_worker_flood.py`` (``--flood control planner`` to choose the floods).

Thirteen protocol tabs on an in-process app, each on its own copy. Ten flooders either press the control lab's
*Why computed torque? (run all three)* every 0.5 s (``control``) or move the planner's force-limit slider to a new
value every 0.1 s (``planner``). Meanwhile, one after the other, three more tabs measure:

- *load*: tab L picks the paper's line, then circle, ... in the *Player* tab, :data:`PAUSE` after each arrived (a
  student now and then); the latency is the choice sent -> the run of that trajectory in L's session;
- *map*: tab M shows the condition-number floor map and types a new link length l_a, :data:`PAUSE` after each map;
  the latency is the Enter sent -> the map of the new parameters drawn in M's explorer;
- *drag*: tab D drags its platform at 20 Hz (as ``bench_control_load.py``); the latency is the gizmo update sent ->
  the new pose committed in D's session.

Prints median and p95 of each, without a flood and under each flood, the p95 against its target, and how long L's
runs and M's maps waited in the worker's queue (submitted -> started: what the fair queue decides; the rest is
computing and drawing). ``--threads N`` sets the pool size (``tpm_viz.classroom.worker.THREADS``). The same script
runs on
the tree before issue 23 (one worker thread in submission order, the planner's own thread): copy it there.
"""

from __future__ import annotations

import argparse
import statistics
import sys
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from timing import p95

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.classroom import worker
from tpm_viz.classroom.runtime import tune_for_serving
from tpm_viz.ui.app import TpmApp, build_server

FLOODERS = 10
LOADS = 20
MAPS = 20
DRAGS = 80
PAUSE = 1.0
"""[s] between one load (map) arriving and tab L (M) asking for the next: a student now and then, not a flood (a
tab asking faster than about once a second counts as flooding: ``tpm_viz.classroom.jobs.FLOODER``)."""
TARGETS = {"load": 0.300, "map": 0.300, "drag": 0.100}  # p95 [s], issue 23
LINE, CIRCLE = "line (Fig. 4)", "circle (Fig. 5)"


def open_tab(app: TpmApp):
    """A new protocol tab on its own copy: (client, view)."""
    before = set(app.views)
    client = ProtocolClient(app.port)
    new = wait_for(lambda: set(app.views) - before, what="a view", timeout=30)
    view = app.views[next(iter(new))]
    wait_for(lambda: view.session.readout is not None, what="first render", timeout=30)
    client.set_value(view.panel.own_copy, True)
    wait_for(lambda: not view.session.shared, what="own copy", timeout=30)
    return client, view


def loads(client: ProtocolClient, view, n: int = LOADS) -> list[float]:
    runs = view.teaching.services.runs
    out = []
    for k in range(n):
        label, kind = (LINE, "line") if k % 2 == 0 else (CIRCLE, "circle")

        def arrived(kind=kind) -> bool:
            ps = runs.of(view.session)
            return ps.run is not None and ps.run.source.kind == kind and ps.loading is None

        t0 = time.perf_counter()
        client.set_value(view.teaching.player.choice, label)
        wait_for(arrived, timeout=60, interval=0.0005, what=f"the {kind} run")
        out.append(time.perf_counter() - t0)
        time.sleep(PAUSE)
    return out


def maps(client: ProtocolClient, view, n: int = MAPS) -> list[float]:
    explorer = view.teaching.explorer
    client.set_value(explorer.map_kind, MAP_KINDS["cond"])
    wait_for(lambda: explorer.kind == "cond", what="the map kind")
    out = []
    for k in range(n):
        l_a = 0.255 + 0.0005 * k + 0.00001 * (time.time_ns() % 97)  # new parameters: never a cached map

        def drawn(l_a=l_a) -> bool:
            params = view.session.state.params
            return abs(params.l_a - l_a) < 1e-9 and explorer._map_drawn == (params, "cond")

        t0 = time.perf_counter()
        client.enter(view.panel.params, {"l_a": f"{l_a * 1e3:.2f}"})
        wait_for(drawn, timeout=60, interval=0.0005, what="the map")
        out.append(time.perf_counter() - t0)
        time.sleep(PAUSE)
    return out


def drags(client: ProtocolClient, view, n: int = DRAGS) -> list[float]:
    out = []
    for k in range(n):
        x, y = 0.02 * np.sin(k / 7.0), 0.015 * np.cos(k / 5.0)
        t0 = time.perf_counter()
        client.drag(view.scene.gizmo, str(view.client.client_id), [(x, y, 0.09)], end=False)
        wait_for(
            lambda x=x, y=y: np.allclose(view.session.state.pose.p, (x, y), atol=1e-9), timeout=10, interval=0.0005
        )
        out.append(time.perf_counter() - t0)
        time.sleep(max(0.0, 0.05 - out[-1]))
    return out


class Waits:
    """The queue wait of every job (submitted -> started) [s], by kind (``run``, ``map``, ``control``, ``plan``):
    ``Worker.submit`` wrapped, so the same code measures the tree before issue 23 and after."""

    def __init__(self) -> None:
        self.waits: dict[str, list[float]] = {}
        submit = worker.Worker.submit

        def timed_submit(this, key, fn, *args, **kwargs):
            kind = str(key[0] if isinstance(key, tuple) else key)
            t0 = time.perf_counter()

            def timed():
                self.waits.setdefault(kind, []).append(time.perf_counter() - t0)
                return fn()

            return submit(this, key, timed, *args, **kwargs)

        worker.Worker.submit = timed_submit

    def take(self) -> dict[str, list[float]]:
        out, self.waits = self.waits, {}
        return out


def flood(kind: str, tabs, stop: threading.Event, counts: list[int]) -> list[threading.Thread]:
    """Threads pressing the control lab's lesson button every 0.5 s, or moving the force slider every 0.1 s."""

    def control(i: int, client, view) -> None:
        while not stop.wait(0.5 if counts[i] else 0.05 * i):
            client.click(view.teaching.control.lesson)
            counts[i] += 1

    def planner(i: int, client, view) -> None:
        while not stop.wait(0.1 if counts[i] else 0.01 * i):
            counts[i] += 1
            client.set_value(view.teaching.planner.force, 100.0 + 0.37 * counts[i] + 0.011 * i)

    body = control if kind == "control" else planner
    threads = [threading.Thread(target=body, args=(i, c, v), daemon=True) for i, (c, v) in enumerate(tabs)]
    for t in threads:
        t.start()
    return threads


def line(name: str, xs: list[float], target: float) -> None:
    ms = 1e3
    print(
        f"  {name:<5} median {statistics.median(xs) * ms:7.1f} ms   p95 {p95(xs) * ms:7.1f} ms   "
        f"max {max(xs) * ms:7.1f} ms   (n={len(xs)}, p95 / target {p95(xs) / target:5.2f})"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument(
        "--flood", nargs="*", default=["none", "control", "planner"], choices=("none", "control", "planner")
    )
    parser.add_argument(
        "--threads", type=int, default=None, help="pool size (default: tpm_viz.classroom.worker.THREADS)"
    )
    args = parser.parse_args()
    if args.threads is not None and hasattr(worker, "THREADS"):
        worker.THREADS = args.threads
    print(f"pool: {getattr(worker, 'THREADS', 'one worker and one planner')} thread(s)")
    waits = Waits()
    app = TpmApp(build_server("127.0.0.1", 0))
    tune_for_serving()  # the runtime as python app.py sets it up
    clients = []
    try:
        flooders = [open_tab(app) for _ in range(FLOODERS)]
        (cl, vl), (cm, vm), (cd, vd) = (open_tab(app) for _ in range(3))
        clients = [c for c, _ in flooders] + [cl, cm, cd]
        for kind in args.flood:
            stop, counts = threading.Event(), [0] * FLOODERS
            threads = [] if kind == "none" else flood(kind, flooders, stop, counts)
            time.sleep(1.0)
            t0 = time.perf_counter()
            waits.take()
            measured = {"load": loads(cl, vl)}
            queued = {"load": waits.take().get("run", [])}
            measured["map"] = maps(cm, vm)
            queued["map"] = waits.take().get("map", [])
            measured["drag"] = drags(cd, vd)
            seconds = time.perf_counter() - t0
            stop.set()
            for t in threads:
                t.join(5)
            rate = sum(counts) / max(seconds, 1e-9)
            print(f"flood: {kind} ({FLOODERS} tabs, {rate:.1f} requests/s in all)" if threads else "flood: none")
            for name, xs in measured.items():
                line(name, xs, TARGETS[name])
            for name, xs in queued.items():
                if xs:
                    print(f"  {name:<5} job queued {statistics.median(xs) * 1e3:7.1f} ms   p95 {p95(xs) * 1e3:7.1f} ms")
            wait_for(app.services.worker.idle, timeout=120, what="the worker idle")
    finally:
        for c in clients:
            c.close()
        app.stop()


if __name__ == "__main__":
    main()
