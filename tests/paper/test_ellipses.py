"""Manipulability ellipses against their definitions: |J ṗ| = 1 on the velocity ellipse, f = Jᵀτ with |τ| = 1."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tests.support.strategies import params_sets, regular_states
from tpm_viz import Params, SingularConfigurationError
from tpm_viz.paper.ellipses import ellipse_outline, manipulability_ellipses
from tpm_viz.paper.jacobians import jacobians


@settings(max_examples=examples(100), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_outlines_satisfy_the_definitions(params, data):
    p, _, _ = data.draw(regular_states(params))
    j = jacobians(params, p).j
    ell = manipulability_ellipses(params, p)
    vel = ellipse_outline(ell.velocity, n=37)
    assert np.linalg.norm(vel @ j.T, axis=1) == pytest.approx(np.ones(37), rel=1e-9)
    force = ellipse_outline(ell.force, n=37)
    tau = np.linalg.solve(j.T, force.T).T  # the actuator forces that produce each boundary force
    assert np.linalg.norm(tau, axis=1) == pytest.approx(np.ones(37), rel=1e-9)
    assert np.prod(ell.velocity.radii) * np.prod(ell.force.radii) == pytest.approx(1.0)
    assert abs(np.linalg.det(j)) == pytest.approx(np.prod(ell.force.radii), rel=1e-9)


def test_home_pose_is_a_unit_circle_and_singular_poses_raise():
    P = Params.paper()
    ell = manipulability_ellipses(P, [0.0, 0.0])  # J = I at p = 0
    assert ell.velocity.radii == pytest.approx([1.0, 1.0]) and ell.force.radii == pytest.approx([1.0, 1.0])
    with pytest.raises(SingularConfigurationError):
        manipulability_ellipses(P, P.l_a * np.array([np.cos(-2.0), np.sin(-2.0)]))  # quadrant-III arc
    near_inverse = manipulability_ellipses(P, [0.0, 0.99 * P.l_a])
    assert max(near_inverse.force.radii) > 5  # the force ellipse grows near cos θ1 -> 0
