"""Planner tab: slider -> cycle time shown (issue 15: within 200 ms). Run by hand: ``python
benchmarks/bench_planner_ui.py``. A protocol tab moves the force-limit slider (single moves, and drags of 15 values
15 ms apart timed from the last one); the latency is message sent -> the panel update with that value received."""

from __future__ import annotations

import statistics
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))  # the repository root: tests.support, tests.ui

from timing import p95

from tests.support.protocol import wait_for
from tests.ui.teaching.test_planner import TimedClient, _measure, _planned
from tpm_viz.ui.app import TpmApp, build_server

ROUNDS = 5
TARGET = 0.200  # s


def main() -> None:
    app = TpmApp(build_server("127.0.0.1", 0))
    client = TimedClient(app.port)
    try:
        view = app.views[next(iter(wait_for(lambda: set(app.views), what="the view")))]
        pv = _planned(view, 200.0)
        single, drags = [], []
        for r in range(ROUNDS):
            s, d = _measure(client, pv, 3.0 * r)  # new values each round: no cached plan
            single += s
            drags += d
        for name, xs in (("single move of the force slider", single), ("last value of a 15-value drag", drags)):
            print(
                f"{name:<34} median {statistics.median(xs) * 1e3:6.1f} ms   p95 {p95(xs) * 1e3:6.1f} ms   "
                f"max {max(xs) * 1e3:6.1f} ms   (n={len(xs)}, p95 / target {p95(xs) / TARGET:.2f})"
            )
    finally:
        client.close()
        app.stop()


if __name__ == "__main__":
    main()
