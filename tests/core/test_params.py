"""Parameter validation: the rules, the paper's values, and the workspace-existence rule checked by search."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
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


@pytest.mark.parametrize(
    ("name", "value", "words"),
    [
        ("l_a", 1e154, "l_a must be between 0.001 and 100000 mm, got 1e+157 mm"),
        ("a", 1e-300, "a must be between 0.001 and 100000 mm, got 1e-297 mm"),
        ("m_p", 1e9, "m_p must be between 1e-09 and 10000 kg, got 1e+09 kg"),
    ],
)
def test_absurd_magnitudes_are_refused_in_the_fields_units(name, value, words):
    with pytest.raises(InvalidParametersError) as exc:
        Params.paper(**{name: value})
    assert words in str(exc.value)


@pytest.mark.parametrize(("name", "unit"), [("b", "mm"), ("stroke", "mm"), ("m_a", "kg")])
def test_a_negative_value_is_refused_in_the_fields_unit(name, unit):
    with pytest.raises(InvalidParametersError) as exc:
        Params.paper(**{name: -0.25})
    shown = "-250" if unit == "mm" else "-0.25"
    assert f"{name} must be positive, got {shown} {unit}" in str(exc.value)


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


@settings(max_examples=examples(60), deadline=None, derandomize=True)
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


# --- refusals phrased as the fix: the bound stated is the boundary of the valid set ---------------------------------

_FIX = re.compile(r"^(l_a|a|b|the stroke Δd) must be at (least|most) (\d+\.\d) mm")
_ALTERNATIVE = re.compile(r"\(or (l_a|a|b|the stroke Δd) at (least|most) (\d+\.\d) mm\)")
_FIELD = {"l_a": "l_a", "a": "a", "b": "b", "the stroke Δd": "stroke"}


def _accepted(**values) -> bool:
    try:
        Params.paper(**values)
    except InvalidParametersError:
        return False
    return True


def _boundary(base: dict, name: str, lo: float, hi: float) -> float:
    """The value of ``name`` [m] where the validator switches, by bisection on the validator alone (``lo`` and
    ``hi`` are on opposite sides)."""
    ok_lo = _accepted(**{**base, name: lo})
    assert ok_lo != _accepted(**{**base, name: hi})
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        if _accepted(**{**base, name: mid}) == ok_lo:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def _check_bound(base: dict, label: str, side: str, shown_mm: str) -> None:
    name = _FIELD[label]
    value = float(shown_mm) * 1e-3
    assert _accepted(**{**base, name: value}), (name, value)
    behind = (float(shown_mm) - 0.1 if side == "least" else float(shown_mm) + 0.1) * 1e-3  # as typed in mm
    assert not _accepted(**{**base, name: behind}), (name, behind)
    # the edge, between the refused value of the set and the accepted number shown, lies within 0.1 mm behind it
    exact = _boundary(base, name, base.get(name, getattr(Params.paper(), name)), value)
    assert min(value, behind) - 1e-12 <= exact <= max(value, behind) + 1e-12
    # and it is the edge: just past it accepted, just before refused
    step = 1e-9 if side == "least" else -1e-9
    assert _accepted(**{**base, name: exact + step})
    assert not _accepted(**{**base, name: exact - step})


@pytest.mark.parametrize(
    ("prior", "changes", "first"),
    [
        ({}, {"l_a": 0.05}, "l_a"),  # the issue's set: a − b − √2 l_a = 319 mm > stroke 300 mm
        ({}, {"stroke": 0.015}, "the stroke Δd"),
        ({}, {"a": 0.9}, "a"),
        ({"a": 0.75}, {"b": 0.06}, "b"),
        ({"a": 0.1, "b": 0.25, "l_a": 0.2, "pivot_spacing": 0.01}, {"l_a": 0.12}, "l_a"),  # sliders behind d = 0
        ({"a": 0.1, "b": 0.25, "l_a": 0.2, "pivot_spacing": 0.01}, {"a": 0.04}, "a"),
        ({"a": 0.1, "b": 0.25, "l_a": 0.2, "pivot_spacing": 0.01}, {"b": 0.35}, "b"),
    ],
)
def test_an_empty_workspace_is_refused_with_the_bound_that_fixes_it(prior, changes, first):
    """ "l_a must be at least 63.7 mm with a = 482 mm, ...": in mm, the field just changed first, and both the bound
    and the alternative offered are the edge of the valid set, found by bisection on the validator."""
    with pytest.raises(InvalidParametersError) as exc:
        Params.paper(**prior).replace(**changes)
    message = str(exc.value)
    fix, alternative = _FIX.match(message), _ALTERNATIVE.search(message)
    assert fix is not None, message
    assert fix.group(1) == first
    assert "no reachable pose inside the stroke" in message and " m " not in message and "\n" not in message
    base = {**prior, **changes}
    _check_bound(base, *fix.groups())
    if alternative is not None:  # a second field that fixes it alone, if there is one
        assert alternative.group(1) != first
        _check_bound(base, *alternative.groups())
    else:
        assert changes == {"l_a": 0.05}  # only l_a: a longer stroke would leave the pivot spacing 60 mm > l_a


def test_the_issues_example_reads_as_the_fix():
    with pytest.raises(InvalidParametersError) as exc:
        Params.paper(l_a=0.05)
    # (482 - 92 - 300) / sqrt(2) = 63.64 mm, rounded up to the next 0.1 mm
    assert str(exc.value).startswith(
        "l_a must be at least 63.7 mm with a = 482 mm, b = 92 mm and the stroke Δd = 300 mm"
    )
