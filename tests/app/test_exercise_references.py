"""Every reference answer by an independent route (the grader computes them with the closed form only).

- ``force-at-pose``: Pinocchio's constrained inverse dynamics (``tpm_viz.multibody``);
- ``direct-singularity-diagonal``: a numerical root (scipy's brentq) of ``cos(θ1 + θ2)`` along the diagonal, the
  angles taken from the link vectors ``B_i - A_i`` of the geometry (``A_i = (d_i - a) e_i``, ``B_i = P - b e_i``);
- ``modes-merge-stroke``: a root of the discriminant of the two leg circles' intersection (the modes merge where
  the circles touch);
- ``actuator-position``, ``leg-angle``, ``nearer-inverse-leg``: the link vectors (length ``l_a``, working branch);
- ``peak-force-scaling``: Pinocchio along the circle in ``t2``;
- ``zero-force-pose``: Pinocchio's ``τ1`` at the revealed pose, the stroke and the warning thresholds;
- ``tune-ctc``: the control lab's own simulation on the Pinocchio plant (``multibody.control.simulate``): the
  revealed gains pass, the gains just outside fail, and the lab and the grader give the same verdict on a grid.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from scipy.optimize import brentq

from tpm_viz.app.exercises.catalogue import by_id
from tpm_viz.app.exercises.gains import GRID, RMS_LIMIT, just_outside, verdict
from tpm_viz.app.exercises.grading import reference, variant_of
from tpm_viz.multibody import inverse_dynamics as pinocchio_forces
from tpm_viz.multibody.control import ControlSetup, simulate
from tpm_viz.paper.control import Gains
from tpm_viz.paper.trajectories import circle_state

SEEDS = range(12)


def _case(ident: str, seed: int):
    exercise = by_id(ident).exercise
    variant = variant_of(exercise, seed)
    return exercise, variant, reference(exercise, variant)


def _links(params, p):
    """Link vectors of both legs (unit, from A_i to B_i) with the working-mode slider positions found by a root of
    ``|B_i - A_i| = l_a`` on the base side of the platform."""
    a, b, la = params.a, params.b, params.l_a
    out = []
    for i in (0, 1):
        j = 1 - i

        def gap(d, i=i, j=j):
            return (p[i] - b - (d - a)) ** 2 + p[j] ** 2 - la**2

        top = p[i] - b + a  # the slider right under the platform's joint: |B - A| = |p_j| < l_a
        d = brentq(gap, top - la - 1e-9, top)  # the slider on the base side (the working mode)
        vec = np.zeros(2)
        vec[i], vec[j] = p[i] - b - (d - a), p[j]
        out.append((d, vec / la))
    return out


def _angles(params, p):
    """``θ1`` from e1 towards e2 and ``θ2`` from e2 towards e1 (docs/conventions.md), from the link vectors."""
    (_, s1), (_, s2) = _links(params, p)
    return math.atan2(s1[1], s1[0]), math.atan2(s2[0], s2[1])


@pytest.mark.parametrize("seed", SEEDS)
def test_force_at_pose_is_pinocchio_s(seed):
    _, v, ref = _case("force-at-pose", seed)
    p, ddp = np.array([v["p1"], v["p2"]]), np.array([v["ddp1"], v["ddp2"]])
    tau = pinocchio_forces(v.params, p, np.zeros(2), ddp)
    assert ref[0] == pytest.approx(tau[0], rel=1e-9, abs=1e-9)


@pytest.mark.parametrize("seed", SEEDS)
def test_the_diagonal_meets_the_direct_singularity_where_cos_vanishes(seed):
    _, v, ref = _case("direct-singularity-diagonal", seed)
    la = v.params.l_a

    def measure(x):
        t1, t2 = _angles(v.params, np.array([x, x]))
        return math.cos(t1 + t2)

    root = brentq(measure, -0.999 * la, -1e-6, xtol=1e-14)
    assert ref[0] == pytest.approx(root * 1e3, abs=1e-6)


@pytest.mark.parametrize("seed", SEEDS)
def test_the_modes_merge_where_the_leg_circles_touch(seed):
    _, v, ref = _case("modes-merge-stroke", seed)
    a, b, la = v.params.a, v.params.b, v.params.l_a

    def discriminant(d):  # circles of radius l_a about (d - a + b, 0) and (0, d - a + b), both sliders at d
        centre = d - a + b
        distance = math.hypot(centre, centre)
        return (2 * la) ** 2 - distance**2

    root = brentq(discriminant, a - b - 2 * la, a - b, xtol=1e-14)  # the side towards the base
    assert ref[0] == pytest.approx(root * 1e3, abs=1e-6)


@pytest.mark.parametrize("seed", SEEDS)
def test_the_slider_angle_and_nearer_leg_from_the_link_vectors(seed):
    _, v, ref = _case("actuator-position", seed)
    (d1, _), _ = _links(v.params, np.array([v["p1"], v["p2"]]))
    assert ref[0] == pytest.approx(d1 * 1e3, abs=1e-6)
    _, v, ref = _case("leg-angle", seed)
    assert ref[0] == pytest.approx(math.degrees(_angles(v.params, np.array([v["p1"], v["p2"]]))[0]), abs=1e-9)
    _, v, ref = _case("nearer-inverse-leg", seed)
    (_, s1), (_, s2) = _links(v.params, np.array([v["p1"], v["p2"]]))
    assert ref == ("leg1" if abs(s1[0]) < abs(s2[1]) else "leg2")  # cos θ1 = s1·e1, cos θ2 = s2·e2


@pytest.mark.parametrize("seed", range(6))
def test_the_slower_circle_s_peak_is_pinocchio_s(seed):
    _, v, ref = _case("peak-force-scaling", seed)
    t = np.linspace(0.0, v["t2"], 801)
    peak = np.max(np.abs(pinocchio_forces(v.params, *circle_state(t, v["t2"]))))
    assert ref[0] == pytest.approx(peak, rel=2e-4)  # the grader samples the Player's grid, this a finer one


@pytest.mark.parametrize("seed", SEEDS)
def test_the_revealed_zero_force_pose_passes_pinocchio(seed):
    _, v, ref = _case("zero-force-pose", seed)
    p = np.array(ref) * 1e-3
    tau = pinocchio_forces(v.params, p, np.zeros(2), np.array([v["ddp1"], v["ddp2"]]))
    assert abs(tau[0]) <= 0.25 * v["tol"]
    links = _links(v.params, p)
    assert all(0.0 <= d <= v.params.stroke for d, _ in links)
    (_, s1), (_, s2) = links
    t1, t2 = _angles(v.params, p)
    assert min(abs(s1[0]), abs(s2[1])) >= 0.2 and math.cos(t1 + t2) >= 0.2  # the app's warning thresholds


def _lab(v, wn, zeta):
    err, limit = v["mass_error"], v["force_limit"]
    setup = ControlSetup(gains=Gains(wn, zeta), mass_error=(err,) * 3, force_limit=limit)
    try:
        run = simulate(v.params, "circle", setup)
    except Exception:  # the platform left the workspace: an unstable loop fails
        return False, math.inf
    return run.rms_error < RMS_LIMIT and not bool(run.saturated.any()), run.rms_error


@pytest.mark.parametrize("seed", range(8))
def test_the_revealed_gains_pass_the_control_lab_and_the_soft_ones_fail(seed):
    _, v, ref = _case("tune-ctc", seed)
    assert _lab(v, *ref)[0]
    soft = just_outside(v)
    assert soft is not None and not _lab(v, *soft)[0]


@pytest.mark.parametrize(  # one seed in the fast loop (the grid and the three dampings); the others in the full run
    "seed", [0, *(pytest.param(seed, marks=pytest.mark.slow) for seed in (1, 2))]
)
def test_the_lab_and_the_grader_agree_on_the_verdict(seed):
    """Over the whole grid and three dampings: the same pass or fail, the same RMS error where both are stable."""
    _, v, _ = _case("tune-ctc", seed)
    for zeta in (0.5, 1.0, 2.0):
        for wn in GRID:
            ours = verdict(v, wn, zeta)
            ok, rms = _lab(v, wn, zeta)
            assert ours.ok == ok, (wn, zeta, ours, rms)
            if ours.failure is None and math.isfinite(rms) and not ours.peak > v["force_limit"]:
                assert ours.rms == pytest.approx(rms, rel=1e-6)
