"""One door to both arrangements (tpm_viz.paper.arrangement): the dispatch gives each arrangement's own results."""

from __future__ import annotations

import numpy as np
import pytest

from tests.support import parallel_reference as pref
from tests.support.reference import minimal_coordinate_forces
from tpm_viz import InputError, InvalidParametersError, Params
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper import dynamics, jacobians, kinematics
from tpm_viz.paper import parallel as par
from tpm_viz.paper.arrangement import Arrangement

P = Params.paper()
PERP, PAR = Arrangement.PERPENDICULAR, Arrangement.PARALLEL


def test_parse_accepts_the_words_and_refuses_others():
    assert Arrangement.parse(" Parallel ") is PAR and Arrangement.parse("perpendicular") is PERP
    assert Arrangement.parse(PAR) is PAR
    with pytest.raises(InputError, match="choose perpendicular or parallel"):
        Arrangement.parse("diagonal")


def test_dispatch_reaches_each_arrangement():
    p, dp, ddp, f = np.array([0.03, 0.12]), np.array([0.2, -0.1]), np.array([1.0, 3.0]), np.array([2.0, -1.0])
    assert np.array_equal(arr.inverse_kinematics(PERP, P, p), kinematics.inverse_kinematics(P, p))
    assert np.array_equal(arr.inverse_kinematics("parallel", P, p), par.inverse_kinematics(P, p))
    assert np.array_equal(arr.jacobians(PERP, P, p).j, jacobians.jacobians(P, p).j)
    assert np.array_equal(arr.jacobians(PAR, P, p).j, par.jacobians(P, p).j)
    assert np.array_equal(arr.inverse_dynamics(PERP, P, p, dp, ddp, f), dynamics.inverse_dynamics(P, p, dp, ddp, f))
    assert np.array_equal(arr.inverse_dynamics(PAR, P, p, dp, ddp, f), par.inverse_dynamics(P, p, dp, ddp, f))
    assert arr.classify(PAR, P, [0.0, 0.0]) != arr.classify(PERP, P, [0.0, 0.0])  # p = 0: home vs singular
    d = arr.inverse_kinematics(PAR, P, p)
    assert np.allclose(arr.forward_kinematics(PAR, P, d), p)
    assert np.allclose(arr.mechanism_pose(PAR, P, p).A, [[d[0] - P.a, 0.0], [P.a - d[1], 0.0]])


@pytest.mark.parametrize("p", [(0.0, 0.1), (0.05, 0.2), (-0.1, 0.06)])
def test_force_per_acceleration_against_independent_lagrangians(p):
    """Column k: τ for p̈ = e_k at rest; references from rigid bodies by finite differences (both arrangements)."""
    p = np.asarray(p)
    got_par = arr.force_per_acceleration(PAR, P, p)
    got_perp = arr.force_per_acceleration(PERP, P, p)
    for k, e in enumerate(np.eye(2)):
        assert np.allclose(got_par[:, k], pref.minimal_coordinate_forces(P, p, np.zeros(2), e), rtol=1e-5, atol=1e-5)
        assert np.allclose(got_perp[:, k], minimal_coordinate_forces(P, p, np.zeros(2), e), rtol=1e-5, atol=1e-5)
    j = par.jacobians(P, p).j
    assert np.allclose(got_par, np.linalg.solve(j.T, par.mass_matrix(P, p)), rtol=1e-12)


def test_validity_home_and_geometry_rules():
    tight = Params.paper(b=0.5)
    assert arr.validate(PERP, tight) is tight
    with pytest.raises(InvalidParametersError):
        arr.validate(PAR, tight)
    assert arr.geometry_problem_of(PERP, 0.482, 0.5, 0.26, 0.3) is None
    assert "parallel" in str(arr.geometry_problem_of(PAR, 0.482, 0.5, 0.26, 0.3))
    assert np.array_equal(arr.home(PERP, P), [0.0, 0.0])
    home = arr.home(PAR, P)
    assert np.allclose(par.inverse_kinematics(P, home), [P.stroke / 2, P.stroke / 2])
    assert arr.in_stroke(PAR, P, par.inverse_kinematics(P, home)) and arr.reachable(PAR, P, [2.0, 0.1])
