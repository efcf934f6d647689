"""Force arrows: a bounded, monotone length (:func:`tpm_viz.app.overlays.arrow_length`) and the 3D scene using it.

The expected lengths are recomputed here from the rule the docstrings state (``L u / (1 + u)``, ``u = ln(1 + F /
50 N)``, ``L = 0.15 (a + l_a)``), and the small-force slope from the parameters alone (``L / 50 N``).
"""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.fake_viser import FakeApi
from tests.support.hypo import examples
from tpm_viz.app.overlays import arrow_length, arrow_reach, arrow_vector
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.state import AppState
from tpm_viz.classroom.snapshot import Snapshot
from tpm_viz.core.params import Params
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.ui.scene import MechanismScene

P = Params.paper()
REACH = 0.15 * (0.482 + 0.260)  # m: 0.15 (a + l_a) of the paper's prototype
SLOPE = REACH / 50.0  # m/N for small forces (2.2 mm per newton)
SETTINGS = settings(max_examples=examples(300), deadline=None, derandomize=True)
FORCE = st.floats(1e-3, 1e12)


def expected(force: float, reach: float = REACH) -> float:
    u = math.log1p(abs(force) / 50.0)
    return reach * u / (1.0 + u)


def test_reach_is_a_fixed_fraction_of_the_mechanism():
    assert arrow_reach(P) == pytest.approx(REACH, rel=1e-12)
    big = P.replace(a=2.0, l_a=1.0, b=0.5, stroke=1.5)
    assert arrow_reach(big) == pytest.approx(0.15 * 3.0, rel=1e-12)


@SETTINGS
@given(FORCE)
def test_bounded_below_the_reach(force):
    length = arrow_length(force, P)
    assert 0.0 < length < arrow_reach(P)
    assert length == pytest.approx(expected(force), rel=1e-12)
    assert arrow_length(-force, P) == length  # the length of |force|; the sign is the arrow's direction


@SETTINGS
@given(FORCE, st.floats(1e-6, 10.0))
def test_strictly_increasing(force, more):
    assert arrow_length(force, P) < arrow_length(force * (1.0 + more), P)


@pytest.mark.parametrize("force", [1e-3, 1e-2, 0.1])
def test_linear_for_small_forces_with_the_stated_slope(force):
    # u/(1+u) = F/50 - (3/2)(F/50)² + ...: relative departure from the line below 2 F / 50 N
    assert arrow_length(force, P) == pytest.approx(SLOPE * force, rel=2 * force / 50.0)
    assert arrow_length(2 * force, P) == pytest.approx(2 * arrow_length(force, P), rel=2 * force / 50.0)


def test_half_the_reach_at_e_minus_one_times_50_newton():
    assert arrow_length((math.e - 1.0) * 50.0, P) == pytest.approx(REACH / 2, rel=1e-12)


def test_non_finite_forces_and_arrays():
    values = arrow_length(np.array([math.nan, math.inf, -math.inf, 0.0, -0.0, 1e308, 20.0]), P)
    assert values.shape == (7,) and np.all(np.isfinite(values))
    np.testing.assert_allclose(values[:5], [0.0, REACH, REACH, 0.0, 0.0], rtol=1e-12)
    assert values[5] < REACH and values[6] == pytest.approx(expected(20.0), rel=1e-12)
    assert isinstance(arrow_length(1.0, P), float)


@SETTINGS
@given(st.floats(-1e9, 1e9), st.floats(-1e9, 1e9))
def test_vector_along_the_force(fx, fy):
    vec = arrow_vector((fx, fy), P)
    norm = math.hypot(fx, fy)
    assert np.all(np.isfinite(vec)) and math.hypot(*vec) < REACH
    if norm == 0.0:
        assert np.all(vec == 0.0)
        return
    assert math.hypot(*vec) == pytest.approx(expected(norm), rel=1e-9)
    np.testing.assert_allclose(vec / math.hypot(*vec), np.array([fx, fy]) / norm, atol=1e-12)  # along the force


def test_vector_of_non_finite_forces():
    assert np.all(arrow_vector((math.nan, 1.0), P) == 0.0)
    np.testing.assert_allclose(arrow_vector((math.inf, 5.0), P), [REACH, 0.0], rtol=1e-12)
    np.testing.assert_allclose(arrow_vector((-math.inf, math.inf), P), [-REACH, REACH] / np.sqrt(2), rtol=1e-12)


# -- the 3D scene draws these lengths -------------------------------------------------------------------------------
def _drawn(f_ext):
    """The scene's two actuator arrows and the load arrow at the home pose under the static load ``f_ext`` [N]."""
    state = AppState.initial(P).replace(load=Load(f_ext=f_ext))
    scene = MechanismScene(FakeApi(), P)
    scene.update(Snapshot(state, evaluate(P, state.pose, state.load)))
    return scene


@pytest.mark.parametrize("force", [20.0, 175.0, 1e3, 1e9])
def test_scene_arrows_have_the_bounded_length(force):
    # At the home pose J = I (both links along their rails): τ = -f_ext (eq. 13).
    scene = _drawn((0.0, -force))
    assert not scene.forces[0].visible and scene.forces[1].visible
    start, tip = np.asarray(scene.forces[1].points, dtype=float)[0]
    np.testing.assert_allclose(tip - start, [0.0, expected(force), 0.0], rtol=1e-6, atol=1e-9)
    assert tuple(np.asarray(scene.forces[1].colors).ravel()) == tuple(PALETTE["tau_pos"])  # τ2 > 0: along +e2
    assert scene.load_arrow.visible
    start, tip = np.asarray(scene.load_arrow.points, dtype=float)[0]
    np.testing.assert_allclose(tip - start, [0.0, -expected(force), 0.0], rtol=1e-6, atol=1e-9)


def test_scene_negative_force_points_back_along_the_rail():
    scene = _drawn((300.0, 0.0))  # τ1 = -300 N
    start, tip = np.asarray(scene.forces[0].points, dtype=float)[0]
    np.testing.assert_allclose(tip - start, [-expected(300.0), 0.0, 0.0], rtol=1e-6, atol=1e-9)
    assert tuple(np.asarray(scene.forces[0].colors).ravel()) == tuple(PALETTE["tau_neg"])


def test_scene_hides_arrows_shorter_than_a_millimetre():
    scene = _drawn((0.0, -0.3))  # 0.3 N: 0.67 mm
    assert not scene.forces[1].visible and not scene.load_arrow.visible
    scene = _drawn((0.0, -0.5))  # 0.5 N: 1.1 mm
    assert scene.forces[1].visible and scene.load_arrow.visible
