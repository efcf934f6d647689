"""Closed-form inverse dynamics (eqs. 28-31) against two independent routes.

1. The minimal-coordinate Lagrangian in p from body velocities (tests/reference.py), τ = J^{-T}(F_p - f_ext).
2. The power balance τ·ḋ + f_ext·ṗ = dK/dt along the paper's trajectories, K from body velocities.
The erratum of eq. (22) (d_i² for ḋ_i²) is shown against the rigid-body kinetic energy.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tests.support.reference import minimal_coordinate_forces, rod_kinetic_energy
from tests.support.strategies import params_sets, regular_states
from tpm_viz import (
    Params,
    SingularConfigurationError,
    actuator_forces_from_platform_force,
    actuator_velocity,
    inverse_dynamics,
    inverse_dynamics_detail,
    kinetic_energy,
    leg_angles,
    paper_trajectory,
)

P = Params.paper()


@settings(max_examples=examples(80), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data(), f=st.tuples(st.floats(-50, 50), st.floats(-50, 50)))
def test_matches_minimal_coordinate_lagrangian(params, data, f):
    p, dp, ddp = data.draw(regular_states(params))
    tau = inverse_dynamics(params, p, dp, ddp, f_ext=f)
    ref = minimal_coordinate_forces(params, p, dp, ddp, f_ext=f)
    assert np.max(np.abs(tau - ref)) / (1.0 + np.max(np.abs(ref))) < 1e-5


@pytest.mark.parametrize("kind", ["line", "circle"])
def test_power_balance_along_the_paper_trajectories(kind):
    """τ·ḋ = dK/dt, K from body velocities, dK/dt by central differences in time."""
    traj = paper_trajectory(kind, samples=2001)
    res = inverse_dynamics_detail(P, traj.p, traj.dp, traj.ddp)
    power = np.sum(res.tau * res.dd, axis=-1)
    k = np.array([rod_kinetic_energy(P, p, v) for p, v in zip(traj.p, traj.dp, strict=True)])
    dk = np.gradient(k, traj.t, edge_order=2)
    scale = np.max(np.abs(power))
    assert np.max(np.abs(power - dk)[5:-5]) < 2e-4 * scale
    assert scale > 10.0  # watts: the check is not vacuous


def test_power_balance_with_external_force():
    f = np.array([12.0, -7.0])
    traj = paper_trajectory("line", samples=2001)
    res = inverse_dynamics_detail(P, traj.p, traj.dp, traj.ddp, f_ext=f)
    power = np.sum(res.tau * res.dd, axis=-1) + traj.dp @ f
    k = np.array([rod_kinetic_energy(P, p, v) for p, v in zip(traj.p, traj.dp, strict=True)])
    dk = np.gradient(k, traj.t, edge_order=2)
    assert np.max(np.abs(power - dk)[5:-5]) < 2e-4 * np.max(np.abs(power))


def test_static_case_is_eq13_with_the_load_sign():
    """At rest, holding an external load f_ext needs τ = J^{-T}(-f_ext) (eq. 13 with f = -f_ext)."""
    p, f = np.array([0.05, -0.07]), np.array([30.0, 11.0])
    tau = inverse_dynamics(P, p, [0, 0], [0, 0], f_ext=f)
    assert tau == pytest.approx(actuator_forces_from_platform_force(P, p, -f), rel=1e-12)


@settings(max_examples=examples(60), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_kinetic_energy_eq22_corrected_matches_rigid_bodies(params, data):
    p, dp, _ = data.draw(regular_states(params))
    assert kinetic_energy(params, p, dp) == pytest.approx(rod_kinetic_energy(params, p, dp), rel=1e-6)


def test_erratum_eq22_printed_d_squared_is_not_the_kinetic_energy():
    """Eq. (22) as printed, 1/2 m_b (d_i² - ...), depends on position, not speed: at rest it is not 0."""
    p, dp = np.array([0.05, 0.02]), np.zeros(2)
    d = inverse_dynamics_detail(P, p, dp, dp).d
    th = leg_angles(P, p)
    printed = np.sum(P.m_b * P.l_a**2 * 0 / 6 + 0.5 * P.m_b * (d**2 - 0 * np.sin(th)))
    assert rod_kinetic_energy(P, p, dp) == 0.0
    assert kinetic_energy(P, p, dp) == 0.0
    assert printed > 0.01  # joules of energy at rest: the printed form is a typo


def test_vectorised_equals_pointwise():
    traj = paper_trajectory("circle", samples=7)
    batch = inverse_dynamics(P, traj.p, traj.dp, traj.ddp)
    for k in range(7):
        assert batch[k] == pytest.approx(inverse_dynamics(P, traj.p[k], traj.dp[k], traj.ddp[k]), rel=1e-14)
    assert batch.shape == (7, 2)
    p, dp = traj.p.reshape(7, 1, 2), traj.dp.reshape(7, 1, 2)
    assert inverse_dynamics(P, p, dp, 0 * dp).shape == (7, 1, 2)


@settings(max_examples=examples(200), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data(), branch=st.tuples(st.sampled_from([1, -1]), st.sampled_from([1, -1])))
def test_the_one_state_fast_path_equals_the_vectorised_path_on_every_branch(params, data, branch):
    """One state (shape (2,)) takes the scalar fast path, a batch of one (shape (1, 2)) the vectorised one: same τ,
    with the branch given by ``d`` (c_i = ±sqrt(l_a² - p_j²), the legs of the other assembly modes) or not."""
    p, dp, ddp = data.draw(regular_states(params))
    c = np.array(branch) * np.sqrt(params.l_a**2 - p[::-1] ** 2)
    d = p - c + params.a - params.b  # eq. (3) on that branch
    f = np.array([data.draw(st.floats(-50, 50)), data.draw(st.floats(-50, 50))])
    for dd in (None, d) if branch == (1, 1) else (d,):
        try:
            batch = inverse_dynamics(params, p[None], dp[None], ddp[None], f, d=None if dd is None else dd[None])[0]
        except SingularConfigurationError:
            with pytest.raises(SingularConfigurationError):
                inverse_dynamics(params, p, dp, ddp, f, d=dd)
            continue
        one = inverse_dynamics(params, p, dp, ddp, f, d=dd)
        assert one.shape == (2,) and one == pytest.approx(batch, rel=1e-12, abs=1e-9)


def test_paper_trajectory_peaks_are_of_the_expected_order():
    """conventions.md: with T = 0.2 s / 0.5 s the peaks are of the order of 150-180 N."""
    for kind in ("line", "circle"):
        traj = paper_trajectory(kind, samples=401)
        peak = np.max(np.abs(inverse_dynamics(P, traj.p, traj.dp, traj.ddp)))
        assert 100 < peak < 250


def test_singular_state_raises():
    p = P.l_a * np.array([np.cos(0.4), np.sin(0.4)])
    with pytest.raises(SingularConfigurationError):
        inverse_dynamics(P, p, [0.1, 0.0], [0.0, 0.0])
    assert actuator_velocity(P, [0.0, 0.0], [1.0, 0.0]) == pytest.approx([1.0, 0.0])
