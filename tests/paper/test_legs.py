"""The shape both arrangements share (tpm_viz.paper.legs, jacobians_of), checked on both against independent routes.

The legs' indices (a_i, σ_i, b_i) against the joints of eq. (1) / (P1): the rail direction by differencing A_i in d_i,
c_i and s_i as the components of B_i - A_i along and across it, |B_i - A_i| = l_a; the Jacobians built from those
indices against finite differences of each arrangement's inverse kinematics and numpy's determinants; the meeting of
two circles against Pythagoras and the status boundaries.
"""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.paper import legs as shared
from tpm_viz.paper.jacobians import jacobians_of
from tpm_viz.paper.kinematics import PERPENDICULAR
from tpm_viz.paper.parallel.kinematics import PARALLEL
from tpm_viz.paper.status import FkStatus

P = Params.paper()
LEGS = pytest.mark.parametrize("legs", [PERPENDICULAR, PARALLEL], ids=["perpendicular", "parallel"])


def _poses(legs: shared.Legs, n: int, seed: int) -> np.ndarray:
    """Regular working-mode poses of the arrangement: |sin θ_i| and |cos θ_i| at least 0.3."""
    rng = np.random.default_rng(seed)
    out = []
    while len(out) < n:
        p = rng.uniform(-0.75 * P.l_a, 0.75 * P.l_a, size=2)
        if legs is PARALLEL and abs(p[1]) < 0.3 * P.l_a:
            continue
        cos = legs.components(P, p, legs.ik(P, p))[0] / P.l_a
        if np.all(np.abs(cos) > 0.3):
            out.append(p)
    return np.array(out)


@LEGS
def test_the_indices_describe_the_joints_of_each_arrangement(legs):
    """∂A_i/∂d_i = σ_i e_{a_i} (the rail, inwards); c_i and s_i are B_i - A_i along it and along e_{b_i}; |B_i - A_i|
    = l_a on every pose, also off the working mode's branch (d given)."""
    e = np.eye(2)
    for p in _poses(legs, 20, seed=1):
        working = legs.ik(P, p)
        a0, b0 = legs.joints(P, p, working)
        np.testing.assert_allclose(np.linalg.norm(b0 - a0, axis=1), P.l_a, rtol=1e-14)  # the loops close
        for d in (working, working + np.array([0.013, -0.021])):
            a0, b0 = legs.joints(P, p, d)
            c, s = legs.components(P, p, d)
            for i in (0, 1):
                step = 1e-3 * e[i]
                rail = (legs.joints(P, p, d + step)[0][i] - legs.joints(P, p, d - step)[0][i]) / 2e-3
                np.testing.assert_allclose(rail, legs.sign[i] * e[legs.along[i]], atol=1e-12)
                leg = b0[i] - a0[i]
                assert c[i] == pytest.approx(leg @ np.round(rail), rel=1e-14, abs=1e-16)
                assert s[i] == pytest.approx(leg @ e[legs.across[i]], rel=1e-14, abs=1e-16)


@LEGS
def test_jacobians_of_are_the_derivatives_of_the_inverse_kinematics(legs):
    """``J = ∂d/∂p`` by central differences of eq. (4) / (P3); ``J_x`` rows are unit vectors, ``J = J_q⁻¹ J_x``, and
    the two singularity measures are numpy's determinants of ``J_x`` and ``J_q``."""
    p = _poses(legs, 16, seed=2)
    jac = jacobians_of(legs, P, p)
    h = 1e-6
    for k in (0, 1):
        step = h * np.eye(2)[k]
        column = (legs.ik(P, p + step) - legs.ik(P, p - step)) / (2 * h)
        np.testing.assert_allclose(jac.j[..., :, k], column, rtol=1e-7, atol=1e-7)
    np.testing.assert_allclose(np.linalg.norm(jac.jx, axis=-1), 1.0, rtol=1e-14)
    np.testing.assert_allclose(np.linalg.solve(jac.jq, jac.jx), jac.j, rtol=1e-12, atol=1e-12)
    np.testing.assert_allclose(jac.det_jx, np.linalg.det(jac.jx), atol=1e-14)
    np.testing.assert_allclose(jac.det_jq, np.linalg.det(jac.jq), atol=1e-14)


def test_two_leg_circles_meet_by_pythagoras_and_the_statuses_sit_on_their_boundaries():
    la = P.l_a
    dist = np.array([0.0, 0.5 * la, 1.2 * la, 2.0 * la, 2.0 * la * (1 + 1e-11), np.inf, np.nan])
    h, exists, status = shared.meeting(P, dist)
    np.testing.assert_allclose(h[1:3], np.sqrt(la**2 - (dist[1:3] / 2) ** 2), rtol=1e-15)
    assert h[3] == 0.0 and np.isnan(h[[0, 4, 5, 6]]).all()
    assert exists.tolist() == [False, True, True, True, False, False, False]
    expected = [FkStatus.COINCIDE, FkStatus.TWO_MODES, FkStatus.TWO_MODES, FkStatus.MODES_MERGE]
    assert status.tolist() == [*expected, FkStatus.APART, FkStatus.APART, FkStatus.APART]


@LEGS
def test_forward_kinematics_through_the_legs_inverts_the_inverse_kinematics(legs):
    """The working-mode pose is one of the two modes the circles give back, and the nearest to itself."""
    for p in _poses(legs, 10, seed=3):
        d = shared.inverse_kinematics(legs, P, p)
        found, mode = shared.forward_kinematics_nearest(legs, P, d, p)
        np.testing.assert_allclose(found, p, atol=1e-12)
        np.testing.assert_allclose(shared.forward_kinematics(legs, P, d, mode), p, atol=1e-12)
