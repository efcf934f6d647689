"""The singularity map

The workspace of the paper's prototype on a 200 × 200 grid: where the platform can be reached, where it is inside
the actuators' stroke, the direct-singularity measure `det J_x = cos(θ1 + θ2)` (eq. 12: zero where the two assembly
modes merge) and the condition number of `J`. It is the floor map of the app's *Explorer* tab; here it is drawn with
matplotlib into `singularity_map.png`, with the direct-singularity arcs and the stroke's edges on top.
"""

import matplotlib

matplotlib.use("Agg")  # draw into a file, no window
import matplotlib.pyplot as plt
import numpy as np

import tpm_viz as tv
from tpm_viz.paper.workspace import stroke_limit_loci, workspace_area

params = tv.Params.paper()
ws = tv.workspace_map(params, n=200)  # det_jx, cond, reachable, in_stroke on the grid xs × ys [m]
print(f"grid {ws.xs.size} × {ws.ys.size}, reachable {ws.reachable.mean():.0%} of it")
print(f"in-stroke workspace: {workspace_area(ws) * 1e4:.0f} cm²")
det = np.where(ws.reachable, ws.det_jx, np.nan)
print(f"det J_x in the stroke: {np.nanmin(np.where(ws.in_stroke, det, np.nan)):.3f} to {np.nanmax(det):.3f}")

fig, ax = plt.subplots(figsize=(6, 5))
extent = [ws.xs[0] * 1e3, ws.xs[-1] * 1e3, ws.ys[0] * 1e3, ws.ys[-1] * 1e3]
image = ax.imshow(det, origin="lower", extent=extent, cmap="RdBu", vmin=-1, vmax=1)
for arc in tv.direct_singularity_locus(params):  # (n, 2) [m] pieces of the circle |p| = l_a
    ax.plot(*(arc.T * 1e3), color="red", lw=2)
for edge in stroke_limit_loci(params):
    ax.plot(*(edge.T * 1e3), color="black", lw=0.8)
fig.colorbar(image, label="det J_x = cos(θ1 + θ2)")
ax.set(xlabel="p1 [mm]", ylabel="p2 [mm]", title="The paper's prototype: direct singularity (red)")
fig.savefig("singularity_map.png", dpi=100)
print("wrote singularity_map.png")
