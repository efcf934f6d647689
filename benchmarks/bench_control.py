"""Speed of the control lab (run by hand: ``python benchmarks/bench_control.py``).

Target of issue 14: 1 s of simulated time at a 1 kHz controller in <= 150 ms (the Pinocchio plant
integrated with RK4 at 1 ms, the closed-form controller at every sample). Prints the median and the
95th percentile of repeated runs (warm: the model is built once and cached) and the ratio to real
time (wall time / simulated time), plus the first (cold) run and one plant evaluation.
"""

from __future__ import annotations

import statistics
import time

from timing import median_seconds, p95, report, samples_seconds

import tpm_viz as tv
from tpm_viz.multibody import model_for
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.multibody.forward import PlatformPlant

TARGET = 0.150  # s per simulated second at 1 kHz
REPEAT = 21


def main() -> None:
    params = tv.Params.paper()
    t0 = time.perf_counter()
    simulate(params, "circle", ControlSetup(), horizon=1.0)
    report("first run, 1 s at 1 kHz (cold: builds the Pinocchio model)", time.perf_counter() - t0, None, "ms", 1e3)
    for kind in ("pd", "pdff", "ctc"):
        setup = ControlSetup(controller=kind, payload=1.0, noise=1e-5, force_limit=400.0)
        samples = samples_seconds(lambda setup=setup: simulate(params, "circle", setup, horizon=1.0), REPEAT)
        med, q95 = statistics.median(samples), p95(samples)
        report(f"{kind}: 1 s of circle + rest at 1 kHz, median", med, TARGET, "ms", 1e3)
        print(f"{'':<58} p95    {q95 * 1e3:9.2f} ms   ratio to real time {med:.3f} (p95 {q95:.3f})")
    plant = PlatformPlant(model_for(params))
    one = median_seconds(lambda: plant.acceleration(0.02, -0.03, 0.4, 0.2, 50.0, -30.0), repeat=21, inner=500)
    report("plant acceleration p̈(p, ṗ, τ), one call (4 per RK4 step)", one, None, "µs", 1e6)
    fast = ControlSetup(rate=10_000.0)
    samples = samples_seconds(lambda: simulate(params, "circle", fast), 5)
    report("ctc: circle T = 0.5 s at 10 kHz, median", statistics.median(samples), None, "ms", 1e3)


if __name__ == "__main__":
    main()
