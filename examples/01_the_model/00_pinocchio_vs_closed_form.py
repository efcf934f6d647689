"""Pinocchio against the closed form

Every force of tpm-viz is computed twice: by the paper's closed form (eqs. 29-31) and by an independent closed-loop
multibody model built in Pinocchio from the same parameters (two prismatic sliders, the four parallelogram links on
revolute joints, the platform, three loop closures; [pinocchio.md](../../pinocchio.md)). This example compares them
on seeded random regular states (with a load on the platform) and along the paper's circle; they agree to about
1e-13 relative, where the paper reported about 5 % against ADAMS. `tpm-viz crosscheck` prints the same comparison as a
table, with the replay of the paper's forces on the model ([the model](../../model.md)).
"""

import numpy as np

import tpm_viz as tv
from tpm_viz.multibody import inverse_dynamics as pinocchio_inverse_dynamics
from tpm_viz.multibody.crosscheck import random_regular_states

params = tv.Params.paper()

p, dp, ddp, f_ext = random_regular_states(params, 100, seed=0)  # regular poses, ~1 m/s, ~20 m/s², ~20 N
closed = tv.inverse_dynamics(params, p, dp, ddp, f_ext=f_ext)
model = pinocchio_inverse_dynamics(params, p, dp, ddp, f_ext)
rel = np.abs(model - closed).max() / (1.0 + np.abs(closed).max())
print(f"100 random states: max |tau_pinocchio - tau_paper| = {np.abs(model - closed).max():.2e} N (rel {rel:.1e})")
assert rel < 1e-9

traj = tv.paper_trajectory("circle")
closed = tv.inverse_dynamics(params, traj.p, traj.dp, traj.ddp)
model = pinocchio_inverse_dynamics(params, traj.p, traj.dp, traj.ddp)
worst = np.abs(model - closed).max()
print(f"the circle (T = 0.5 s): peak {np.abs(closed).max():.1f} N, largest difference {worst:.1e} N")
