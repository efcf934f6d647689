"""Does simulating control runs slow another tab down? (issue 14: "another tab's drag p95 unchanged while runs are
simulated"). Run by hand: ``python benchmarks/bench_control_load.py``.

Two protocol tabs on an in-process app, each on its own copy. Tab B drags its platform at 20 Hz; the latency of a
drag is the time from sending the gizmo update to the new pose being committed in B's session. Measured twice:
with tab A idle, and with tab A pressing *Why computed torque? (run all three)* again and again (three closed-loop
simulations in the background worker per press). Prints median and p95 of both and their ratio.
"""

from __future__ import annotations

import statistics
import sys
import threading
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support

from timing import p95

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.ui.app import TpmApp, build_server

N = 80


def drag_latencies(client: ProtocolClient, view, n: int = N) -> list[float]:
    out = []
    for k in range(n):
        x, y = 0.02 * np.sin(k / 7.0), 0.015 * np.cos(k / 5.0)
        t0 = time.perf_counter()
        client.drag(view.scene.gizmo, str(view.client.client_id), [(x, y, 0.09)], end=False)
        wait_for(
            lambda x=x, y=y: np.allclose(view.session.state.pose.p, (x, y), atol=1e-9), timeout=5.0, interval=0.0005
        )
        out.append(time.perf_counter() - t0)
        time.sleep(max(0.0, 0.05 - out[-1]))
    return out


def main() -> None:
    app = TpmApp(build_server("127.0.0.1", 0))
    try:
        clients, views = [], []
        for _ in range(2):
            before = set(app.views)
            c = ProtocolClient(app.port)
            new = wait_for(lambda before=before: set(app.views) - before, what="a view")
            v = app.views[next(iter(new))]
            wait_for(lambda v=v: v.session.readout is not None, what="first render")
            c.set_value(v.panel.own_copy, True)
            wait_for(lambda v=v: not v.session.shared, what="own copy")
            clients.append(c)
            views.append(v)
        (ca, va), (cb, vb) = zip(clients, views, strict=True)
        idle = drag_latencies(cb, vb)
        stop = threading.Event()
        presses = [0]

        def press() -> None:
            while not stop.is_set():
                ca.click(va.teaching.control.lesson)
                presses[0] += 1
                time.sleep(0.25)

        presser = threading.Thread(target=press, daemon=True)
        presser.start()
        time.sleep(0.5)
        busy = drag_latencies(cb, vb)
        stop.set()
        presser.join(2)
        ms = 1e3
        print(f"tab B drags, tab A idle: median {statistics.median(idle) * ms:6.2f} ms  p95 {p95(idle) * ms:6.2f} ms")
        print(
            f"tab B drags, A simulating ({presses[0]} presses): median {statistics.median(busy) * ms:6.2f} ms  "
            f"p95 {p95(busy) * ms:6.2f} ms   ratio of p95 {p95(busy) / p95(idle):.2f}"
        )
        for c in clients:
            c.close()
    finally:
        app.stop()


if __name__ == "__main__":
    main()
