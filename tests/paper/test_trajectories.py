"""Trajectories: the cubic time law, the paper's line and circle, the spline for users' paths, CSV parsing."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz import (
    InputError,
    circle_state,
    line_state,
    paper_trajectory,
    parse_trajectory_csv,
    trajectory_from_samples,
)
from tpm_viz.paper.spline import CubicSpline


@pytest.mark.parametrize("kind", ["line", "circle"])
def test_endpoints_and_rest_at_both_ends(kind):
    traj = paper_trajectory(kind, samples=51)
    start, end = {"line": ([-0.1, -0.05], [0.1, 0.05]), "circle": ([0.1, 0.0], [0.1, 0.0])}[kind]
    assert traj.p[0] == pytest.approx(start, abs=1e-15)
    assert traj.p[-1] == pytest.approx(end, abs=1e-15)
    assert traj.dp[0] == pytest.approx([0, 0], abs=1e-15) and traj.dp[-1] == pytest.approx([0, 0], abs=1e-12)
    assert traj.duration == pytest.approx({"line": 0.2, "circle": 0.5}[kind])


@settings(max_examples=examples(40), deadline=None, derandomize=True)
@given(kind=st.sampled_from(["line", "circle"]), duration=st.floats(0.05, 5.0), t=st.floats(0.01, 0.99))
def test_analytic_derivatives_match_finite_differences(kind, duration, t):
    state = line_state if kind == "line" else circle_state
    t = t * duration
    h = 1e-6 * duration
    p_m, p_0, p_p = (state(np.array(x), duration)[0] for x in (t - h, t, t + h))
    _, dp, ddp = state(np.array(t), duration)
    assert dp == pytest.approx((p_p - p_m) / (2 * h), rel=1e-6, abs=1e-9)
    assert ddp == pytest.approx((p_p - 2 * p_0 + p_m) / h**2, rel=1e-3, abs=1e-3 / duration**2)


def test_circle_stays_on_the_circle_and_turns_once_counter_clockwise():
    traj = paper_trajectory("circle", samples=401)
    assert np.linalg.norm(traj.p, axis=1) == pytest.approx(np.full(401, 0.1), abs=1e-15)
    angle = np.unwrap(np.arctan2(traj.p[:, 1], traj.p[:, 0]))
    assert angle[-1] - angle[0] == pytest.approx(2 * np.pi) and np.all(np.diff(angle) >= 0)


def test_spline_interpolates_and_differentiates_smooth_data():
    t = np.linspace(0, 1, 201)
    y = np.stack([np.sin(3 * t), t**2], -1)
    s = CubicSpline(t, y)
    assert s(t) == pytest.approx(y, abs=1e-15)
    mid = t[50:150]
    assert s(mid, 1)[:, 0] == pytest.approx(3 * np.cos(3 * mid), abs=1e-4)
    assert s(mid, 2)[:, 0] == pytest.approx(-9 * np.sin(3 * mid), abs=2e-3)
    assert s(np.array([0.0, 1.0]), 2) == pytest.approx(np.zeros((2, 2)), abs=1e-12)  # natural ends


def test_csv_trajectory_reproduces_the_paper_circle_away_from_the_ends():
    ref = paper_trajectory("circle", samples=501)
    text = "t,p1,p2\n" + "\n".join(f"{t:.17g},{x:.17g},{y:.17g}" for t, (x, y) in zip(ref.t, ref.p, strict=True))
    traj = parse_trajectory_csv(text)
    inner = slice(50, -50)
    assert traj.dp[inner] == pytest.approx(ref.dp[inner], abs=1e-4 * np.abs(ref.dp).max())
    assert traj.ddp[inner] == pytest.approx(ref.ddp[inner], abs=1e-3 * np.abs(ref.ddp).max())


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("", "is empty"),
        ("t,p1\n0,1\n", "missing column 'p2'"),
        ("t,p1,p2\n0,0,0\n1,x,0\n2,0,0\n3,0,0\n", "'x' is not a number"),
        ("t,p1,p2\n0,0,0\n1,nan,0\n2,0,0\n3,0,0\n", "not finite"),
        ("t,p1,p2\n0,0,0\n1,0,0\n1,0,0\n3,0,0\n", "increase strictly"),
        ("t,p1,p2\n0,0,0\n1,0,0\n", "at least 4 samples"),
        ("t,p1,p2\n0,0,0\n1,0\n2,0,0\n3,0,0\n", "row 3 has 2 cells"),
    ],
)
def test_csv_errors_are_one_line_and_name_the_problem(text, message):
    with pytest.raises(InputError, match=message) as exc:
        parse_trajectory_csv(text)
    assert "\n" not in str(exc.value)


def test_bad_durations_and_kinds():
    for bad in (0, -1, float("nan"), float("inf"), "soon"):
        with pytest.raises(InputError, match="duration"):
            paper_trajectory("line", bad)
    with pytest.raises(InputError, match="'line' or 'circle'"):
        paper_trajectory("spiral")
    with pytest.raises(InputError, match="samples"):
        paper_trajectory("line", samples=1)
    with pytest.raises(InputError, match="shape"):
        trajectory_from_samples(np.arange(5.0), np.zeros((5, 3)))
