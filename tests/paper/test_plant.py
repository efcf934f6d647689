"""The closed form as a plant (``paper/plant.py``) and the sampled loop on it (``paper/tracking.py``).

Independent routes: Pinocchio's 2-DOF plant (``multibody.forward.PlatformPlant``, its own tree, closures solved in
closed form and ``rnea``) for the accelerations; the closed form's inverse dynamics for the round trip
``ID(p, ṗ, FD(τ)) = τ``; the control lab's own simulation (``multibody.control.simulate``, Pinocchio plant) for the
runs of :func:`tpm_viz.paper.tracking.track`.
"""

from __future__ import annotations

import numpy as np
import pytest

from tests.support.strategies import random_states
from tpm_viz.core.errors import SingularConfigurationError, TpmVizError, UnreachablePoseError
from tpm_viz.core.params import Params
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.multibody.forward import PlatformPlant
from tpm_viz.multibody.model import model_for
from tpm_viz.paper.control import ControlLaw, ControllerKind, Gains, model_with_errors
from tpm_viz.paper.dynamics import inverse_dynamics
from tpm_viz.paper.plant import closed_form_plant
from tpm_viz.paper.tracking import track

PARAMS = (Params.paper(), Params.paper(l_a=0.21, m_a=1.7, m_b=0.3, m_p=4.0))


@pytest.mark.parametrize("params", PARAMS, ids=["paper", "other"])
def test_accelerations_agree_with_pinocchio(params):
    closed, pinocchio = closed_form_plant(params), PlatformPlant(model_for(params)).acceleration
    rng = np.random.default_rng(5)
    for p, dp, _ in random_states(params, 40, seed=11):
        tau = rng.uniform(-200.0, 200.0, 2)
        state = (*p.tolist(), *dp.tolist(), *tau.tolist())
        a, b = np.array(closed(*state)), np.array(pinocchio(*state))
        assert np.max(np.abs(a - b)) <= 1e-9 * (1.0 + np.max(np.abs(b)))


@pytest.mark.parametrize("params", PARAMS, ids=["paper", "other"])
def test_forward_undoes_inverse(params):
    plant = closed_form_plant(params)
    for p, dp, ddp in random_states(params, 40, seed=3):
        tau = inverse_dynamics(params, p, dp, ddp)
        back = np.array(plant(*p.tolist(), *dp.tolist(), *tau.tolist()))
        assert back == pytest.approx(ddp, rel=1e-9, abs=1e-9)


def test_refuses_poses_out_of_reach_and_singular():
    params = Params.paper()
    plant = closed_form_plant(params)
    with pytest.raises(UnreachablePoseError):
        plant(0.0, params.l_a, 0.0, 0.0, 0.0, 0.0)
    x = -params.l_a / np.sqrt(2.0)  # the diagonal's direct singularity, cos(θ1 + θ2) = 0
    with pytest.raises(SingularConfigurationError):
        plant(x, x, 0.0, 0.0, 1.0, 1.0)


@pytest.mark.parametrize(
    ("wn", "zeta", "err", "limit"),
    [(30.0, 1.0, 0.2, 200.0), (5.0, 0.5, -0.3, 185.0), (64.0, 0.7, -0.15, None), (12.0, 2.0, 0.3, 178.0)],
)
def test_track_is_the_control_lab_run(wn, zeta, err, limit):
    """The same experiment as the lab's Pinocchio simulation: the same positions, forces and summary numbers."""
    params = Params.paper()
    law = ControlLaw(ControllerKind.CTC, model_with_errors(params, err, err, err), Gains(wn, zeta))
    ours = track(law, closed_form_plant(params), "circle", force_limit=limit)
    lab = simulate(params, "circle", ControlSetup(gains=Gains(wn, zeta), mass_error=(err,) * 3, force_limit=limit))
    assert ours.t == pytest.approx(lab.t, abs=0)
    assert np.max(np.abs(ours.p - lab.p)) < 1e-9
    assert np.max(np.abs(ours.tau - lab.tau)) < 1e-6
    assert ours.rms_error == pytest.approx(lab.rms_error, rel=1e-6)
    assert ours.saturated == bool(lab.saturated.any())
    if limit is None:
        assert ours.commanded_peak == pytest.approx(lab.peak_force, rel=1e-9)
    assert np.all(np.abs(ours.tau) <= (limit or np.inf))


def test_an_unstable_loop_is_one_line_with_the_time():
    params = Params.paper()
    law = ControlLaw(ControllerKind.CTC, model_with_errors(params, 0.3, 0.3, 0.3), Gains(400.0, 1.0))
    with pytest.raises(TpmVizError, match=r"^at t = \d\.\d{4} s: "):
        track(law, closed_form_plant(params), "circle")
