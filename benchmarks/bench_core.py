"""Speed of the pure-numpy core (run by hand: ``python benchmarks/bench_core.py``).

Prints medians over repeated runs and the ratio to the targets of issue 2:
closed-form inverse dynamics for 100 000 states < 25 ms (vectorised), one state < 20 µs,
a 200 x 200 singularity map < 50 ms.
"""

from __future__ import annotations

import numpy as np
from timing import median_seconds, report

import tpm_viz as tv


def main() -> None:
    params = tv.Params.paper()
    rng = np.random.default_rng(0)
    n = 100_000
    p = rng.uniform(-0.1, 0.1, (n, 2))
    dp = rng.uniform(-1.0, 1.0, (n, 2))
    ddp = rng.uniform(-10.0, 10.0, (n, 2))
    report(
        "inverse_dynamics, 100 000 states (vectorised)",
        median_seconds(lambda: tv.inverse_dynamics(params, p, dp, ddp), repeat=21),
        25e-3,
        "ms",
        1e3,
    )
    one = (p[7], dp[7], ddp[7])
    report(
        "inverse_dynamics, one state",
        median_seconds(lambda: tv.inverse_dynamics(params, *one), repeat=21, inner=2000),
        20e-6,
        "µs",
        1e6,
    )
    report(
        "inverse_dynamics_detail, 100 000 states",
        median_seconds(lambda: tv.inverse_dynamics_detail(params, p, dp, ddp), repeat=21),
        25e-3,
        "ms",
        1e3,
    )
    report(
        "workspace_map 200 x 200 (reach, det J_x, det J_q, cond)",
        median_seconds(lambda: tv.workspace_map(params, 200), repeat=21),
        50e-3,
        "ms",
        1e3,
    )
    report(
        "inverse_kinematics, 100 000 poses",
        median_seconds(lambda: tv.inverse_kinematics(params, p), repeat=21),
        25e-3,
        "ms",
        1e3,
    )


if __name__ == "__main__":
    main()
