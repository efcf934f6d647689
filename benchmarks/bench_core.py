"""Speed of the pure-numpy core (run by hand: ``python benchmarks/bench_core.py``).

Prints medians over repeated runs and the ratio to the targets of issue 2:
closed-form inverse dynamics for 100 000 states < 25 ms (vectorised), one state < 20 µs,
a 200 x 200 singularity map < 50 ms. Then the ratios of issue 27 against an independent implementation measured in
the same run (``sympy_reference.py``: sympy from the Lagrangian, lambdified): vectorised inverse dynamics of 10^5
states <= 0.5 x the reference's time, one state <= 1.0 x. The two are timed in alternation (best of each), so a busy
machine slows both alike (best of batches of consecutive calls: see ``_alternating``).
"""

from __future__ import annotations

import timeit

import numpy as np
from sympy_reference import reference_inverse_dynamics
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
    ratios(params, p, dp, ddp)


def _alternating(ours, theirs, number: int, rounds: int = 6, batch: int = 5) -> tuple[float, float]:
    """Best time per call [s] of ``ours`` and of ``theirs``: ``rounds`` alternations of ``batch`` consecutive timings
    each (of ``number`` calls). Consecutive, because the first call after the other implementation pays for the heap
    the other left behind (glibc returns freed 10^5-state arrays to the system); alternated, because a busy machine
    then slows both alike."""
    best_ours = best_theirs = float("inf")
    for _ in range(rounds):
        best_ours = min(best_ours, min(timeit.repeat(ours, number=number, repeat=batch)) / number)
        best_theirs = min(best_theirs, min(timeit.repeat(theirs, number=number, repeat=batch)) / number)
    return best_ours, best_theirs


def ratios(params, p, dp, ddp) -> None:
    """Issue 27's ratios to the sympy reference (same inputs, same run)."""
    cols = [np.ascontiguousarray(x[:, k]) for x in (p, dp, ddp) for k in (0, 1)]
    ours, ref = _alternating(
        lambda: tv.inverse_dynamics(params, p, dp, ddp), lambda: reference_inverse_dynamics(params, *cols), 1
    )
    print(
        f"{'vectorised 10^5 states: tpm_viz / sympy reference':<58} {ours * 1e3:7.2f} ms / {ref * 1e3:7.2f} ms"
        f"   ratio {ours / ref:5.2f}   target <= 0.50"
    )
    one, scalars = (p[7], dp[7], ddp[7]), [float(c[7]) for c in cols]
    ours, ref = _alternating(
        lambda: tv.inverse_dynamics(params, *one), lambda: reference_inverse_dynamics(params, *scalars), 2000
    )
    print(
        f"{'one state: tpm_viz / sympy reference':<58} {ours * 1e6:7.2f} µs / {ref * 1e6:7.2f} µs"
        f"   ratio {ours / ref:5.2f}   target <= 1.00"
    )


if __name__ == "__main__":
    main()
