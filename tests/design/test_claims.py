"""The claims docs/design.md makes about the two arrangements, checked by routes of their own: the perpendicular
machine's mirror symmetry (legs swapped when X and Y are), a scan of every placement of a turned task, the
stroke rule of the parallel arrangement written here (eq. P3), and a small-platform parallel design that fits the
perpendicular prototype's footprint."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.design.indices import Settings, Task, evaluate
from tpm_viz.paper.arrangement import Arrangement

ROOT = Path(__file__).resolve().parents[2]
PERP, PAR = Arrangement.PERPENDICULAR, Arrangement.PARALLEL
PAPER = Params.paper()
TASK = Task(-0.1, 0.1, -0.05, 0.05)
TURNED = Task(-0.05, 0.05, -0.1, 0.1)  # the same task a quarter turn round: its length along Y


def test_the_perpendicular_machine_picks_along_y_as_it_picks_along_x():
    """Swapping X and Y swaps the legs (same masses): the pick along Y of the turned task is the pick along X of
    the task, every index equal, footprint width and depth exchanged."""
    along_x = evaluate(PERP, PAPER, TASK)
    along_y = evaluate(PERP, PAPER, TURNED, Settings(pick="y"))
    assert along_x.feasible and along_y.feasible
    for name in ("gci", "cond_max", "dyn_mean", "dyn_max", "peak_force", "cycle_time"):
        assert getattr(along_y, name) == pytest.approx(getattr(along_x, name), rel=1e-9), name
    assert (along_y.footprint_x, along_y.footprint_y) == pytest.approx((along_x.footprint_y, along_x.footprint_x))
    with pytest.raises(InputError, match="x or y"):
        Settings(pick="z")


def _parallel_covers(params: Params, task: Task) -> bool:
    """Written here from docs/parallel.md: every pose of the task regular and in stroke for the parallel
    arrangement. Working mode: u = sqrt(l_a² - p_2²), tan θ_i = p_2 / u, d_1,2 = ±p_1 + a - b - u (eq. P3); the
    thresholds cos θ_i = u / l_a >= 0.2 (inverse) and |sin(θ_1 + θ_2)| = 2 |p_2| u / l_a² >= 0.2 (direct)."""
    ys = np.concatenate([np.linspace(task.y0, task.y1, 401), [0.0] if task.y0 < 0 < task.y1 else []])
    if np.any(np.abs(ys) >= params.l_a):
        return False
    u = np.sqrt(params.l_a**2 - ys**2)
    if np.any(u / params.l_a < 0.2) or np.any(2 * np.abs(ys) * u / params.l_a**2 < 0.2):
        return False
    k = params.a - params.b
    low = min(task.x0, -task.x1) + k - u.max()
    high = max(task.x1, -task.x0) + k - u.min()
    return bool(low >= 0 and high <= params.stroke)


@pytest.mark.slow  # about 20 s: 12,000 placements
def test_the_parallel_prototype_covers_no_placement_of_the_turned_task():
    """docs/design.md: clear of the direct singularity p_2 >= 26.1 mm, and both d_i within the stroke need
    u >= a - b + 50 mm - Δd = 140 mm, p_2 <= 219.1 mm: 193 mm of p_2 for the task's 200. Every centre scanned
    every 5 mm: neither this rule nor evaluate finds one; the task along X is covered by both."""
    p_low = np.sqrt((PAPER.l_a**2 - np.sqrt(PAPER.l_a**4 - 4 * (0.1 * PAPER.l_a**2) ** 2)) / 2)
    p_high = np.sqrt(PAPER.l_a**2 - (PAPER.a - PAPER.b + 0.05 - PAPER.stroke) ** 2)
    assert (p_low * 1e3, p_high * 1e3) == pytest.approx((26.1, 219.1), abs=0.05)
    covered = []
    for cx in np.arange(-0.3, 0.3001, 0.005):
        for cy in np.arange(-0.26, 0.2601, 0.005):
            if abs(cy) + 0.1 >= PAPER.l_a:
                continue
            placed = TURNED.centred_at(float(cx), float(cy))
            if _parallel_covers(PAPER, placed) or evaluate(PAR, PAPER, placed, Settings(pick="y")).feasible:
                covered.append((cx, cy))
    assert covered == []
    along_x = TASK.centred_at(0.0, 0.1)
    assert _parallel_covers(PAPER, along_x) and evaluate(PAR, PAPER, along_x).feasible


def test_a_small_platform_lets_a_parallel_design_fit_the_perpendicular_footprint():
    """The footprint proof holds b = 92 mm; with b = 41 mm this parallel design covers the task within the
    perpendicular prototype's 582 x 532 mm (docs/design.md quotes it)."""
    small = Params.paper(a=0.291, b=0.041, l_a=0.156, stroke=0.29)
    got = evaluate(PAR, small, Task(-0.1, 0.1, 0.044, 0.144))
    assert got.feasible, got.why
    assert got.footprint_x <= 0.582 + 1e-12 and got.footprint_y <= 0.532
    assert _parallel_covers(small, Task(-0.1, 0.1, 0.044, 0.144))
    prototype = evaluate(PERP, PAPER, TASK)
    assert (prototype.footprint_x, prototype.footprint_y) == pytest.approx((0.582, 0.532))
    assert math.isfinite(got.cycle_time)
    docs = " ".join((ROOT / "docs" / "design.md").read_text(encoding="utf-8").split())
    assert f"within 582 × {got.footprint_y * 1e3:.0f} mm, a pick cycle of {got.cycle_time * 1e3:.0f} ms" in docs
