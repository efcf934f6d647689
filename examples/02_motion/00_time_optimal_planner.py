"""The time-optimal planner

The fastest rest-to-rest motion along a path within the motors' force limit `|τ_i| ≤ F_max`, with the closed-form
dynamics and [toppra](https://github.com/hungpham2511/toppra): the paper's circle, then a pick-and-place cycle (up
25 mm, across, down, and back) centred in the prototype's workspace. The forces of the plan are the closed form's
along the exact path; at almost every instant one actuator is at the limit. The sizing table says what the cycle
asks of the motors (peak and RMS force, power, energy). The same as `tpm-viz plan` and `tpm-viz size`
([control and C](../../control.md)).
"""

import numpy as np

import tpm_viz as tv
from tpm_viz.app.paths import circle_path, default_pick
from tpm_viz.app.planner import Limits, plan_cycle, plan_path
from tpm_viz.app.sizing import format_sizing, size_motion

params = tv.Params.paper()
limits = Limits(force=100.0)  # F_max [N]

circle = plan_path(params, circle_path(), limits)
states = circle.samples()  # every millisecond, plus the ends
print(f"circle at F_max = 100 N: {circle.duration:.3f} s, peak |tau| = {np.abs(states.tau).max():.1f} N")

cycle = plan_cycle(params, default_pick(params), limits)
strokes = ", ".join(f"{d:.4f} s" for d in cycle.move_durations)
print(f"pick and place: {cycle.duration:.4f} s of motion (the two strokes: {strokes})")
s = cycle.samples()
sizing = size_motion(s.t, s.tau, s.dd, dwell=0.2, dp=s.dp)  # with a dwell of 0.2 s per cycle
print(f"with a 0.2 s dwell: cycle time {sizing.cycle_time:.4f} s, {60 / sizing.cycle_time:.1f} picks/min")
print(format_sizing(sizing))
