"""Control lab (issue 14): sampled controllers drive the Pinocchio closed-loop model.

Independent routes only: the reduced plant against the KKT forward dynamics and Pinocchio's closures;
the computed-torque error against the analytic solution of ë + 2ζω ė + ω² e = 0; the actuator work
against the kinetic energy of rigid bodies (tests/support/reference.py, no tpm_viz dynamics).
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tpm_viz as tv
from tests.support.reference import ik_quadratic, rod_kinetic_energy
from tpm_viz.multibody import model_for
from tpm_viz.multibody.control import COLUMNS, ControlRun, ControlSetup, simulate
from tpm_viz.multibody.forward import PlatformPlant
from tpm_viz.paper.control import Gains

P = tv.Params.paper()


@pytest.mark.parametrize("seed", range(4))
def test_reduced_plant_is_the_constrained_multibody_dynamics(seed):
    rng = np.random.default_rng(seed)
    params = P if seed < 2 else P.replace(m_p=3.5, m_b=1.2, l_a=0.3)
    model = model_for(params)
    plant = PlatformPlant(model)
    p, dp, tau = rng.uniform(-0.12, 0.12, 2), rng.normal(0, 1.5, 2), rng.normal(0, 80, 2)
    q, v, _ = plant.joint_state(p, dp)
    assert model.constraint_violation(q) < 1e-14  # q(p) closes Pinocchio's loops
    assert model.platform_position(q) == pytest.approx(p, abs=1e-15)
    jc = model.closure_terms(q)[1]
    n = plant.null_space(p)
    assert np.max(np.abs(jc @ n)) < 1e-13 and np.linalg.matrix_rank(n) == 2  # admissible motions
    assert np.max(np.abs(jc @ v)) < 1e-13
    ddp = np.array(plant.acceleration(*p, *dp, *tau))
    a = plant.joint_state(p, dp, ddp)[2]
    kkt = model.forward_dynamics(q, v, tau)  # the replay's SVD/KKT route
    assert np.max(np.abs(a - kkt)) < 1e-9 * (1 + np.max(np.abs(kkt)))


def test_computed_torque_with_an_exact_model_tracks_the_circle_to_a_micrometre():
    # With an exact model the only error left is the zero-order hold: τ held over one period lags the
    # continuous law; the error is then ~ p⃛ h / (2 ω²), so it halves when the rate doubles.
    runs = [simulate(P, "circle", ControlSetup(rate=rate, gains=Gains(50.0, 1.0))) for rate in (1e4, 2e4)]
    assert runs[0].t[-1] == pytest.approx(0.5) and len(runs[0].t) == 5001
    assert runs[0].max_error <= 1e-6
    assert 1.7 < runs[0].max_error / runs[1].max_error < 2.3
    assert runs[0].peak_force > 100  # the circle's ~180 N forces were applied
    assert not runs[0].saturated.any()


@pytest.mark.parametrize("zeta", [1.0, 0.5])
def test_computed_torque_error_from_an_offset_follows_the_second_order_solution(zeta):
    gains, e0 = Gains(20.0, zeta), -1e-3  # e = p_ref - p with the platform started 1 mm to +x
    run = simulate(P, "circle", ControlSetup(rate=2e4, gains=gains, offset=(1e-3, 0.0)), horizon=0.25)
    w, t = 2 * math.pi * 20.0, run.t
    if zeta == 1.0:  # critically damped: e = e0 (1 + ω t) exp(-ω t)
        expected = e0 * (1 + w * t) * np.exp(-w * t)
    else:  # e = e0 exp(-ζωt) (cos ω_d t + ζω/ω_d sin ω_d t), ω_d = ω sqrt(1 - ζ²)
        wd = w * math.sqrt(1 - zeta**2)
        expected = e0 * np.exp(-zeta * w * t) * (np.cos(wd * t) + zeta * w / wd * np.sin(wd * t))
    assert np.max(np.abs(run.error[:, 0] - expected)) < 0.01 * 1e-3
    assert np.max(np.abs(run.error[:, 1])) < 0.01 * 1e-3
    assert run.error[0, 0] == pytest.approx(e0)


def test_unknown_payload_ranks_pd_then_feedforward_then_computed_torque():
    gains = Gains(10.0, 1.0)
    rms = {
        kind: simulate(P, "circle", ControlSetup(controller=kind, gains=gains, payload=1.0)).rms_error
        for kind in ("pd", "pdff", "ctc")
    }
    assert rms["pd"] > 2 * rms["pdff"] > 2 * rms["ctc"]
    assert rms["pdff"] > 1.1 * rms["ctc"]
    exact = simulate(P, "circle", ControlSetup(controller="ctc", gains=gains)).rms_error
    assert exact < 0.1 * rms["ctc"]  # the payload, not the sampling, makes the error


def test_saturation_caps_the_force_and_the_plant_conserves_energy():
    setup = ControlSetup(controller="pdff", gains=Gains(15.0, 0.7), payload=1.0, force_limit=120.0, noise=1e-5)
    run = simulate(P, "circle", setup)
    assert np.max(np.abs(run.tau)) <= 120.0
    assert run.time_in_saturation > 0.02 and run.saturated.any()
    # τ is constant over each hold interval, so ∫ τ·ḋ dt = Σ τ_k · (d_{k+1} - d_k) exactly;
    # d from eq. (3) solved as a quadratic, K from rigid-body velocities (no tpm_viz dynamics).
    plant = run.plant_params
    assert plant.m_p == pytest.approx(P.m_p + 1.0)
    d = np.array([ik_quadratic(plant, p) for p in run.p])
    work = np.concatenate([[0.0], np.cumsum(np.sum(run.tau[:-1] * np.diff(d, axis=0), axis=1))])
    energy = np.array([rod_kinetic_energy(plant, p, dp) for p, dp in zip(run.p, run.dp, strict=True)])
    assert energy.max() > 1.0
    assert np.max(np.abs(work - (energy - energy[0]))) < 1e-6 * energy.max()


def test_energy_balance_with_computed_torque_and_mass_errors_on_the_line():
    setup = ControlSetup(controller="ctc", mass_error=(0.2, -0.3, 0.1), offset=(0.002, -0.001))
    run = simulate(P, "line", setup)
    assert run.model_params.m_a == pytest.approx(1.2 * P.m_a) and run.plant_params == P
    d = np.array([ik_quadratic(P, p) for p in run.p])
    work = np.concatenate([[0.0], np.cumsum(np.sum(run.tau[:-1] * np.diff(d, axis=0), axis=1))])
    energy = np.array([rod_kinetic_energy(P, p, dp) for p, dp in zip(run.p, run.dp, strict=True)])
    assert np.max(np.abs(work - (energy - energy[0]))) < 1e-6 * energy.max()


def test_noise_is_seeded_and_degrades_tracking():
    quiet = simulate(P, "line", ControlSetup())
    noisy = [simulate(P, "line", ControlSetup(noise=1e-4, seed=s)) for s in (1, 1, 2)]
    assert np.array_equal(noisy[0].p, noisy[1].p) and not np.array_equal(noisy[0].p, noisy[2].p)
    assert noisy[0].rms_error > 1.2 * quiet.rms_error
    # The feedback passes the sensor noise to the forces: K_p m ~ 17 kN/m times 0.1 mm per sample.
    roughness = [np.std(np.diff(r.tau, axis=0)) for r in (quiet, noisy[0])]
    assert roughness[1] > 5 * roughness[0]


def test_user_trajectory_and_longer_horizon():
    t = np.linspace(0.0, 0.3, 31)
    text = "t,p1,p2\n" + "\n".join(f"{x},{0.04 * math.sin(10 * x)},{-0.03 * (1 - math.cos(10 * x))}" for x in t)
    traj = tv.parse_trajectory_csv(text, name="wave")
    run = simulate(P, traj, ControlSetup(rate=2000.0, gains=Gains(20.0, 1.0)), horizon=0.4)
    assert run.name == "wave" and len(run.t) == 801 and run.t[-1] == pytest.approx(0.4)
    on_path = run.t <= traj.duration
    assert np.max(run.error_norm[on_path]) < 1e-5
    # The natural spline ends at ~0.4 m/s: the reference then stops dead and the loop settles again.
    assert np.max(run.error_norm[~on_path]) > 1e-4 and run.error_norm[-1] < 1e-6
    assert run.p_ref[-1] == pytest.approx(traj.p[-1]) and run.dp_ref[-1] == pytest.approx([0.0, 0.0])
    late = dataclasses.replace(traj, t=traj.t + 2.0)  # a planned motion may start at any time
    shifted = simulate(P, late, ControlSetup(rate=2000.0, gains=Gains(20.0, 1.0)), horizon=0.4)
    assert shifted.t[0] == 0.0 and np.allclose(shifted.p_ref, run.p_ref, rtol=0, atol=1e-12)


def test_result_columns_summary_and_frozen():
    run = simulate(P, "line", ControlSetup(controller="pd", force_limit=50.0), duration=0.1)
    cols = run.columns()
    assert list(cols) == COLUMNS and all(len(c) == len(run.t) for c in cols.values())
    assert cols["e1"] == pytest.approx(cols["p1_ref"] - cols["p1"]) and not cols["tau_ff2"].any()
    line = run.summary()
    assert "\n" not in line and "RMS error" in line and "peak force 50.0 N" in line and "saturated" in line
    assert isinstance(run, ControlRun)
    with pytest.raises(dataclasses.FrozenInstanceError):
        run.name = "x"


@pytest.mark.parametrize(
    ("kwargs", "error"),
    [
        ({"setup": ControlSetup(gains=Gains(400.0, 1.0))}, tv.UnreachablePoseError),  # ω h = 2.5: unstable
        ({"reference": "square"}, tv.InputError),
        ({"duration": -1.0}, tv.InputError),
        ({"horizon": 0.0}, tv.InputError),
        ({"setup": "ctc"}, tv.InputError),
    ],
)
def test_bad_input_and_unstable_loops_raise_one_line(kwargs, error):
    args = {"reference": "line", **kwargs}
    with pytest.raises(error) as info:
        simulate(P, **args)
    assert "\n" not in str(info.value)


@pytest.mark.parametrize(
    "kwargs",
    [
        {"rate": 0.0},
        {"rate": float("nan")},
        {"payload": -1.0},
        {"force_limit": 0.0},
        {"noise": -1e-3},
        {"offset": (0.1,)},
        {"mass_error": (0.0, -1.0, 0.0)},
        {"controller": "pid"},
        {"seed": 1.5},
    ],
)
def test_setup_validation(kwargs):
    with pytest.raises(tv.InputError):
        ControlSetup(**kwargs)
