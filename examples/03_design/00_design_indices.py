"""The design indices of one design

What the design studio computes for one design over a task, the rectangle its platform must cover: feasibility
(inside the stroke, clear of both singularities), the global conditioning index (the area mean of `1/cond J`), the
worst `cond J`, the worst actuator force per unit platform acceleration (kg), the peak force of a standard pick in
0.2 s per stroke, its minimum cycle time at a force limit, the moving mass and the footprint. Here: the paper's
prototype, in its own perpendicular arrangement and in the parallel one it claims to beat, over a 200 × 100 mm task
around each one's home pose ([design.md](../../design.md)).
"""

from tpm_viz import Params
from tpm_viz.design.indices import Settings, Task, evaluate
from tpm_viz.paper.arrangement import Arrangement, home

params = Params.paper()
task = Task(-0.1, 0.1, -0.05, 0.05)  # [m]
for arrangement in Arrangement:
    placed = task.centred_at(*home(arrangement, params))  # the task centred on this machine's home pose
    idx = evaluate(arrangement, params, placed, Settings(force_limit=100.0))
    print(f"{arrangement.value}: feasible {idx.feasible}")
    if idx.feasible:
        print(f"  GCI {idx.gci:.3f}, worst cond J {idx.cond_max:.2f}, worst force/acceleration {idx.dyn_max:.2f} kg")
        print(f"  peak force {idx.peak_force:.0f} N, pick cycle {idx.cycle_time * 1e3:.0f} ms at 100 N")
        size = f"{idx.footprint_x * 1e3:.0f} × {idx.footprint_y * 1e3:.0f} mm"
        print(f"  moving mass {idx.moving_mass:.2f} kg, footprint {size}")
    else:
        print(f"  {idx.why}")
