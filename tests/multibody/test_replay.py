"""Forward-dynamics replay: the paper's forces drive the Pinocchio model along Figs. 4-5 paths.

Independent checks: the platform follows the reference (the two dynamic models agree), the
actuator work equals the multibody kinetic energy (power balance, no reference to the paper),
RK4 converges at fourth order, and a 0.1 % mass mismatch is caught by the 0.1 mm tolerance.
"""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

import tpm_viz as tv
from tpm_viz.multibody.replay import MAX_STEPS, ReplayResult, replay

P = tv.Params.paper()


@pytest.fixture(scope="module", params=["line", "circle"])
def result(request) -> ReplayResult:
    return replay(P, request.param)


def test_platform_tracks_the_reference_and_closures_hold(result):
    n = round(tv.DEFAULT_DURATIONS[result.kind] / 1e-3) + 1
    assert result.t.shape == (n,) and result.p_sim.shape == result.p_ref.shape == result.tau.shape == (n, 2)
    assert result.t[-1] == pytest.approx(tv.DEFAULT_DURATIONS[result.kind])
    assert result.max_tracking_error < 1e-7  # m; the requirement is 0.1 mm
    assert result.max_constraint_violation < 1e-9  # m; the requirement is 1e-6 m
    assert np.max(np.abs(result.tau)) > 100  # the paper's ~150-180 N peaks drive it
    path = np.linalg.norm(np.diff(result.p_sim, axis=0), axis=1).sum()
    assert path > 0.2  # it moved: 224 mm along the line, 628 mm around the circle
    assert result.p_sim[-1] == pytest.approx(result.p_ref[-1], abs=1e-7)


def test_actuator_work_equals_the_multibody_kinetic_energy(result):
    power = np.sum(result.tau * result.dd_sim, axis=1)  # τ·ḋ [W]; no external force
    h = result.dt
    pairs = h / 3 * (power[:-2:2] + 4 * power[1:-1:2] + power[2::2])  # Simpson on [t_2m, t_2m+2]
    work = np.concatenate([[0.0], np.cumsum(pairs)])
    energy = result.kinetic_energy[::2]
    assert energy.max() > 1.0  # J: a real motion
    assert np.max(np.abs(work - energy)) < 1e-6 * energy.max()
    assert result.kinetic_energy[-1] < 1e-12 * energy.max()  # back at rest at t = T


def test_rk4_converges_at_fourth_order():
    errors = [replay(P, "line", dt=dt).max_tracking_error for dt in (4e-3, 2e-3)]
    assert 10 < errors[0] / errors[1] < 22  # 2^4 = 16


def test_a_small_mass_mismatch_shows_as_tracking_error():
    wrong = replay(P, "line", force_params=P.replace(m_p=P.m_p * 1.002))
    assert wrong.max_tracking_error > 0.1e-3  # m: the 0.1 mm tolerance catches a 0.2 % platform-mass error


def test_other_parameter_sets_and_durations_also_agree():
    params = P.replace(l_a=0.3, m_b=1.5, m_p=1.0, b=0.05)
    r = replay(params, "circle", duration=0.8, dt=2e-3)
    assert r.duration == 0.8 and r.dt == pytest.approx(2e-3)
    assert r.max_tracking_error < 1e-6
    assert r.max_constraint_violation < 1e-9


def test_dt_is_rounded_to_whole_steps_and_result_is_frozen():
    r = replay(P, "line", duration=0.05, dt=0.003)
    assert len(r.t) - 1 == 17 and r.dt == pytest.approx(0.05 / 17)
    with pytest.raises(dataclasses.FrozenInstanceError):
        r.kind = "circle"


@pytest.mark.parametrize(
    ("kwargs", "error"),
    [
        ({"kind": "square"}, tv.InputError),
        ({"kind": "line", "duration": -1.0}, tv.InputError),
        ({"kind": "line", "duration": float("nan")}, tv.InputError),
        ({"kind": "line", "duration": "abc"}, tv.InputError),
        ({"kind": "line", "dt": 0.0}, tv.InputError),
        ({"kind": "line", "dt": "x"}, tv.InputError),
        ({"kind": "line", "duration": 1.0, "dt": 1.0 / (MAX_STEPS + 10)}, tv.InputError),
    ],
)
def test_bad_input_is_a_one_line_error(kwargs, error):
    with pytest.raises(error) as info:
        replay(P, **kwargs)
    assert "\n" not in str(info.value)


def test_a_path_outside_the_workspace_is_reported():
    with pytest.raises(tv.UnreachablePoseError):
        replay(P.replace(l_a=0.09, a=0.3, b=0.05, stroke=0.3), "line")
