"""How far the design studio's ``cycle_time`` (the toppra planner on a grid) is from the time-optimal cycle, found
here by an independent route: the reachability recursion of the phase plane (``x = ṡ²``, constant ``s̈`` per step,
the force limits ``|a_i s̈ + b_i x| <= F`` at every point, a backward pass of the largest ``x`` from which the path
can still stop, a forward pass of the largest acceleration within it), whose error falls as the step (30,000 and
60,000 steps per stroke, extrapolated: within 1e-6). The table of ``docs/design.md`` (*Accuracy*) is this test's
output."""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from tpm_viz.core.params import Params
from tpm_viz.design.indices import Settings, Task, evaluate, pick_path
from tpm_viz.paper import dynamics
from tpm_viz.paper.arrangement import Arrangement

ROOT = Path(__file__).resolve().parents[2]
TASK = Task(-0.1, 0.1, -0.05, 0.05)
GRIDS = (60, 100, 150, 300, 1000)
FORCE = 100.0


def time_optimal_stroke(params: Params, path, force: float, steps: int) -> float:
    """Minimum rest-to-rest time [s] along ``path`` with ``|τ_i| <= force`` (perpendicular arrangement)."""
    s = np.unique(np.concatenate([np.linspace(0.0, path.length, steps + 1), path.junctions]))
    steps, h_all = len(s) - 1, np.diff(s).tolist()
    p, dp, ddp = path.evaluate(s), path.evaluate(s, 1), path.evaluate(s, 2)
    a = dynamics.inverse_dynamics(params, p, np.zeros_like(p), dp)  # τ per unit s̈
    b = dynamics.inverse_dynamics(params, p, dp, ddp)  # τ per unit ṡ²
    assert np.all(np.abs(a) > 1e-9)  # both actuators move along this path: every bound is on s̈
    slope = -b / a  # s̈ bounds: lower_i = lo_i + slope_i x, upper_i = -lo_i + slope_i x
    lo = np.where(a > 0, -force / a, force / a)
    mvc = np.full(steps + 1, np.inf)  # where the two actuators' s̈ intervals stop overlapping
    for i, j in ((0, 1), (1, 0)):
        gap = slope[:, i] - slope[:, j]
        mvc = np.where(gap > 0, np.minimum(mvc, (-lo[:, j] - lo[:, i]) / np.where(gap > 0, gap, 1.0)), mvc)
    reach = np.zeros(steps + 1)  # largest x from which the path can still stop at its end
    lo_l, slope_l, mvc_l = lo.tolist(), slope.tolist(), mvc.tolist()
    for k in range(steps - 1, -1, -1):
        x, h = mvc_l[k], h_all[k]
        for i in (0, 1):
            den = 1.0 + 2.0 * h * slope_l[k][i]
            if den > 0:
                x = min(x, (reach[k + 1] - 2.0 * h * lo_l[k][i]) / den)
        reach[k] = max(x, 0.0)
    x = np.zeros(steps + 1)
    for k in range(steps):
        h = h_all[k]
        accel = min(-lo_l[k][i] + slope_l[k][i] * x[k] for i in (0, 1))
        x[k + 1] = max(min(x[k] + 2.0 * h * accel, reach[k + 1]), 0.0)
    root = np.sqrt(x)
    return float(np.sum(2.0 * np.diff(s) / (root[:-1] + root[1:])))


def reference_cycle(params: Params, path) -> float:
    """The time-optimal cycle [s] (there and back: twice the stroke), Richardson-extrapolated from 30,000 and 60,000
    steps (the recursion's error is first order in the step)."""
    coarse, fine = (time_optimal_stroke(params, path, FORCE, n) for n in (30_000, 60_000))
    assert abs(coarse / fine - 1) < 1e-4
    return 2.0 * (2.0 * fine - coarse)


def _designs() -> list[Params]:
    rng = np.random.default_rng(2)
    return [Params.paper()] + [
        Params.paper(l_a=float(rng.uniform(0.22, 0.28)), stroke=float(rng.uniform(0.28, 0.4))) for _ in range(4)
    ]


def test_the_reference_solver_converges_and_agrees_with_the_planner_on_a_fine_grid():
    path = pick_path(TASK)
    steps = (15_000, 30_000, 60_000)
    times = [2 * time_optimal_stroke(Params.paper(), path, FORCE, n) for n in steps]
    assert times[0] < times[1] < times[2]  # first order in the step: each halving gains half as much as the last
    assert (times[2] - times[1]) / (times[1] - times[0]) == pytest.approx(0.5, abs=0.05)
    best = 2 * times[2] - times[1]
    planner = evaluate(Arrangement.PERPENDICULAR, Params.paper(), TASK, Settings(planner_grid=2000), True)
    assert best < planner.cycle_time < best * (1 + 1e-3)  # the planner keeps the limits: never faster
    docs = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    quoted = float(docs.split("the planner itself at 2000 points, which is ")[1].split(" ")[0])
    assert quoted == pytest.approx(planner.cycle_time / best - 1, rel=0.05)


@pytest.mark.slow  # about 30 s: five designs, five planner grids, the reference on 30,000 and 60,000 steps each
def test_the_accuracy_table_of_the_docs_is_measured():
    path = pick_path(TASK)
    errors = {g: [] for g in GRIDS}
    for params in _designs():
        best = reference_cycle(params, path)
        for g in GRIDS:
            got = evaluate(Arrangement.PERPENDICULAR, params, TASK, Settings(planner_grid=g), True).cycle_time
            assert got >= best * (1 - 1e-6)
            errors[g].append(got / best - 1)
    docs = (ROOT / "docs" / "design.md").read_text(encoding="utf-8")
    line = next(x for x in docs.splitlines() if x.startswith("| largest relative error of `cycle_time` |"))
    printed = [float(v) for v in re.findall(r"\d\.\de-\d+", line)]
    measured = [max(errors[g]) for g in GRIDS]
    assert len(printed) == len(GRIDS)
    for g, shown, value in zip(GRIDS, printed, measured, strict=True):
        assert shown == pytest.approx(value, rel=0.05), (g, shown, f"{value:.1e}")
    prototype = docs.split("the paper's prototype: ")[1].split()[0]  # the prototype's own error at 300 points
    assert float(prototype) == pytest.approx(errors[300][0], rel=0.05), f"{errors[300][0]:.1e}"
