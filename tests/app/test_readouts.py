"""The displayed quantities of a pose (tpm_viz.app.readouts), against independent routes."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tpm_viz import (
    InputError,
    Params,
    actuator_forces_from_platform_force,
    condition_number,
    inverse_dynamics,
    leg_angles,
)
from tpm_viz.app.moves import Pose, drive_to
from tpm_viz.app.poses import preset_pose
from tpm_viz.app.readouts import Load, evaluate, with_reference
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces
from tpm_viz.paper.jacobians import jacobians

P = Params.paper()
POSE = Pose.working(P, (0.04, -0.03))


def _finite_numbers(readout) -> bool:
    nums = [readout.det_jx, readout.det_jq, readout.cond, *readout.p, *readout.d, *readout.theta]
    f = readout.forces
    for arr in (f.tau, f.tau_ref, f.diff):
        if arr is not None:
            nums.extend(arr)
    return all(math.isfinite(float(x)) for x in nums if x is not None)


def test_kinematic_readouts_match_the_library():
    r = evaluate(P, POSE)
    np.testing.assert_allclose(r.theta, leg_angles(P, POSE.p))
    # Independent: θ_1 from sin θ_1 = p_2 / l_a, θ_2 from sin θ_2 = p_1 / l_a (working mode).
    np.testing.assert_allclose(r.theta, np.arcsin([POSE.p[1] / P.l_a, POSE.p[0] / P.l_a]))
    assert r.det_jx == pytest.approx(math.cos(r.theta.sum()))
    assert r.det_jq == pytest.approx(math.cos(r.theta[0]) * math.cos(r.theta[1]))
    assert r.cond == pytest.approx(float(condition_number(P, POSE.p)))
    assert r.mode == 1 and r.alerts == ()


def test_static_forces_are_eq_13_with_f_equal_minus_f_ext():
    f_ext = (12.0, -7.0)
    r = evaluate(P, POSE, Load("static", f_ext=f_ext))
    expected = actuator_forces_from_platform_force(P, POSE.p, -np.array(f_ext))
    np.testing.assert_allclose(r.forces.tau, expected, rtol=1e-12)
    assert "eq. 13" in r.forces.equation


def test_dynamic_forces_are_eq_31():
    load = Load("dynamic", dp=(0.5, -0.2), ddp=(3.0, 4.0))
    r = evaluate(P, POSE, load)
    np.testing.assert_allclose(r.forces.tau, inverse_dynamics(P, POSE.p, load.dp, load.ddp))
    assert r.forces.tau_ref is None and "no reference" in str(r.forces.note)


def test_reference_and_difference():
    def reference(params, p, dp, ddp, f_ext):
        return inverse_dynamics(params, p, dp, ddp, f_ext) + 0.5

    r = evaluate(P, POSE, Load("dynamic", dp=(0.1, 0.1)), reference=reference)
    np.testing.assert_allclose(r.forces.diff, 0.5)


@pytest.mark.parametrize("seed", range(6))
def test_a_live_readout_completed_with_the_reference_is_the_full_readout(seed):
    """Mid-drag the kinematics are computed once (live) and the reference forces added when the numbers are shown:
    every field equals the readout computed with the reference from the start (Pinocchio as the reference)."""
    rng = np.random.default_rng(seed)
    pose = drive_to(P, POSE, rng.uniform(0.02, P.stroke - 0.02, 2)).pose
    load = Load("dynamic", dp=tuple(rng.normal(0, 0.3, 2)), ddp=tuple(rng.normal(0, 3.0, 2)))
    live = evaluate(P, pose, load)
    full = evaluate(P, pose, load, reference=pinocchio_forces)
    done = with_reference(live, P, pose, load, pinocchio_forces)
    assert live.forces.tau_ref is None and done.forces.tau_ref is not None
    np.testing.assert_allclose(done.forces.tau_ref, done.forces.tau, rtol=1e-9, atol=1e-9)  # two models agree
    for name in ("p", "d", "theta", "other_p"):
        np.testing.assert_array_equal(getattr(done, name), getattr(full, name))
    np.testing.assert_array_equal(done.forces.tau_ref, full.forces.tau_ref)
    assert (done.det_jx, done.cond, done.mode, done.alerts, done.forces.note) == (
        full.det_jx,
        full.cond,
        full.mode,
        full.alerts,
        full.forces.note,
    )


def test_reference_errors_become_a_note_not_an_exception():
    def broken(*_args):
        raise ArithmeticError("diverged")

    r = evaluate(P, POSE, reference=broken)
    assert r.forces.tau_ref is None and "diverged" in str(r.forces.note)


def test_reference_is_skipped_off_the_working_branch():
    """The other assembly mode at d = (200, 250) mm has a leg on the other branch (c_i < 0)."""
    pose = drive_to(P, Pose.working(P, (0.0, 0.0)), (0.2, 0.25)).pose
    other = Pose(np.asarray(evaluate(P, pose).other_p), pose.d)
    if np.all(other.branch(P) > 0):
        pytest.skip("the other mode is on the working branch here")
    r = evaluate(P, other, reference=lambda *a: np.zeros(2))
    assert r.forces.tau_ref is None and "working mode" in str(r.forces.note)


@pytest.mark.parametrize("kind", ["inverse", "direct", "stroke"])
def test_alerts_at_the_demo_poses(kind):
    r = evaluate(P, preset_pose(P, kind).pose, Load("static", f_ext=(10.0, 10.0)))
    assert kind in {a.kind for a in r.alerts}
    assert _finite_numbers(r)
    (text,) = [str(a.text) for a in r.alerts if a.kind == kind]
    pose = preset_pose(P, kind).pose
    jac = jacobians(P, pose.p, pose.d)
    # plain words first (what happens to the machine), then the number and the equation (issue 13)
    if kind == "direct":
        assert "stiffness" in text and "without bound" in text
        assert text.endswith(f"(cos(θ1+θ2) = {float(jac.det_jx):.3f}, eq. 12)")
    elif kind == "inverse":
        i = int(np.argmin(np.abs(np.diag(jac.jq))))
        assert f"perpendicular to rail {i + 1}" in text
        assert text.endswith(f"(cos θ{i + 1} = {float(jac.jq[i, i]):.3f}, eq. 11)")
    else:
        assert "end-stop" in text and "back into the stroke" in text


def test_other_assembly_mode_is_the_other_circle_intersection():
    r = evaluate(P, POSE)
    other = np.asarray(r.other_p)
    k = P.a - P.b
    # Both intersections are at distance l_a from both leg circle centres C_1, C_2.
    assert np.hypot(other[0] - (POSE.d[0] - k), other[1]) == pytest.approx(P.l_a)
    assert np.hypot(other[0], other[1] - (POSE.d[1] - k)) == pytest.approx(P.l_a)
    assert np.linalg.norm(other - POSE.p) > 1e-3


def test_load_is_validated():
    with pytest.raises(InputError):
        Load("sideways")
    with pytest.raises(InputError):
        Load(f_ext=(np.nan, 0.0))
    assert Load(dp=[1, 2]).dp == (1.0, 2.0)
