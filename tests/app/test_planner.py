"""The time-optimal planner: limits checked by an independent model, bang-bang, time scaling, optimality.

Independent routes: forces are recomputed from the planned ``p, ṗ, p̈`` by the Pinocchio closed-loop model
(:func:`tpm_viz.multibody.inverse_dynamics`); ``ṗ, p̈`` against finite differences of ``p``; the minimum time
against a phase-plane integration written here (Bobrow-style: accelerate as hard as the forces allow from the
start, brake as hard as they allow into the end); the paper's cubic law scaled to the same peak force.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

import tpm_viz as tv
from tests.support.hypo import examples
from tests.support.strategies import params_sets
from tpm_viz.app import paths, planner
from tpm_viz.core.errors import InputError
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces
from tpm_viz.paper.trajectories import paper_trajectory

P = tv.Params.paper()
F_MAX = 100.0


@pytest.fixture(scope="module")
def plans() -> dict[str, planner.Plan]:
    limits = planner.Limits(F_MAX)
    out = {kind: planner.plan_path(P, paths.path_for(P, kind), limits) for kind in ("line", "circle")}
    out["pick"] = planner.plan_cycle(P, paths.path_for(P, "pick"), limits)
    return out


def resample_1khz(plan: planner.Plan):
    """States every 1 ms, offset by 0.37 ms so that the times differ from the planner's own check."""
    return plan.sample(np.arange(0.37e-3, plan.duration, 1e-3))


@pytest.mark.parametrize("kind", ["line", "circle", "pick"])
def test_pinocchio_forces_never_exceed_the_limit_by_more_than_one_percent(plans, kind):
    smp = resample_1khz(plans[kind])
    tau = pinocchio_forces(P, smp.p, smp.dp, smp.ddp)
    assert np.max(np.abs(tau)) <= 1.01 * F_MAX
    assert np.max(np.abs(tau - smp.tau)) < 1e-6 * F_MAX  # the plan's own forces are the model's


@pytest.mark.parametrize("kind", ["line", "circle", "pick"])
def test_bang_bang_every_accelerating_or_braking_stretch_reaches_the_limit(plans, kind):
    smp = resample_1khz(plans[kind])
    load = np.max(np.abs(pinocchio_forces(P, smp.p, smp.dp, smp.ddp)), axis=1) / F_MAX
    sign = np.sign(smp.dds)
    edges = np.flatnonzero((np.diff(sign) != 0) | (np.diff(smp.move) != 0)) + 1
    for stretch in np.split(np.arange(len(sign)), edges):
        if sign[stretch[0]] != 0:
            assert load[stretch].max() >= 0.98, f"stretch at t = {smp.t[stretch[0]]:.4f} s"
    assert np.mean(load >= 0.98) >= 0.95  # and at (nearly) every instant, not only at one peak


@pytest.mark.parametrize("kind", ["line", "circle", "pick"])
def test_velocities_and_accelerations_match_finite_differences_of_the_positions(plans, kind):
    plan, h = plans[kind], 1e-6
    t = np.linspace(0.01, plan.duration - 0.01, 301)
    t = t[np.min(np.abs(t[:, None] - plan.starts[None, :]), axis=1) > 2 * h]
    mid, ahead, back = plan.sample(t), plan.sample(t + h), plan.sample(t - h)
    assert np.allclose((ahead.p - back.p) / (2 * h), mid.dp, atol=1e-6)
    smooth = np.abs(ahead.dds - back.dds) < 1e-9  # away from the switches of the piecewise-constant s̈
    assert smooth.mean() > 0.8
    assert np.allclose(((ahead.dp - back.dp) / (2 * h))[smooth], mid.ddp[smooth], atol=1e-4)


@pytest.mark.parametrize("kind", ["line", "circle", "pick"])
def test_quadrupling_the_force_limit_halves_the_cycle_time(plans, kind):
    solve = planner.plan_cycle if kind == "pick" else planner.plan_path
    fast = solve(P, paths.path_for(P, kind), planner.Limits(4 * F_MAX))
    assert fast.duration == pytest.approx(plans[kind].duration / 2, rel=0.01)


def _cubic_time_at_peak(kind: str, force: float) -> float:
    """Duration [s] of the paper's cubic law whose peak actuator force is ``force`` (``τ ∝ 1/T²``)."""
    traj = paper_trajectory(kind, duration=1.0, samples=4001)
    peak = np.max(np.abs(pinocchio_forces(P, traj.p[::4], traj.dp[::4], traj.ddp[::4])))
    return math.sqrt(peak / force)


@pytest.mark.parametrize("kind", ["line", "circle"])
def test_the_plan_is_never_slower_than_the_papers_cubic_law_at_the_same_peak_force(plans, kind):
    assert plans[kind].duration < _cubic_time_at_peak(kind, F_MAX)


def test_the_pick_stroke_is_faster_than_the_cubic_law_along_the_same_path(plans):
    path = plans["pick"].paths[0]
    tau_n = np.linspace(0.0, 1.0, 1001)  # the paper's time law on the arc length, T = 1 s
    s, ds, dds = (
        path.length * (3 * tau_n**2 - 2 * tau_n**3),
        path.length * (6 * tau_n - 6 * tau_n**2),
        path.length * (6 - 12 * tau_n),
    )
    p = path.evaluate(s)
    dp = path.evaluate(s, 1) * ds[:, None]
    ddp = path.evaluate(s, 1) * dds[:, None] + path.evaluate(s, 2) * (ds**2)[:, None]
    peak = np.max(np.abs(pinocchio_forces(P, p, dp, ddp)))
    assert plans["pick"].move_durations[0] < math.sqrt(peak / F_MAX)


def test_a_path_outside_the_valid_region_is_refused_before_planning():
    with pytest.raises(InputError, match=r"leaves the valid region at \(170\.\d, 0\.0\) mm"):
        planner.plan_path(P, paths.waypoint_path([(0.0, 0.0), (0.25, 0.0)]), planner.Limits(F_MAX))


def _phase_plane_time(path: paths.GeometricPath, force: float, n: int = 4001) -> float:
    """Minimum time by integrating ``dx/ds = 2 s̈`` (``x = ṡ²``) at the extreme feasible ``s̈`` both ways.

    Valid where the maximum-velocity curve is never reached (true for the line): then the optimum is one
    acceleration arc from the start met by one braking arc into the end.
    """
    s_coarse = np.linspace(0.0, path.length, 201)
    p, ps, pss = path.evaluate(s_coarse), path.evaluate(s_coarse, 1), path.evaluate(s_coarse, 2)
    a_c = pinocchio_forces(P, p, np.zeros_like(p), ps)
    b_c = pinocchio_forces(P, p, ps, pss)
    s = np.linspace(0.0, path.length, n)
    a = np.stack([np.interp(s, s_coarse, a_c[:, i]) for i in range(2)], -1)
    b = np.stack([np.interp(s, s_coarse, b_c[:, i]) for i in range(2)], -1)

    def extreme(k, x, pick):
        lo, hi = (-force - b[k] * x) / a[k], (force - b[k] * x) / a[k]
        upper = np.where(a[k] > 0, hi, lo)
        lower = np.where(a[k] > 0, lo, hi)
        return np.min(upper) if pick == "max" else np.max(lower)

    fwd, bwd = np.zeros(n), np.zeros(n)
    for k in range(n - 1):  # forward at full acceleration (Heun's method in s)
        h = s[k + 1] - s[k]
        pred = fwd[k] + 2 * h * extreme(k, fwd[k], "max")
        fwd[k + 1] = fwd[k] + h * (extreme(k, fwd[k], "max") + extreme(k + 1, pred, "max"))
    for k in range(n - 1, 0, -1):  # backward at full braking
        h = s[k] - s[k - 1]
        pred = bwd[k] - 2 * h * extreme(k, bwd[k], "min")
        bwd[k - 1] = bwd[k] - h * (extreme(k, bwd[k], "min") + extreme(k - 1, pred, "min"))
    v = np.sqrt(np.maximum(np.minimum(fwd, bwd), 0.0))
    return float(np.sum(2 * np.diff(s) / (v[1:] + v[:-1])))


def test_the_line_takes_the_minimum_time_of_an_independent_phase_plane_integration(plans):
    assert plans["line"].duration == pytest.approx(_phase_plane_time(paths.line_path(), F_MAX), rel=0.005)


def test_the_back_stroke_of_a_pick_cycle_takes_as_long_as_the_forward_stroke(plans):
    # no friction: tau(p, -dp, ddp) = tau(p, dp, ddp), so the back stroke is the forward one reversed in time
    forward, back = plans["pick"].move_durations
    assert back == pytest.approx(forward, rel=2e-3)
    smp = plans["pick"].samples()
    assert np.allclose(smp.p[0], smp.p[-1], atol=1e-12)  # a closed cycle


@pytest.mark.parametrize("kind", ["line", "circle", "pick"])
def test_rest_to_rest_along_the_path(plans, kind):
    plan = plans[kind]
    smp = plan.sample(np.concatenate([plan.starts, [plan.duration]]))
    assert np.allclose(smp.ds[[0, -1]], 0.0, atol=1e-9)
    path = plan.paths[0]
    assert np.allclose(smp.p[0], path.evaluate(0.0), atol=1e-12)
    assert np.all(np.diff(plan.samples().s[plan.samples().move == 0]) >= -1e-12)  # never backwards


def test_speed_limits_hold_and_cost_time():
    path = paths.path_for(P, "circle")
    free = planner.plan_path(P, path, planner.Limits(F_MAX))
    capped = planner.plan_path(P, path, planner.Limits(F_MAX, speed=1.0, actuator_speed=1.1))
    smp = capped.sample(np.arange(0.0, capped.duration, 2e-4))
    assert np.max(np.hypot(smp.dp[:, 0], smp.dp[:, 1])) <= 1.0 * (1 + 1e-9)
    assert np.max(np.abs(smp.dd)) <= 1.1 * 1.01
    assert np.max(np.abs(pinocchio_forces(P, smp.p[::10], smp.dp[::10], smp.ddp[::10]))) <= 1.01 * F_MAX
    assert capped.duration > free.duration
    # cruising at the speed cap for most of the circle: the time is close to length / v_max
    assert capped.duration == pytest.approx(path.length / 1.0, rel=0.1)


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"force": 0.0}, "force limit"),
        ({"force": float("nan")}, "force limit"),
        ({"force": 10.0, "speed": -1.0}, "speed limit"),
        ({"force": 10.0, "actuator_speed": "fast"}, "actuator speed limit"),
    ],
)
def test_bad_limits_are_refused_with_one_line(kwargs, match):
    with pytest.raises(InputError, match=match) as err:
        planner.Limits(**kwargs)
    assert "\n" not in str(err.value)


@pytest.mark.parametrize("grid", [0, 5, 2.5, True, 10**6])
def test_bad_grids_are_refused(grid):
    with pytest.raises(InputError, match="grid"):
        planner.plan_path(P, paths.line_path(), planner.Limits(F_MAX), grid=grid)


@settings(max_examples=examples(12), deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(params=params_sets(), force=st.floats(5.0, 2000.0), seed=st.integers(0, 2**16))
def test_random_parameters_default_pick_within_the_limit(params, force, seed):
    try:
        path = paths.path_for(params, "pick")
    except InputError:
        return  # no valid workspace for these parameters: refused, as it should be
    plan = planner.plan_cycle(params, path, planner.Limits(force), grid=150)
    rng = np.random.default_rng(seed)
    smp = plan.sample(rng.uniform(0.0, plan.duration, 200))
    tau = tv.inverse_dynamics(params, smp.p, smp.dp, smp.ddp)
    assert np.max(np.abs(tau)) <= 1.01 * force
