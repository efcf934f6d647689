"""Position kinematics: eq. (4) against eq. (3) and the loop-closure geometry; FK modes; part poses."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tests.support.reference import ik_quadratic
from tests.support.strategies import params_sets, regular_states
from tpm_viz import (
    FK_STATUS,
    InputError,
    Params,
    SingularConfigurationError,
    UnreachablePoseError,
    forward_kinematics,
    forward_kinematics_both,
    forward_kinematics_nearest,
    inverse_kinematics,
    leg_angles,
    mechanism_pose,
)
from tpm_viz.paper.jacobians import jacobians

P = Params.paper()


def test_home_pose_by_hand():
    """At p = 0 every link lies along its rail: d_i = a - b - l_a = 0.13 m (by hand from Table 1)."""
    assert inverse_kinematics(P, [0.0, 0.0]) == pytest.approx([0.482 - 0.092 - 0.260] * 2, abs=1e-15)
    assert leg_angles(P, [0.0, 0.0]) == pytest.approx([0.0, 0.0], abs=1e-15)


@settings(max_examples=examples(200), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_ik_matches_eq3_negative_root_and_closes_the_loop(params, data):
    p, _, _ = data.draw(regular_states(params, margin=0.05))
    d = inverse_kinematics(params, p)
    assert d == pytest.approx(ik_quadratic(params, p, root=-1), abs=1e-12)
    pose = mechanism_pose(params, p, d)
    for i in range(2):
        for k in range(2):
            start, end = pose.links[i, k]
            assert np.linalg.norm(end - start) == pytest.approx(params.l_a, abs=1e-12)
        # both links of a parallelogram stay parallel and the couplers translate
        assert pose.links[i, 0, 1] - pose.links[i, 0, 0] == pytest.approx(pose.links[i, 1, 1] - pose.links[i, 1, 0])
    # angle definitions of conventions.md
    assert math.sin(pose.theta[0]) == pytest.approx(p[1] / params.l_a, abs=1e-12)
    assert math.sin(pose.theta[1]) == pytest.approx(p[0] / params.l_a, abs=1e-12)


@settings(max_examples=examples(200), deadline=None, derandomize=True)
@given(params=params_sets(), data=st.data())
def test_fk_of_ik_round_trip_in_the_plus_mode(params, data):
    p, _, _ = data.draw(regular_states(params, margin=0.05))
    d = inverse_kinematics(params, p)
    sol = forward_kinematics_both(params, d)
    mode = 1 if jacobians(params, p).det_jx > 0 else -1
    assert forward_kinematics(params, d, mode) == pytest.approx(p, abs=1e-10)
    other = sol.minus if mode == 1 else sol.plus
    # the other assembly mode satisfies both loop closures too (eq. 27) ...
    for centre in ([d[0] - params.a + params.b, 0.0], [0.0, d[1] - params.a + params.b]):
        assert np.linalg.norm(other - centre) == pytest.approx(params.l_a, abs=1e-10)
        assert np.linalg.norm(p - centre) == pytest.approx(params.l_a, abs=1e-10)
    # ... and is a different pose away from the direct singularity
    assert np.linalg.norm(other - p) > 1e-6


def test_nearest_mode_follows_the_previous_pose():
    d = inverse_kinematics(P, [0.03, 0.02])
    sol = forward_kinematics_both(P, d)
    assert forward_kinematics_nearest(P, d, sol.minus + 0.001)[1] == -1
    p, mode = forward_kinematics_nearest(P, d, [0.0, 0.0])
    assert mode == 1 and p == pytest.approx([0.03, 0.02], abs=1e-12)


@pytest.mark.parametrize("phi", [-2.0, -2.4])
def test_modes_merge_on_the_third_quadrant_direct_singularity(phi):
    """On p1² + p2² = l_a² with p1, p2 < 0: s_1 = -s_2, the circles touch, both FK solutions meet."""
    p = P.l_a * np.array([math.cos(phi), math.sin(phi)])
    assert abs(float(jacobians(P, p).det_jx)) < 1e-12
    d = inverse_kinematics(P, p)
    centres = np.array([[d[0] - P.a + P.b, 0.0], [0.0, d[1] - P.a + P.b]])
    assert np.linalg.norm(centres[0] - centres[1]) == pytest.approx(2 * P.l_a, abs=1e-12)
    sol = forward_kinematics_both(P, d)
    assert np.linalg.norm(sol.plus - sol.minus) < 1e-5
    assert sol.plus == pytest.approx(p, abs=1e-5)
    assert FK_STATUS[int(sol.status)].startswith("direct singularity: the two assembly modes merge")
    # just inside, two distinct modes on either side of the locus
    sol_in = forward_kinematics_both(P, inverse_kinematics(P, 0.95 * p))
    assert np.linalg.norm(sol_in.plus - sol_in.minus) > 1e-3


def test_first_quadrant_direct_singularity_is_a_coincidence_of_the_leg_circles():
    """On p1² + p2² = l_a² with p1, p2 > 0: s_1 = s_2, d_1 = d_2 = a - b, the position is undetermined."""
    for phi in (0.3, 0.8, 1.2):
        p = P.l_a * np.array([math.cos(phi), math.sin(phi)])
        assert inverse_kinematics(P, p) == pytest.approx([P.a - P.b] * 2, abs=1e-12)
        assert abs(float(jacobians(P, p).det_jx)) < 1e-12
    with pytest.raises(SingularConfigurationError, match="coincide"):
        forward_kinematics(P, [P.a - P.b] * 2)
    assert "coincide" in FK_STATUS[int(forward_kinematics_both(P, [P.a - P.b] * 2).status)]


def test_unreachable_and_unassemblable_raise_one_line_errors():
    with pytest.raises(UnreachablePoseError, match=r"\(300.0, 0.0\) mm is unreachable"):
        inverse_kinematics(P, [0.3, 0.0])
    with pytest.raises(UnreachablePoseError, match="cannot be assembled"):
        forward_kinematics(P, [0.0, 0.9])
    with pytest.raises(InputError, match="non-finite"):
        inverse_kinematics(P, [float("nan"), 0.0])
    with pytest.raises(InputError, match=r"shape \(\.\.\., 2\)"):
        inverse_kinematics(P, [0.0, 0.0, 0.0])
    assert not forward_kinematics_both(P, [0.0, 0.9]).exists
    assert FK_STATUS[int(forward_kinematics_both(P, [0.0, 0.9]).status)].startswith("cannot assemble")
    assert FK_STATUS[int(forward_kinematics_both(P, [0.1, 0.1]).status)] == "two assembly modes"


def test_ik_is_vectorised_over_leading_axes():
    rng = np.random.default_rng(1)
    p = rng.uniform(-0.1, 0.1, size=(3, 4, 2))
    d = inverse_kinematics(P, p)
    assert d.shape == (3, 4, 2)
    assert d[2, 1] == pytest.approx(ik_quadratic(P, p[2, 1]), abs=1e-14)
