"""Design indices (tpm_viz/design/indices.py) against independent routes: brute-force grids with Jacobians written
here from the kinematics (eq. 10 and the parallel J of issue 26), the mass matrix from the kinetic energy, the
mechanism's own joint positions, the cubic law's own sizing and the scaling law of minimum time."""

from __future__ import annotations

import math
import pickle
import tomllib
from pathlib import Path

import numpy as np
import pytest

from tpm_viz.app.planner import Limits, plan_cycle, plan_path
from tpm_viz.app.planning import cubic_strokes
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, say
from tpm_viz.design import indices
from tpm_viz.design.indices import Settings, Task, area_means, evaluate, footprint, pick_path, pointwise, task_grid
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.paper.dynamics import inverse_dynamics

PERP, PAR = Arrangement.PERPENDICULAR, Arrangement.PARALLEL
PAPER = Params.paper()
TASK = Task(-0.1, 0.1, -0.05, 0.05)
PAR_TASK = Task(-0.1, 0.1, 0.05, 0.15)  # above the rails, clear of p2 = 0


def _j_perpendicular(p: np.ndarray, l_a: float) -> np.ndarray:
    """Eq. (10) in the working mode: J = [[1, p2/sqrt(l²-p2²)], [p1/sqrt(l²-p1²), 1]]."""
    t1 = p[:, 1] / np.sqrt(l_a**2 - p[:, 1] ** 2)
    t2 = p[:, 0] / np.sqrt(l_a**2 - p[:, 0] ** 2)
    one = np.ones(len(p))
    return np.stack([np.stack([one, t1], -1), np.stack([t2, one], -1)], -2)


def _midpoints(task: Task, n: int) -> np.ndarray:
    xs = task.x0 + (np.arange(n) + 0.5) * task.width / n
    ys = task.y0 + (np.arange(n) + 0.5) * task.height / n
    return np.stack(np.meshgrid(xs, ys, indexing="ij"), -1).reshape(-1, 2)


def test_gci_of_the_perpendicular_design_matches_a_brute_force_grid():
    got = evaluate(PERP, PAPER, TASK)
    assert got.feasible
    p = _midpoints(TASK, 700)
    brute = float(np.mean(1.0 / np.linalg.cond(_j_perpendicular(p, PAPER.l_a))))
    assert got.gci == pytest.approx(brute, rel=1e-3)


def test_gci_of_the_parallel_design_is_the_mean_of_min_p2_over_u_and_its_inverse():
    """cond(J) = max(p2/u, u/p2) for J = [[1, p2/u], [-1, p2/u]] (its columns are orthogonal)."""
    got = evaluate(PAR, PAPER, PAR_TASK)
    assert got.feasible
    p = _midpoints(PAR_TASK, 700)
    u = np.sqrt(PAPER.l_a**2 - p[:, 1] ** 2)
    brute = float(np.mean(np.minimum(p[:, 1] / u, u / p[:, 1])))
    assert got.gci == pytest.approx(brute, rel=1e-3)
    y = np.linspace(PAR_TASK.y0, PAR_TASK.y1, 20001)
    uy = np.sqrt(PAPER.l_a**2 - y**2)
    assert got.cond_max == pytest.approx(float(np.max(np.maximum(y / uy, uy / y))), rel=1e-6)


def test_worst_condition_number_and_dynamic_index_match_a_fine_grid():
    got = evaluate(PERP, PAPER, TASK)
    p = _midpoints(TASK, 600)
    p = np.concatenate([p, [[x, y] for x in (TASK.x0, TASK.x1) for y in (TASK.y0, TASK.y1)]])
    cond = np.linalg.cond(_j_perpendicular(p, PAPER.l_a))
    assert got.cond_max == pytest.approx(float(cond.max()), rel=1e-5)
    assert got.cond_max >= float(cond.max()) * (1 - 1e-12)
    dyn = np.linalg.svd(arr.force_per_acceleration(PERP, PAPER, p), compute_uv=False)[:, 0]
    assert got.dyn_max == pytest.approx(float(dyn.max()), rel=1e-5)
    assert got.dyn_mean == pytest.approx(float(np.mean(dyn[:-4])), rel=1e-3)


@pytest.mark.parametrize("arrangement", list(Arrangement))
def test_the_dynamic_index_is_the_force_of_the_mass_matrix_of_the_kinetic_energy(arrangement):
    """J⁻ᵀ M(p) from the closed-form inverse dynamics equals J⁻ᵀ M with M read off the kinetic energy
    (M_kk = 2 K(e_k), M_12 = K(e_1 + e_2) - K(e_1) - K(e_2))."""
    params = PAPER
    task = TASK if arrangement is PERP else PAR_TASK
    rng = np.random.default_rng(7)
    p = np.column_stack([rng.uniform(task.x0, task.x1, 20), rng.uniform(task.y0, task.y1, 20)])
    e1, e2 = np.array([1.0, 0.0]), np.array([0.0, 1.0])

    def energy(v):
        return arr.kinetic_energy(arrangement, params, p, np.broadcast_to(v, p.shape))

    k1, k2, k12 = energy(e1), energy(e2), energy(e1 + e2)
    m = np.stack([np.stack([2 * k1, k12 - k1 - k2], -1), np.stack([k12 - k1 - k2, 2 * k2], -1)], -2)
    j = arr.jacobians(arrangement, params, p).j
    expected = np.linalg.solve(np.swapaxes(j, -1, -2), m)
    got = pointwise(arrangement, params, p)
    assert np.allclose(got[:, 1], np.linalg.svd(expected, compute_uv=False)[:, 0], rtol=1e-9)
    assert np.allclose(got[:, 0], 1.0 / np.linalg.cond(j), rtol=1e-9)


def test_area_means_reach_the_stated_tolerance_on_a_known_integral():
    """Mean of |x|·y² + cos(9 y) over [-1, 2] x [0, 1] (a kink at x = 0, off the panel edges)."""
    task = Task(-1.0, 2.0, 0.0, 1.0)
    means, panels = area_means(lambda p: (np.abs(p[:, 0]) * p[:, 1] ** 2 + np.cos(9 * p[:, 1]))[:, None], task)
    exact = ((0.5 + 2.0) / 3.0) * (1.0 / 3.0) + math.sin(9.0) / 9.0
    assert means[0] == pytest.approx(exact, rel=1e-3)
    assert panels >= 2


def test_an_infeasible_task_has_no_numbers():
    got = evaluate(PAR, PAPER, TASK)  # crosses p2 = 0, the parallel arrangement's direct singularity
    assert not got.feasible and "direct singularity" in str(got.why)
    assert all(math.isnan(v) for k, v in got.row().items() if k != "feasible")
    too_big = evaluate(PERP, PAPER, Task(-0.3, 0.3, -0.1, 0.1))
    assert not too_big.feasible and all(math.isnan(v) for k, v in too_big.row().items() if k != "feasible")
    invalid = evaluate(PAR, Params.paper(a=0.05, b=0.092, l_a=0.1), PAR_TASK)  # a < b: no pose in the stroke
    assert not invalid.feasible and "a − b > 0" in str(invalid.why)


def test_an_infeasible_design_says_why_in_each_language_and_keeps_it_across_processes():
    """The reason is a phrase: English in the CSV (``str``), the tab's language on screen, intact after pickling (a
    design row crosses to a worker process). Korean checked against the catalogue file read here, not the code."""
    ko = tomllib.loads((Path(__file__).parents[2] / "assets" / "words" / "ko.toml").read_text("utf-8"))
    got = evaluate(PERP, PAPER, Task(-0.2, 0.2, -0.2, 0.2))  # its corner is out of stroke
    english = str(got.why)
    assert english.startswith("the task is not covered: (") and english.endswith(") mm is out of stroke")
    korean = say(Lang.KO, got.why)
    assert ko["out of stroke"] in korean and korean.startswith(
        ko["the task is not covered: ({x:.1f}, {y:.1f}) mm is {status}"][:8]
    )
    assert not any(word in korean for word in ("task", "covered", "stroke"))
    back = pickle.loads(pickle.dumps(got))
    assert say(Lang.KO, back.why) == korean and str(back.why) == english


def test_feasibility_agrees_with_a_dense_check_of_the_task():
    for arrangement, task in ((PERP, TASK), (PAR, PAR_TASK), (PAR, Task(-0.1, 0.1, 0.02, 0.12))):
        dense = _midpoints(task, 400)
        status = arr.classify(arrangement, PAPER, dense)
        assert evaluate(arrangement, PAPER, task).feasible == bool(np.all(status == 0))


@pytest.mark.parametrize("arrangement", list(Arrangement))
def test_footprint_is_the_bounding_box_of_the_rails_and_the_drawn_legs(arrangement):
    task = TASK if arrangement is PERP else PAR_TASK
    pts = []
    for p in _midpoints(task, 30).tolist() + [[x, y] for x in (task.x0, task.x1) for y in (task.y0, task.y1)]:
        pose = arr.mechanism_pose(arrangement, PAPER, np.array(p))
        pts += [pose.links[i, 0, k] for i in range(2) for k in range(2)]
    for d in ((0.0, 0.0), (PAPER.stroke, PAPER.stroke)):  # rail ends: A_i at d_i = 0 and Δd
        p_any = np.array([0.0, 0.0]) if arrangement is PERP else arr.home(PAR, PAPER)
        pose = arr.mechanism_pose(arrangement, PAPER, p_any, np.array(d))
        pts += list(pose.A)
    pts = np.array(pts)
    width, depth = footprint(arrangement, PAPER, task_grid(task))
    assert width == pytest.approx(float(np.ptp(pts[:, 0])), abs=1e-4)
    assert depth == pytest.approx(float(np.ptp(pts[:, 1])), abs=1e-4)


def test_peak_force_is_the_cubic_law_at_the_reference_stroke_sampled_densely():
    """The paper's eqs. (29)-(31) along s = L (3u² - 2u³) at 400 001 instants (either side of a corner)."""
    got = evaluate(PERP, PAPER, TASK)
    path, duration = pick_path(TASK), indices.REFERENCE_STROKE
    length = path.length
    u = np.linspace(0.0, 1.0, 400001)
    s = length * (3 * u**2 - 2 * u**3)
    ds, dds = length * (6 * u - 6 * u**2) / duration, length * (6 - 12 * u) / duration**2
    peak = 0.0
    for side in ("left", "right"):
        ps, pss = path.evaluate(s, 1), path.evaluate(s, 2, side)
        tau = inverse_dynamics(PAPER, path.evaluate(s), ps * ds[:, None], ps * dds[:, None] + pss * (ds**2)[:, None])
        peak = max(peak, float(np.max(np.abs(tau))))
    assert got.peak_force == pytest.approx(peak, rel=1e-3)
    slower, _ = cubic_strokes(PAPER, (path,), got.peak_force / 4.0)  # the planner tab's cubic law: τ ∝ 1/T²
    assert slower == pytest.approx(2 * duration, rel=0.02)  # its 201 samples see the corners less sharply


def test_cycle_time_is_the_planners_cycle_and_scales_as_one_over_root_force():
    path = pick_path(TASK)
    cycle = plan_cycle(PAPER, path, Limits(100.0)).duration
    got = evaluate(PERP, PAPER, TASK)
    assert got.cycle_time == pytest.approx(cycle, rel=1e-4)
    fast = evaluate(PERP, PAPER, TASK, Settings(force_limit=400.0))
    assert got.cycle_time / fast.cycle_time == pytest.approx(2.0, rel=1e-4)  # τ ∝ 1/T²: T ∝ F^(-1/2)


def test_the_planner_times_a_parallel_path_within_its_own_force_limit():
    path = pick_path(PAR_TASK)
    plan = plan_path(PAPER, path, Limits(80.0), arrangement=PAR)
    samples = plan.samples(1000.0)  # the rate at which the planner checks its forces
    assert plan.arrangement is PAR
    assert np.max(np.abs(samples.tau)) <= 80.0 * (1 + 1e-3)  # checked at 1 kHz by the planner, not at these ticks
    assert np.max(np.abs(samples.tau)) >= 80.0 * 0.99  # bang-bang: the limit is reached
    tau = arr.inverse_dynamics(PAR, PAPER, samples.p, samples.dp, samples.ddp)
    assert np.allclose(samples.tau, tau)
    perp = plan_path(PAPER, pick_path(TASK), Limits(80.0))
    assert perp.arrangement is PERP


def test_task_text_is_refused_in_one_line():
    with pytest.raises(ValueError, match="four numbers"):
        Task.parse("0,1,2")
    with pytest.raises(ValueError, match="X0 < X1"):
        Task.parse("0.1,-0.1,0,1")
    with pytest.raises(ValueError, match="finite"):
        Task.parse("nan,1,0,1")
