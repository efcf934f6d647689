"""Speed of the design studio (a benchmark, not a test): per-design time, sweep throughput per worker, the
10,000-design atlas, and the optimiser's wall time (issue 35: differential evolution polished by Nelder-Mead).

Target (issue 26): 10,000 designs with every index, cycle time included, within 10 minutes on the 2-core machine.
The cycle time's accuracy per planner grid is measured by ``tests/design/test_cycle_accuracy.py`` against an
independent time-optimal solver (docs/design.md, *Accuracy*).

Run: ``python benchmarks/bench_design.py`` (per-design times, throughput with 1 and 2 workers);
``--optimiser`` times ``compare`` (both arrangements' optima, ``--repeat`` times: medians and p95) directly and with
its batches run as jobs of the app's fair worker; ``--full`` adds the 10,000-design atlas (``--planner-grid K``).
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/timing.py

from timing import p95

from tpm_viz.classroom.worker import Worker
from tpm_viz.core.params import Params
from tpm_viz.design.atlas import Vary, designs, sweep
from tpm_viz.design.compare import Hold, compare
from tpm_viz.design.indices import Settings, Task, evaluate
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.ui.teaching.design.compare import in_turns

TASK = Task(-0.1, 0.1, -0.05, 0.05)
TARGET_S = 600.0
FULL = ["a=0.40:0.56:10", "b=0.06:0.12:10", "l_a=0.18:0.34:10", "stroke=0.2:0.4:10"]
"""The 10,000-design grid (about half of it covers the task)."""
SMALL = ["l_a=0.18:0.34:5", "stroke=0.2:0.4:4", "a=0.44:0.52:4"]
"""An 80-design grid for the throughput per worker."""


def per_design(grid_points: int, n: int = 20) -> list[float]:
    rng = np.random.default_rng(1)
    out = []
    for _ in range(n):
        params = Params.paper(l_a=float(rng.uniform(0.22, 0.32)), stroke=float(rng.uniform(0.28, 0.4)))
        t0 = time.perf_counter()
        evaluate(Arrangement.PERPENDICULAR, params, TASK, Settings(planner_grid=grid_points))
        out.append(time.perf_counter() - t0)
    return out


def throughput(spec: list[str], workers: int, grid_points: int) -> tuple[float, int, int]:
    grid = designs([Vary.parse(s) for s in spec])
    t0 = time.perf_counter()
    rows = sweep(Arrangement.PERPENDICULAR, Params.paper(), grid, TASK, Settings(planner_grid=grid_points), workers)
    return time.perf_counter() - t0, len(grid), sum(bool(r["feasible"]) for r in rows)


def handoff(batches: int = 2000) -> None:
    """What running batches as fair-worker jobs adds: ``batches`` batches of 8 designs whose cost is free."""
    worker = Worker(name="bench-handoff")
    evaluate_with = in_turns(worker, object(), "bench", lambda: True)
    points = [np.zeros(2)] * (8 * batches)
    times = []
    for _ in range(5):
        t0 = time.perf_counter()
        evaluate_with(lambda x: 0.0, points)
        times.append((time.perf_counter() - t0) / batches)
    print(f"fair-worker handoff: median {statistics.median(times) * 1e6:.0f} µs per batch of 8 designs")


def optimiser(hold: Hold, repeat: int) -> None:
    """Wall time of ``compare`` (two searches, seed 0) run directly and through the fair worker, and its designs."""
    counted: list[int] = []

    def counting(cost, points):
        counted.append(len(points))
        return [cost(x) for x in points]

    worker = Worker(name="bench-design")
    tab = object()
    for name, evaluate_with in (("direct", counting), ("fair worker", in_turns(worker, tab, "bench", lambda: True))):
        times = []
        for _ in range(repeat):
            counted.clear()
            t0 = time.perf_counter()
            rows = compare(Params.paper(), TASK, hold, evaluate=evaluate_with)
            times.append(time.perf_counter() - t0)
        cycles = ", ".join(f"{float(r['cycle_time']) * 1e3:.1f}" for r in rows[2:] if r.get("feasible"))
        designs_n = f", {sum(counted)} designs" if counted else ""
        print(
            f"compare --hold {hold.value} ({name}{designs_n}): median {statistics.median(times):.1f} s, "
            f"p95 {p95(times):.1f} s over {repeat}; optima {cycles} ms"
        )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--full", action="store_true", help="also run the 10,000-design atlas")
    ap.add_argument("--planner-grid", type=int, default=300)
    ap.add_argument("--workers", type=int, default=os.cpu_count() or 1)
    ap.add_argument("--optimiser", action="store_true", help="time compare's two searches (both ways)")
    ap.add_argument("--repeat", type=int, default=3, help="repeats of each optimiser timing")
    args = ap.parse_args()
    if args.optimiser:
        handoff()
        for hold in (Hold.LINK, Hold.FOOTPRINT):
            optimiser(hold, args.repeat)
        return
    print(f"cores {os.cpu_count()}, task {TASK.text()} m, force limit 100 N")
    for g in (300, 100):
        t = per_design(g)
        print(
            f"one feasible design, planner grid {g}: "
            f"median {statistics.median(t) * 1e3:.0f} ms, p95 {p95(t) * 1e3:.0f} ms"
        )
    for workers in (1, 2):
        seconds, n, ok = throughput(SMALL, workers, args.planner_grid)
        print(
            f"sweep of {n} designs ({ok} feasible), {workers} worker(s), planner grid {args.planner_grid}: "
            f"{seconds:.1f} s, {n / seconds:.1f} designs/s, {n / seconds / workers:.1f} designs/s per worker"
        )
    if args.full:
        seconds, n, ok = throughput(FULL, args.workers, args.planner_grid)
        print(
            f"atlas of {n} designs ({ok} feasible), {args.workers} workers, planner grid {args.planner_grid}: "
            f"{seconds:.0f} s ({seconds / 60:.1f} min; target {TARGET_S / 60:.0f} min, ratio {seconds / TARGET_S:.2f})"
        )


if __name__ == "__main__":
    main()
