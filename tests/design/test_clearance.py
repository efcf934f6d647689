"""Plan-view clearance (tpm_viz/design/clearance.py) against an independent route: the parts built here from the
drawn mechanism (``mechanism_pose``: both links of each parallelogram, the rails from the slider joints at d = 0 and
Δd) and intersected with orientation tests (proper edge crossings, a vertex strictly inside), not separating axes;
hand-made designs that cross, that come within a millimetre without crossing, and that cross only between the
poses of a coarse grid."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, say
from tpm_viz.design.clearance import collision, rail_problem, separations
from tpm_viz.design.indices import Task, evaluate
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

PERP, PAR = Arrangement.PERPENDICULAR, Arrangement.PARALLEL


def _cross(o: np.ndarray, a: np.ndarray, b: np.ndarray) -> float:
    return float((a[0] - o[0]) * (b[1] - o[1]) - (a[1] - o[1]) * (b[0] - o[0]))


def _segments_cross(p, q, r, s) -> bool:
    """Whether segments pq and rs cross at a point inside both (strictly: touching is not crossing)."""
    d1, d2 = _cross(r, s, p), _cross(r, s, q)
    d3, d4 = _cross(p, q, r), _cross(p, q, s)
    return d1 * d2 < 0 and d3 * d4 < 0


def _inside(point, polygon) -> bool:
    """Whether ``point`` is strictly inside the convex ``polygon`` (vertices in order)."""
    signs = [_cross(polygon[k], polygon[(k + 1) % len(polygon)], point) for k in range(len(polygon))]
    return all(s > 0 for s in signs) or all(s < 0 for s in signs)


def _overlap(one, two) -> bool:
    """Whether two convex shapes (a segment is two vertices) share interior points: an edge crossing or a vertex of
    one strictly inside the other."""
    edges = [(one[k], one[(k + 1) % len(one)]) for k in range(len(one))]
    others = [(two[k], two[(k + 1) % len(two)]) for k in range(len(two))]
    if any(_segments_cross(*e, *f) for e in edges for f in others):
        return True
    inside_two = len(two) > 2 and any(_inside(v, two) for v in one)
    inside_one = len(one) > 2 and any(_inside(v, one) for v in two)
    return inside_two or inside_one


def _parts(arrangement: Arrangement, params: Params, p: np.ndarray):
    """Both legs (parallelograms from the drawn links) and both rails, from ``mechanism_pose``."""
    pose = arr.mechanism_pose(arrangement, params, p)
    legs = [
        np.array([pose.links[i, 0, 0], pose.links[i, 0, 1], pose.links[i, 1, 1], pose.links[i, 1, 0]]) for i in (0, 1)
    ]
    home = np.zeros(2) if arrangement is PERP else arr.home(PAR, params)
    start = arr.mechanism_pose(arrangement, params, home, np.zeros(2)).A
    end = arr.mechanism_pose(arrangement, params, home, np.full(2, params.stroke)).A
    rails = [np.array([start[i], end[i]]) for i in (0, 1)]
    return legs, rails


def _crossings(arrangement: Arrangement, params: Params, p: np.ndarray) -> list[bool]:
    """Leg 1 over rail 2, leg 2 over rail 1, the legs crossing, by the orientation tests."""
    legs, rails = _parts(arrangement, params, p)
    return [_overlap(legs[0], rails[1]), _overlap(legs[1], rails[0]), _overlap(legs[0], legs[1])]


def _random_design(rng: np.random.Generator, arrangement: Arrangement) -> Params | None:
    a = rng.uniform(0.15, 0.6)
    try:
        params = Params.paper(
            a=a,
            b=rng.uniform(0.03, 0.12),
            l_a=rng.uniform(0.12, 0.35),
            stroke=rng.uniform(0.1, 0.98 * a),
            pivot_spacing=rng.uniform(0.02, 0.08),
        )
        return arr.validate(arrangement, params)
    except TpmVizError:
        return None


@pytest.mark.parametrize("arrangement", list(Arrangement))
def test_the_separation_of_every_pair_has_the_sign_of_the_orientation_tests(arrangement):
    rng = np.random.default_rng(11)
    seen = np.zeros((3, 2), dtype=int)  # per pair: apart, crossing
    for _ in range(600):
        params = _random_design(rng, arrangement)
        if params is None:
            continue
        reach = 0.9 * params.l_a
        if arrangement is PERP:
            p = rng.uniform(-reach, reach, 2)
        else:
            p = np.array([rng.uniform(-0.3, 0.3), rng.choice([-1, 1]) * rng.uniform(0.2 * params.l_a, reach)])
        sigma = separations(arrangement, params, p[None])[0]
        expected = _crossings(arrangement, params, p)
        for k in range(3):
            if abs(sigma[k]) < 1e-9:
                continue  # touching: either answer
            assert (sigma[k] < 0) == expected[k], (k, params, p, sigma)
            seen[k, int(expected[k])] += 1
    assert np.all(seen[:2] > 10), seen  # both outcomes of each leg-over-rail pair were tried
    if arrangement is PERP:
        assert seen[2, 0] > 10, seen  # legs crossing are rare here: test_the_two_legs_crossing_are_found
    else:
        assert seen[2, 1] == 0  # the parallel legs stand on either side of the platform: they never cross


def test_a_leg_over_the_other_rail_is_infeasible_and_says_where():
    """Leg 1 reaches past x = 0 (p1 > b) over rail 2, which ends at y = Δd - a = -50 mm."""
    params = Params.paper(a=0.5, stroke=0.45)
    task = Task(0.10, 0.14, -0.12, -0.08)
    got = evaluate(PERP, params, task)
    assert not got.feasible
    text = str(got.why)
    assert text.startswith("leg 1 runs over rail 2 in plan view with the platform at (")
    x, y = (float(v) / 1e3 for v in text.split("at (")[1].split(")")[0].split(","))
    assert task.x0 <= x <= task.x1 and task.y0 <= y <= task.y1
    assert _crossings(PERP, params, np.array([x, y]))[0]
    assert "레일 2" in say(Lang.KO, got.why) and "다리 1" in say(Lang.KO, got.why)
    clear = evaluate(PERP, params, Task(-0.05, 0.05, -0.12, -0.08))  # the same design, the task left of x = b
    assert clear.feasible, clear.why


def test_a_crossing_between_the_grid_poses_is_found():
    """Leg 1 over rail 2 only for p1 in about (93, 210) mm at p2 = -100 mm: the four corners of the rectangle
    0 <= p1 <= 250 mm are clear, the certificate splits the cells until it finds the crossing inside."""
    params = Params.paper(a=0.3, stroke=0.25)
    xs, ys = np.array([0.0, 0.25]), np.array([-0.1005, -0.0995])
    corners = np.array([[x, y] for x in xs for y in ys])
    assert np.all(separations(PERP, params, corners) > 0)
    assert not any(any(_crossings(PERP, params, c)) for c in corners)
    why = collision(PERP, params, xs, ys)
    assert why is not None and str(why).startswith("leg 1 runs over rail 2")
    x = float(str(why).split("at (")[1].split(",")[0]) / 1e3
    assert _crossings(PERP, params, np.array([x, -0.1]))[0] or _crossings(PERP, params, np.array([x, -0.0995]))[0]


def test_parts_a_millimetre_apart_are_clear_over_the_whole_rectangle():
    """The same geometry with rail 2 ending at y = -101 mm: leg 1 passes 1 mm above its end (at p1 = b)."""
    params = Params.paper(a=0.3, stroke=0.199)
    xs, ys = np.array([0.0, 0.25]), np.array([-0.1, -0.0995])
    dense = np.stack(np.meshgrid(np.linspace(0.0, 0.25, 501), ys, indexing="ij"), -1).reshape(-1, 2)
    sigma = separations(PERP, params, dense)[:, 0]
    assert 0.0 < sigma.min() <= 1e-3 + 1e-12  # close: the certificate must split cells to clear it
    assert not any(_crossings(PERP, params, p)[0] for p in dense[::10])
    assert collision(PERP, params, xs, ys) is None


def test_the_two_legs_crossing_are_found():
    """With p1, p2 > b + sqrt(l_a² - p_j²) each leg starts beyond the other's slider: leg 1 runs from (34, 0) mm
    to (200, 250) mm, leg 2 from (0, 34) mm to (250, 200) mm, an X."""
    params = Params.paper(a=0.45, b=0.05, l_a=0.3, stroke=0.44, pivot_spacing=0.06)
    p = np.array([0.25, 0.25])
    assert _crossings(PERP, params, p)[2]
    assert separations(PERP, params, p[None])[0, 2] < 0
    why = collision(PERP, params, np.array([0.24, 0.25]), np.array([0.24, 0.25]))
    assert why is not None and str(why).startswith(("the two legs cross", "leg "))


@pytest.mark.parametrize(("arrangement", "word"), [(PERP, "cross in plan view"), (PAR, "overlap on the X axis")])
def test_rails_that_meet_are_refused_with_the_bound(arrangement, word):
    params = Params.paper(a=0.3, stroke=0.3)
    why = rail_problem(arrangement, params)
    assert why is not None and word in str(why) and "300.0 mm" in str(why)
    assert rail_problem(arrangement, Params.paper(a=0.3, stroke=0.299)) is None
    _, rails = _parts(arrangement, params, np.array([0.0, 0.1]))
    for rail in rails:  # Δd = a: both rails reach the origin, where they meet
        assert min(np.linalg.norm(rail, axis=1)) < 1e-12


def test_the_prototype_is_clear_over_the_standard_tasks():
    paper = Params.paper()
    for arrangement, task in ((PERP, Task(-0.1, 0.1, -0.05, 0.05)), (PAR, Task(-0.1, 0.1, 0.05, 0.15))):
        assert evaluate(arrangement, paper, task).feasible
        dense = np.stack(np.meshgrid(np.linspace(-0.1, 0.1, 21), np.linspace(task.y0, task.y1, 11)), -1)
        assert not any(any(_crossings(arrangement, paper, p)) for p in dense.reshape(-1, 2))
