"""Parameter validation: the rules, the paper's values, and the workspace-existence rule checked by search."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tpm_viz import InvalidParametersError, Params, in_stroke, inverse_kinematics


def test_paper_values_are_tables_1_and_2():
    """Values transcribed from the paper's Tables 1-2 (m_b = 2 x 0.42 kg)."""
    p = Params.paper()
    assert (p.a, p.b, p.l_a, p.stroke) == (0.482, 0.092, 0.260, 0.300)
    assert (p.m_a, p.m_p) == (0.95, 2.21)
    assert p.m_b == pytest.approx(2 * 0.42)


@pytest.mark.parametrize("name", ["a", "b", "l_a", "m_a", "m_b", "m_p", "stroke", "pivot_spacing"])
@pytest.mark.parametrize("value", [0.0, -1.0, float("nan"), float("inf")])
def test_bad_values_are_refused_naming_the_parameter(name, value):
    with pytest.raises(InvalidParametersError, match=name) as exc:
        Params.paper(**{name: value})
    assert "\n" not in str(exc.value)


@pytest.mark.parametrize(("name", "value"), [("l_a", 1e154), ("a", 1e-300), ("m_p", 1e9)])
def test_absurd_magnitudes_are_refused(name, value):
    with pytest.raises(InvalidParametersError, match=f"{name} = .* outside the supported range"):
        Params.paper(**{name: value})


def test_non_numbers_and_unknown_names_are_refused():
    with pytest.raises(InvalidParametersError, match="a must be a number"):
        Params(a="big")
    with pytest.raises(InvalidParametersError, match="unknown parameter 'l_b'"):
        Params.paper().replace(l_b=0.3)
    with pytest.raises(InvalidParametersError, match="m_p must be a number"):
        Params.paper().with_overrides({"m_p": "heavy"})


def test_replace_and_overrides_validate_and_keep_the_original():
    p = Params.paper()
    q = p.with_overrides({"l_a": "0.3", "m_p": 3})
    assert (q.l_a, q.m_p, p.l_a) == (0.3, 3.0, 0.26)
    with pytest.raises(InvalidParametersError):
        p.replace(l_a=0.05)  # pivot spacing 0.06 would exceed the link length
    assert p == Params.paper()


def _has_valid_pose(params: Params, n: int = 401) -> bool:
    """Brute-force search of a reachable, in-stroke pose on a fine grid (independent of the rule)."""
    xs = np.linspace(-params.l_a, params.l_a, n)[1:-1]
    grid = np.stack(np.meshgrid(xs, xs), -1).reshape(-1, 2)
    return bool(np.any(in_stroke(params, inverse_kinematics(params, grid))))


@settings(max_examples=60, deadline=None, derandomize=True)
@given(k=st.floats(-0.6, 0.8), stroke=st.floats(0.01, 0.5))
def test_workspace_rule_matches_a_grid_search(k, stroke):
    """The constructor accepts a geometry iff a grid search finds a reachable pose inside the stroke."""
    l_a = 0.26
    margin = 0.01  # stay off the exact boundary, where a finite grid cannot decide
    lower, upper = k - math.sqrt(2) * l_a, k + l_a
    if abs(lower - stroke) < margin or abs(upper) < margin:
        return
    try:
        params = Params(a=0.4 + k, b=0.4, l_a=l_a, stroke=stroke)
    except InvalidParametersError:
        # Rejected: a grid search on the raw eq. (4) must find no pose with both d_i in the stroke.
        xs = np.linspace(-l_a, l_a, 401)[1:-1]
        g = np.stack(np.meshgrid(xs, xs), -1)
        d = g + k - np.sqrt(l_a**2 - g[..., ::-1] ** 2)
        assert not np.any(np.all((d >= 0) & (d <= stroke), axis=-1))
    else:
        assert _has_valid_pose(params)
