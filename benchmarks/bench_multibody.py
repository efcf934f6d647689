"""Speed of the Pinocchio closed-loop model (run by hand: ``python benchmarks/bench_multibody.py``).

Prints medians over repeated runs and the ratio to the targets of issue 3: constrained inverse
dynamics < 200 µs per state in Python, forward-dynamics replay of the 0.5 s circle < 2 s.
"""

from __future__ import annotations

import numpy as np
from timing import median_seconds, report

import tpm_viz as tv
from tpm_viz import multibody
from tpm_viz.multibody.replay import replay


def main() -> None:
    params = tv.Params.paper()
    model = multibody.model_for(params)
    traj = tv.paper_trajectory("circle", samples=501)
    n = len(traj.t)
    rng = np.random.default_rng(0)
    p_rand = rng.uniform(-0.15, 0.15, (n, 2))
    dp_rand, ddp_rand = rng.normal(0, 1, (n, 2)), rng.normal(0, 20, (n, 2))

    along = median_seconds(lambda: model.inverse_dynamics(traj.p, traj.dp, traj.ddp), repeat=7) / n
    report("Pinocchio inverse dynamics, per state along the circle", along, 200e-6, "µs", 1e6)
    scattered = median_seconds(lambda: model.inverse_dynamics(p_rand, dp_rand, ddp_rand), repeat=7) / n
    report("Pinocchio inverse dynamics, per state, random states", scattered, 200e-6, "µs", 1e6)
    one = (traj.p[100], traj.dp[100], traj.ddp[100])
    report(
        "Pinocchio inverse dynamics, one call (same state: app frame)",
        median_seconds(lambda: model.inverse_dynamics(*one), repeat=21, inner=200),
        200e-6,
        "µs",
        1e6,
    )
    closed = median_seconds(lambda: tv.inverse_dynamics(params, *one), repeat=21, inner=2000)
    report("paper closed form, one call (for the ratio)", closed, None, "µs", 1e6)
    print(f"{'':<58} Pinocchio / closed form = {along / closed:.0f}x per state")
    q = model.configuration(one[0])
    report(
        "configuration(p) + placements(q) (app frame)",
        median_seconds(lambda: model.placements(model.configuration(one[0])), repeat=21, inner=200),
        None,
        "µs",
        1e6,
    )
    v = model.constrained_motion(*one)[1]
    tau = model.inverse_dynamics(*one)
    report(
        "forward_dynamics(q, v, τ), one call",
        median_seconds(lambda: model.forward_dynamics(q, v, tau), repeat=21, inner=200),
        None,
        "µs",
        1e6,
    )
    for kind, target in (("circle", 2.0), ("line", 2.0)):
        seconds = median_seconds(lambda kind=kind: replay(params, kind), repeat=5)
        res = replay(params, kind)
        report(f"replay {kind} T={res.duration:g} s, {len(res.t) - 1} RK4 steps", seconds, target, "s", 1.0)
        print(
            f"{'':<58} tracking {res.max_tracking_error * 1e3:.2e} mm, violation {res.max_constraint_violation:.2e} m"
        )


if __name__ == "__main__":
    main()
