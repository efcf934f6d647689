"""Along the paper's line and circle

The two trajectories of the paper's Figs. 4-5, a line in 0.2 s and a circle in 0.5 s, both on the cubic time law
(start and end at rest), and the closed-form actuator forces along them. The peak force scales as `1/T²`: the circle
played twice as slowly needs a quarter of the force. The run is written as a CSV file (SI columns), the file
`tpm-viz dynamics` reads and writes.
"""

import csv

import numpy as np

import tpm_viz as tv

params = tv.Params.paper()
for kind in ("line", "circle"):
    traj = tv.paper_trajectory(kind)  # default durations: line 0.2 s, circle 0.5 s (docs/conventions.md)
    tau = tv.inverse_dynamics(params, traj.p, traj.dp, traj.ddp)  # (n, 2) [N]
    k = int(np.argmax(np.abs(tau).max(axis=1)))
    print(f"{kind:6s} T = {traj.duration:.1f} s: peak |tau| = {np.abs(tau).max():6.1f} N at t = {traj.t[k]:.3f} s")

fast = tv.paper_trajectory("circle", duration=0.5)
slow = tv.paper_trajectory("circle", duration=1.0)
peak = [np.abs(tv.inverse_dynamics(params, t.p, t.dp, t.ddp)).max() for t in (fast, slow)]
print(f"circle at 0.5 s vs 1 s: {peak[0]:.1f} N / {peak[1]:.1f} N = {peak[0] / peak[1]:.3f}")  # 4.000: 1/T²

tau = tv.inverse_dynamics(params, fast.p, fast.dp, fast.ddp)
with open("circle.csv", "w", newline="") as f:
    out = csv.writer(f)
    out.writerow(["t", "p1", "p2", "dp1", "dp2", "ddp1", "ddp2", "tau1", "tau2"])
    for row in zip(fast.t, *fast.p.T, *fast.dp.T, *fast.ddp.T, *tau.T, strict=True):
        out.writerow([f"{v:.17g}" for v in row])
print(f"wrote circle.csv ({len(fast.t)} samples)")
