"""Motor sizing against hand formulas (a point mass on a trapezoidal velocity profile) and energy balance."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import tpm_viz as tv
from tests.support.hypo import examples
from tpm_viz.app import paths, planner
from tpm_viz.app.sizing import SIZING_COLUMNS, format_sizing, size_motion, size_trajectory, sizing_columns
from tpm_viz.core.errors import InputError
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces
from tpm_viz.paper.trajectories import paper_trajectory

P = tv.Params.paper()


def trapezoid(m: float, acc: float, v: float, cruise: float, k: int = 7):
    """A point mass ``m`` [kg]: accelerate at ``acc`` to ``v``, cruise ``cruise`` [s], brake at ``acc``.

    Samples ``k`` per phase; the switching instants appear twice (force before and after the step).
    Actuator 2 carries the same motion scaled by -2 (mass 2 m, velocity -v): every figure doubles or quadruples.
    """
    ta = v / acc
    t_acc = np.linspace(0.0, ta, k)
    t_cru = np.linspace(ta, ta + cruise, k)
    t_brk = np.linspace(ta + cruise, 2 * ta + cruise, k)
    t = np.concatenate([t_acc, t_cru, t_brk])
    vel = np.concatenate([acc * t_acc, np.full(k, v), v - acc * (t_brk - ta - cruise)])
    force = np.concatenate([np.full(k, m * acc), np.zeros(k), np.full(k, -m * acc)])
    tau = np.stack([force, 2 * force], -1)
    dd = np.stack([vel, -vel], -1)
    return t, tau, dd, ta


@settings(max_examples=examples(60), deadline=None)
@given(
    m=st.floats(0.1, 20.0),
    acc=st.floats(0.5, 50.0),
    v=st.floats(0.05, 3.0),
    cruise=st.floats(0.0, 1.0),
    dwell=st.floats(0.0, 2.0),
    km=st.floats(1.0, 100.0),
)
def test_point_mass_trapezoid_matches_hand_formulas(m, acc, v, cruise, dwell, km):
    t, tau, dd, ta = trapezoid(m, acc, v, cruise)
    size = size_motion(t, tau, dd, dwell=dwell, motor_constant=km)
    motion = 2 * ta + cruise
    cycle = motion + dwell
    f = m * acc
    scale_f = np.array([1.0, 2.0])  # actuator 2: twice the force, same speed
    exact = {
        "cycle_time": cycle,
        "motion_time": motion,
        "peak_force": f * scale_f,
        "rms_force": f * scale_f * math.sqrt(2 * ta / cycle),
        "peak_power": f * v * scale_f,  # at the end of the acceleration
        "energy": 0.5 * m * v**2 * scale_f,  # the kinetic energy given by the drive
        "braking_energy": 0.5 * m * v**2 * scale_f,  # and taken back while braking
        "mean_power": 0.5 * m * v**2 * scale_f / cycle,
        "peak_actuator_speed": np.array([v, v]),
        "peak_copper_loss": (f * scale_f) ** 2 / km**2,
        "mean_copper_loss": (f * scale_f) ** 2 * 2 * ta / cycle / km**2,
        "copper_energy": (f * scale_f) ** 2 * 2 * ta / km**2,
    }
    for name, value in exact.items():
        got = getattr(size, name)
        assert np.allclose(got, value, rtol=1e-9, atol=1e-12), name


def test_power_changing_sign_inside_an_interval_is_split_at_the_zero():
    # constant force 2 N, velocity from -1 to +3 m/s over 1 s: P = 2 v, positive part ∫ = 2 * (3 * 0.75 / 2)
    size = size_motion([0.0, 1.0], [[2.0, 0.0], [2.0, 0.0]], [[-1.0, 0.0], [3.0, 0.0]])
    assert size.energy[0] == pytest.approx(2 * 3 * 0.75 / 2, abs=1e-12)
    assert size.braking_energy[0] == pytest.approx(2 * 1 * 0.25 / 2, abs=1e-12)
    # a linear force: ∫ τ² of a line from 0 to 3 N over 2 s = 9 * 2 / 3
    lin = size_motion([0.0, 2.0], [[0.0, 0.0], [3.0, 0.0]], np.zeros((2, 2)))
    assert lin.rms_force[0] == pytest.approx(math.sqrt(6.0 / 2.0), abs=1e-12)


def test_a_planned_rest_to_rest_motion_gives_back_all_the_energy_it_put_in():
    plan = planner.plan_path(P, paths.path_for(P, "line"), planner.Limits(100.0))
    smp = plan.sample(np.linspace(0.0, plan.duration, 20001))
    size = size_trajectory(P, smp.t, smp.p, smp.dp, smp.ddp, dwell=0.3, motor_constant=20.0)
    kinetic = tv.kinetic_energy(P, smp.p, smp.dp)  # the paper's eqs. (20)-(22), an independent route
    net = np.sum(size.energy) - np.sum(size.braking_energy)
    assert abs(net) < 1e-3 * np.sum(size.energy)  # no gravity, no friction: the cycle's net work is zero
    assert np.sum(size.energy) >= kinetic.max() * (1 - 1e-3)  # at least the peak kinetic energy went in
    assert np.max(size.peak_force) == pytest.approx(100.0, rel=0.01)
    assert size.peak_platform_speed == pytest.approx(np.max(np.hypot(*smp.dp.T)), rel=1e-12)
    assert size.cycle_time == pytest.approx(plan.duration + 0.3)


def test_the_papers_cubic_circle_sized_against_the_independent_model():
    traj = paper_trajectory("circle", duration=0.5, samples=2001)
    size = size_trajectory(P, traj.t, traj.p, traj.dp, traj.ddp, dwell=0.5)
    ref = pinocchio_forces(P, traj.p, traj.dp, traj.ddp)
    assert np.allclose(size.peak_force, np.max(np.abs(ref), axis=0), rtol=1e-9)
    rms = np.sqrt(np.trapezoid(ref**2, traj.t, axis=0) / 1.0)
    assert np.allclose(size.rms_force, rms, rtol=1e-4)  # trapezoid vs piecewise-linear force: close, not equal
    dd = tv.actuator_velocity(P, traj.p, traj.dp)
    assert np.allclose(size.peak_actuator_speed, np.max(np.abs(dd), axis=0), rtol=1e-12)


def test_the_dwell_dilutes_rms_and_means_but_not_peaks():
    t, tau, dd, _ = trapezoid(2.0, 10.0, 1.0, 0.2)
    busy, idle = size_motion(t, tau, dd), size_motion(t, tau, dd, dwell=0.6)
    ratio = busy.cycle_time / idle.cycle_time
    assert np.allclose(idle.rms_force**2, busy.rms_force**2 * ratio, rtol=1e-12)
    assert np.allclose(idle.mean_power, busy.mean_power * ratio, rtol=1e-12)
    assert np.array_equal(idle.peak_force, busy.peak_force)
    assert np.array_equal(idle.energy, busy.energy)


def test_table_rows_text_and_csv_columns():
    t, tau, dd, _ = trapezoid(1.0, 5.0, 0.5, 0.1)
    size = size_motion(t, tau, dd, dwell=0.1, motor_constant=10.0)
    names = [r[0] for r in size.rows()]
    for name in ("peak force", "RMS force", "peak mechanical power", "energy per cycle", "mean copper loss"):
        assert name in names
    text = format_sizing(size)
    assert len(text.splitlines()) == len(names) + 1
    cols = sizing_columns(size)
    assert list(cols) == SIZING_COLUMNS
    assert cols["actuator2"][names.index("peak force")] == pytest.approx(10.0)
    assert "copper" not in format_sizing(size_motion(t, tau, dd))


@pytest.mark.parametrize(
    "kwargs, match",
    [
        ({"t": [0.0, 1.0, 0.5]}, "must not decrease"),
        ({"t": [0.0, 0.0, 0.0]}, "longer than zero"),
        ({"tau": np.zeros((3, 3))}, "need t"),
        ({"tau": np.full((3, 2), np.nan)}, "non-finite"),
        ({"dwell": -1.0}, "dwell"),
        ({"motor_constant": 0.0}, "motor constant"),
        ({"dp": np.zeros((2, 2))}, "platform velocity"),
    ],
)
def test_bad_input_is_refused_with_one_line(kwargs, match):
    args = {"t": [0.0, 0.5, 1.0], "tau": np.zeros((3, 2)), "dd": np.zeros((3, 2))} | kwargs
    with pytest.raises(InputError, match=match) as err:
        size_motion(**args)
    assert "\n" not in str(err.value)
