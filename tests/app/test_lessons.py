"""The guided demonstrations (assets/lessons/*.toml, read by tpm_viz.app.lessons): every scene is valid, and the
effect each one states is true (the files and their [checks]: test_lesson_files.py)."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import InputError, Params, forward_kinematics_both
from tpm_viz.app.lessons import DEMOS, demo_by_key, demo_params, demo_pose, demo_source, effect
from tpm_viz.app.moves import check
from tpm_viz.app.overlays import MAP_KINDS, cached_map
from tpm_viz.app.runs import Source, build_run
from tpm_viz.drawing import meshes
from tpm_viz.multibody.model import inverse_dynamics as pinocchio_forces
from tpm_viz.paper.ellipses import manipulability_ellipses
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.status import PoseStatus
from tpm_viz.paper.workspace import workspace_area

P = Params.paper()


def test_keys_and_titles_are_unique_and_the_tour_is_ordered():
    assert len({d.key for d in DEMOS}) == len(DEMOS) == len({d.title for d in DEMOS})
    assert [d.title.split(".")[0] for d in DEMOS] == [str(k + 1) for k in range(len(DEMOS))]
    assert demo_by_key("speed").motion.kind == "circle"
    with pytest.raises(InputError):
        demo_by_key("nope")


@pytest.mark.parametrize("demo", DEMOS, ids=[d.key for d in DEMOS])
def test_every_demo_is_a_valid_scene(demo):
    params = demo_params(demo)  # validated by Params
    pose = demo_pose(demo, params)
    assert check(params, pose) == PoseStatus.REGULAR  # inside the stroke, clear of both singularities
    assert pose.mode(params) == demo.mode or demo.d is None
    source = demo_source(demo)
    if source is not None:
        run = build_run(params, source)  # raises if any sample is not a valid pose
        np.testing.assert_allclose(run.p[0], pose.p)
    assert demo.map_kind in MAP_KINDS
    lo, hi = meshes.base_extent(params)
    look, pos = np.array(demo.camera.look_at), np.array(demo.camera.position)
    assert np.all((lo <= look[:2]) & (look[:2] <= hi)) and look[2] == 0.0
    assert pos[2] > 0.3 and 0.4 < np.linalg.norm(pos - look) < 1.5  # above the floor, the subject in view
    assert 200 < len(demo.text) < 900 and "\n" not in demo.text
    assert str(effect(demo)) and "nan" not in str(effect(demo)).lower()


def test_forces_really_grow_approaching_the_direct_singularity():
    demo = demo_by_key("direct")
    run = build_run(P, demo_source(demo))
    det = jacobians(P, run.p).det_jx
    assert det[0] == pytest.approx(1.0) and 0.03 < det[-1] < 0.2  # ends in the warning band, before the margin
    assert np.linalg.norm(run.ddp[-1]) == pytest.approx(np.linalg.norm(run.ddp[0]))  # same |p̈| at both ends
    start, end = np.linalg.norm(run.tau[0]), np.linalg.norm(run.tau[-1])
    assert end > 5 * start
    # Along the decelerating second half, |τ| grows as det J_x falls.
    half = run.tau[len(run.t) // 2 + 40 :]
    assert np.all(np.diff(np.linalg.norm(half, axis=1)) > 0)


def test_shorter_links_really_shrink_the_workspace():
    demo = demo_by_key("workspace")
    before, after = cached_map(P), cached_map(demo_params(demo))
    assert workspace_area(after) < 0.85 * workspace_area(before)
    assert workspace_area(after, "reachable") < 0.65 * workspace_area(before, "reachable")
    assert "944 → 771 cm²" in str(effect(demo))


def test_the_circle_peak_at_two_speeds_goes_as_one_over_t_squared():
    demo = demo_by_key("speed")
    t1, t2 = demo.compare
    p1, p2 = (build_run(P, Source.paper("circle", t)).peak for t in (t1, t2))
    assert p1 / p2 == pytest.approx((t2 / t1) ** 2, rel=1e-9)
    assert "ratio 4.000 = (T2/T1)² = 4.000" in str(effect(demo))


def test_paper_and_pinocchio_really_agree_on_the_agreement_demo():
    from tpm_viz.multibody.model import inverse_dynamics as pinocchio

    demo = demo_by_key("agreement")
    run = build_run(P, demo_source(demo), pinocchio)
    assert np.max(np.abs(run.tau_ref - run.tau) / (1.0 + np.abs(run.tau))) < 1e-9  # conventions.md
    assert run.peak > 100.0  # and the forces are not trivially small


def test_the_two_assembly_modes_exist_mirror_each_other_and_are_both_valid():
    demo = demo_by_key("modes")
    sol = forward_kinematics_both(P, demo.d)
    pose = demo_pose(demo, P)
    np.testing.assert_allclose(pose.p, sol.plus)
    dets = [float(jacobians(P, q, demo.d).det_jx) for q in (sol.plus, sol.minus)]
    assert dets[0] > 0.2 and dets[1] < -0.2  # opposite signs of det J_x, clear of the arc
    from tpm_viz.app.moves import Pose
    from tpm_viz.paper.status import PoseStatus

    assert check(P, Pose(sol.minus, demo.d)) == PoseStatus.REGULAR
    np.testing.assert_allclose(sol.plus, sol.plus[::-1])  # both on the diagonal, mirrored across the arc
    np.testing.assert_allclose(sol.minus, sol.minus[::-1])


def test_near_the_inverse_singularity_the_velocity_ellipse_collapses_and_the_force_ellipse_grows():
    demo = demo_by_key("inverse")
    pose = demo_pose(demo, P)
    jac = jacobians(P, pose.p)
    assert abs(jac.jq[0, 0]) < 0.2  # cos θ1 in the warning band of eq. (11)
    ell = manipulability_ellipses(P, pose.p)
    assert min(ell.velocity.radii) < 0.2 and max(ell.force.radii) > 5.0
    axis = ell.velocity.axes[:, np.argmin(ell.velocity.radii)]
    assert abs(axis[1]) > 0.95  # it collapses along e2, along leg 1's links


def test_lesson_1_states_the_forces_per_actuator_as_the_panel_shows_them():
    """Issue 13: the lesson said 179 N (the norm of τ) where the panel showed 126.3 N per actuator. Its numbers are
    now each actuator's force, here recomputed by the Pinocchio closed-loop model at the motion's two ends."""
    demo = demo_by_key("direct")
    params, source = demo_params(demo), demo_source(demo)
    t = np.array([0.0, source.duration])
    p, dp, ddp = source.motion(t)
    text = str(effect(demo))
    for k, where in ((0, "at the start"), (1, "at the end")):
        tau = pinocchio_forces(params, p[k], dp[k], ddp[k])
        assert f"({tau[0]:.1f}, {tau[1]:.1f}) N {where}" in text
    end = pinocchio_forces(params, p[1], dp[1], ddp[1])
    assert np.max(np.abs(end)) < 0.8 * np.linalg.norm(end)  # the norm (179 N) would differ from what is shown
    assert f"{np.linalg.norm(end):.0f} N" not in text
