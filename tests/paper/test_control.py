"""Control laws of issue 14 on the closed form (tpm_viz.paper.control), against independent routes.

- gains and the PD axis masses from first principles (2π, the rigid-body kinetic energy at home);
- the computed-torque force against the minimal-coordinate Lagrangian of tests/support/reference.py;
- the PD laws against the public kinematics (eqs. 4, 9);
- the reference sampler against the exact paper paths and an exact quintic.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pytest

import tpm_viz as tv
from tests.support.reference import minimal_coordinate_forces
from tpm_viz.paper.control import (
    ControlLaw,
    ControllerKind,
    Gains,
    axis_masses,
    model_with_errors,
    reference_state,
)
from tpm_viz.paper.spline import CubicSpline

P = tv.Params.paper()
RNG = np.random.default_rng(14)


def _row(law: ControlLaw, p_ref, dp_ref, ddp_ref):
    return law.sample([0.0], np.atleast_2d(p_ref), np.atleast_2d(dp_ref), np.atleast_2d(ddp_ref)).rows()[0]


def test_gains_from_natural_frequency_and_damping():
    g = Gains(wn=7.5, zeta=0.6)
    w = 2 * math.pi * 7.5
    assert g.omega == pytest.approx(w)
    assert g.kp == pytest.approx(w * w) and g.kd == pytest.approx(2 * 0.6 * w)
    # A unit mass under K_p e + K_d ė rings at ω_d = ω sqrt(1 - ζ²): the roots of s² + K_d s + K_p.
    roots = np.roots([1.0, g.kd, g.kp])
    assert np.allclose(sorted(abs(roots.imag)), [w * math.sqrt(1 - 0.36)] * 2)
    assert np.allclose(roots.real, -0.6 * w)
    assert Gains(wn=3, zeta=0).kd == 0.0
    for bad in ({"wn": 0}, {"wn": -1}, {"wn": float("nan")}, {"zeta": -0.1}, {"wn": "fast"}):
        with pytest.raises(tv.InputError):
            Gains(**bad)
    with pytest.raises(dataclasses.FrozenInstanceError):
        g.wn = 3.0


def test_axis_masses_are_the_home_inertia_of_the_mass_model():
    # At p = 0 a slider moves with its platform axis and the other leg's links swing about the slider
    # pivot: K = ½ (m_p + m_a + m_b) ṗ_i² + ½ (m_b / 3) ṗ_i² per axis (uniform rods, I = m l² / 3).
    for params in (P, P.replace(m_a=2.0, m_b=0.3, m_p=5.0)):
        expected = params.m_p + params.m_a + params.m_b + params.m_b / 3
        assert axis_masses(params) == pytest.approx((expected, expected), rel=1e-12)


def test_model_with_errors_scales_masses_only():
    wrong = model_with_errors(P, 0.1, -0.2, 0.5)
    assert (wrong.m_a, wrong.m_b, wrong.m_p) == pytest.approx((0.95 * 1.1, 0.84 * 0.8, 2.21 * 1.5))
    assert (wrong.a, wrong.b, wrong.l_a) == (P.a, P.b, P.l_a)
    assert model_with_errors(P) == P
    for bad in (-1.0, -2.0, float("inf")):
        with pytest.raises(tv.InputError):
            model_with_errors(P, m_p=bad)


@pytest.mark.parametrize("seed", range(6))
def test_computed_torque_force_matches_the_minimal_coordinate_lagrangian(seed):
    rng = np.random.default_rng(seed)
    law = ControlLaw("ctc", P, Gains(12.0, 0.8))
    p_ref, dp_ref, ddp_ref = rng.uniform(-0.1, 0.1, 2), rng.normal(0, 1, 2), rng.normal(0, 20, 2)
    p, dp = p_ref + rng.normal(0, 2e-3, 2), dp_ref + rng.normal(0, 0.05, 2)
    tau1, tau2, ff1, ff2 = law.force(_row(law, p_ref, dp_ref, ddp_ref), p, dp)
    g = law.gains
    command = ddp_ref + g.kd * (dp_ref - dp) + g.kp * (p_ref - p)  # p̈_ref + K_d ė + K_p e
    expected = minimal_coordinate_forces(P, p, dp, command)
    scale = 1.0 + np.max(np.abs(expected))
    assert np.max(np.abs(np.array([tau1, tau2]) - expected)) / scale < 1e-5
    expected_ff = minimal_coordinate_forces(P, p, dp, ddp_ref)
    assert np.max(np.abs(np.array([ff1, ff2]) - expected_ff)) / (1.0 + np.max(np.abs(expected_ff))) < 1e-5


@pytest.mark.parametrize("kind", ["pd", "pdff"])
def test_pd_laws_act_on_actuator_coordinates(kind):
    law = ControlLaw(kind, P, Gains(8.0, 0.7))
    p_ref, dp_ref, ddp_ref = np.array([0.03, -0.05]), np.array([0.4, 0.2]), np.array([3.0, -5.0])
    row = _row(law, p_ref, dp_ref, ddp_ref)
    ff = tv.inverse_dynamics(P, p_ref, dp_ref, ddp_ref) if kind == "pdff" else np.zeros(2)
    on_reference = law.force(row, p_ref, dp_ref)
    assert on_reference == pytest.approx([*ff, *ff], abs=1e-9)  # no error: only the feedforward
    p, dp = p_ref + np.array([1e-3, -2e-3]), dp_ref + np.array([0.01, 0.03])
    d, d_ref = tv.inverse_kinematics(P, p), tv.inverse_kinematics(P, p_ref)
    dd, dd_ref = tv.actuator_velocity(P, p, dp), tv.actuator_velocity(P, p_ref, dp_ref)
    m = np.array(axis_masses(P))
    expected = ff + m * (law.gains.kp * (d_ref - d) + law.gains.kd * (dd_ref - dd))
    assert law.force(row, p, dp)[:2] == pytest.approx(expected, rel=1e-12, abs=1e-9)


def test_controller_kind_and_law_validation():
    assert ControllerKind.parse("pdff") is ControllerKind.PDFF
    assert ControlLaw("ctc", P).kind is ControllerKind.CTC
    with pytest.raises(tv.InputError, match="pd, pdff, ctc"):
        ControllerKind.parse("pid")
    with pytest.raises(tv.InputError):
        ControlLaw("pd", "paper")
    law = ControlLaw("ctc", P)
    row = _row(law, [0.0, 0.0], [0.0, 0.0], [0.0, 0.0])
    with pytest.raises(tv.UnreachablePoseError):
        law.force(row, [0.0, 0.3], [0.0, 0.0])  # |p_2| > l_a


def test_reference_of_the_paper_paths_is_exact():
    t = np.linspace(0.0, 0.5, 11)
    p, dp, ddp = reference_state("circle", t)
    assert np.allclose(np.linalg.norm(p, axis=1), 0.1, atol=1e-15)
    assert p[0] == pytest.approx([0.1, 0.0]) and p[-1] == pytest.approx([0.1, 0.0], abs=1e-15)
    phi_dot = 2 * math.pi * 6 * (t / 0.5 - (t / 0.5) ** 2) / 0.5  # ds/dt of 3τ² - 2τ³
    assert np.linalg.norm(dp, axis=1) == pytest.approx(0.1 * phi_dot, abs=1e-12)
    p, dp, ddp = reference_state("line", [0.0, 0.1, 0.2], duration=0.2)
    assert p[1] == pytest.approx([0.0, 0.0], abs=1e-15) and ddp[1] == pytest.approx([0.0, 0.0], abs=1e-12)
    with pytest.raises(tv.InputError):
        reference_state("square", t)


def test_reference_of_a_sampled_trajectory_is_quintic_hermite():
    # An exact quintic in time, sampled at 7 uneven times: interpolation must reproduce it between samples.
    coef = RNG.normal(0, 0.05, (6, 2))
    ts = np.array([0.0, 0.05, 0.07, 0.15, 0.2, 0.31, 0.4])

    def poly(t, k):
        powers = np.arange(6)
        c = coef * np.array([math.perm(n, k) if n >= k else 0 for n in powers])[:, None]
        return np.stack([t ** max(n - k, 0) * (n >= k) for n in powers], -1) @ c

    traj = tv.Trajectory("quintic", ts, poly(ts, 0), poly(ts, 1), poly(ts, 2))
    t = np.linspace(0.0, 0.4, 97)
    for got, k in zip(reference_state(traj, t), range(3), strict=True):
        assert np.max(np.abs(got - poly(t, k))) < 1e-12 * 10**k
    p, dp, ddp = reference_state(traj, [0.5])  # after the end: at rest at the last sample
    assert p[0] == pytest.approx(traj.p[-1]) and not dp.any() and not ddp.any()
    with pytest.raises(tv.InputError):
        reference_state(traj, t, duration=1.0)


def test_reference_of_a_users_csv_goes_through_its_samples():
    ts = np.linspace(0.0, 0.3, 13)
    text = "t,p1,p2\n" + "\n".join(f"{t},{0.05 * math.sin(9 * t)},{0.02 * t}" for t in ts)
    traj = tv.parse_trajectory_csv(text)
    p, dp, _ = reference_state(traj, ts)
    assert np.max(np.abs(p - traj.p)) < 1e-15 and np.max(np.abs(dp - traj.dp)) < 1e-12
    # Between samples the reference is the user's natural cubic spline itself (quintic Hermite is exact on cubics).
    mid = np.sort(RNG.uniform(0.0, 0.3, 50))
    spline = CubicSpline(ts, traj.p)
    for k, got in enumerate(reference_state(traj, mid)):
        assert np.max(np.abs(got - spline(mid, k))) < 1e-12 * 30**k
