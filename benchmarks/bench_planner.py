"""Speed of the time-optimal planner (a benchmark, not a test): prints medians and 95th percentiles.

Target (issue 15): one solve with 300 grid points <= 100 ms, i.e. coefficients from the closed form (eqs. 29-31),
toppra's reachability analysis, the time law and the 1 kHz force check. The pick-and-place cycle is two solves
(there and back). The import of the planner (toppra, and matplotlib through it) and the first call are timed apart.

Run: ``python benchmarks/bench_planner.py`` (``--quick`` for fewer repeats).
"""

from __future__ import annotations

import argparse
import sys
import time
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parent))  # benchmarks/timing.py

from timing import samples_seconds

from tpm_viz import Params
from tpm_viz.app import paths

TARGET_MS = 100.0


def _stats(name: str, seconds, target: bool = True) -> None:
    ms = np.asarray(seconds) * 1e3
    verdict = f", target {TARGET_MS:.0f} ms: {'ok' if np.percentile(ms, 95) <= TARGET_MS else 'OVER'}" if target else ""
    print(
        f"  {name:<46} median {np.median(ms):7.2f} ms   p95 {np.percentile(ms, 95):7.2f} ms"
        f"   max {np.max(ms):7.2f} ms   (n={len(ms)}{verdict})"
    )


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--quick", action="store_true", help="fewer repeats")
    repeat = 10 if ap.parse_args().quick else 50
    t0 = time.perf_counter()
    from tpm_viz.app import planner  # imports toppra, which imports matplotlib

    print(f"  import tpm_viz.app.planner (toppra, matplotlib)  {1e3 * (time.perf_counter() - t0):7.1f} ms")
    params = Params.paper()
    limits = planner.Limits(100.0)
    cases = {kind: paths.path_for(params, kind) for kind in ("line", "circle", "pick")}
    t0 = time.perf_counter()
    planner.plan_path(params, cases["line"], limits)
    print(f"  first solve                                      {1e3 * (time.perf_counter() - t0):7.1f} ms")

    print(f"one solve, grid 300, F_max = {limits.force:g} N (paper's parameters):")
    for kind, path in cases.items():
        _stats(
            f"plan_path {kind} ({path.length * 1e3:.0f} mm)",
            samples_seconds(lambda p=path: planner.plan_path(params, p, limits), repeat),
        )
    cycle = samples_seconds(lambda: planner.plan_cycle(params, cases["pick"], limits), repeat)
    _stats("plan_cycle pick (two solves)", cycle, target=False)
    speed = planner.Limits(100.0, speed=1.0, actuator_speed=1.2)
    _stats(
        "plan_path circle + speed limits",
        samples_seconds(lambda: planner.plan_path(params, cases["circle"], speed), repeat),
    )
    for grid in (1000, 3000):
        _stats(
            f"plan_path circle, grid {grid}",
            samples_seconds(lambda g=grid: planner.plan_path(params, cases["circle"], limits, g), max(repeat // 5, 3)),
            target=False,
        )


if __name__ == "__main__":
    main()
