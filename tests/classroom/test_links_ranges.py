"""Hostile numbers in a share link (issue 35, item 8): a link whose uploaded trajectory had ``p = 1e308`` samples
opened without a word. Every numeric field a link carries is now held to a physically meaningful range, and
anything outside it (1e308, -1e308, subnormals, integers beyond float's range, NaN, inf) is refused in one line, in
the tab's language, like NaN. Tokens are made by hand from the documented layout (``tests/classroom/test_links.py``)."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.classroom.test_links import _saved, _token
from tests.support.hypo import examples
from tpm_viz.app.inputs import MAX_UPLOAD_POSITION, MAX_UPLOAD_SECONDS
from tpm_viz.app.transitions import MAX_ACCEL, MAX_FORCE, MAX_POSITION, MAX_SPEED
from tpm_viz.classroom.links import decode_link
from tpm_viz.classroom.sessionfile import encode_saved
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Lang, say
from tpm_viz.paper.spline import CubicSpline

RAW = encode_saved(_saved())


def _numbers(node, path=()):
    """The JSON path of every number of a link's state (booleans are not numbers here)."""
    if isinstance(node, dict):
        for key, value in node.items():
            yield from _numbers(value, (*path, key))
    elif isinstance(node, list):
        for k, value in enumerate(node):
            yield from _numbers(value, (*path, k))
    elif isinstance(node, int | float) and not isinstance(node, bool):
        yield path


PATHS = sorted(_numbers(RAW), key=str)
HOSTILE = st.one_of(
    st.sampled_from([1e308, -1e308, 1.7976931348623157e308, 1e300, 1e20, -1e20, 5e-324, -5e-324, 1e-300]),
    st.sampled_from([math.nan, math.inf, -math.inf, 10**400, -(10**400), 2**63, 10**18]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.integers(min_value=-(10**30), max_value=10**30),
)


def _set(raw, path, value):
    node = raw
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value


def _in_range(saved) -> None:
    """Every number of a state that opened is one a browser could have typed or uploaded."""
    s = saved.state
    assert np.all(np.abs(s.pose.p) <= MAX_POSITION) and np.all(np.abs(s.pose.d) <= MAX_POSITION)
    assert np.all(np.abs(s.load.f_ext) <= MAX_FORCE) and np.all(np.abs(s.load.dp) <= MAX_SPEED)
    assert np.all(np.abs(s.load.ddp) <= MAX_ACCEL)
    assert 0 <= s.trajectory.t <= MAX_UPLOAD_SECONDS and 0 <= s.trajectory.duration <= MAX_UPLOAD_SECONDS
    assert 0 <= saved.playing_t <= MAX_UPLOAD_SECONDS
    if saved.source is not None and saved.source.knots is not None:
        t, p = saved.source.knots
        assert np.all(np.abs(p) <= MAX_UPLOAD_POSITION) and 0 < t[-1] - t[0] <= MAX_UPLOAD_SECONDS
        spline = CubicSpline(t, p)
        assert np.all(np.isfinite(spline(t, 1))) and np.all(np.isfinite(spline(t, 2)))


def _refused_in_one_line(token: str) -> InputError:
    with pytest.raises(InputError) as refused:
        decode_link(token)
    english, korean = str(refused.value), say(Lang.KO, refused.value)
    assert "\n" not in english and "\n" not in korean and english.startswith("the share link")
    assert korean != english and "공유 링크" in korean  # the tab's language
    return refused.value


@settings(max_examples=examples(400), deadline=None)
@given(path=st.sampled_from(PATHS), value=HOSTILE)
def test_a_hostile_number_anywhere_is_refused_in_one_line_or_is_within_range(path, value):
    raw = json.loads(json.dumps(RAW))
    _set(raw, path, value)
    token = _token(raw)  # json writes NaN and Infinity as such: a forger can too
    try:
        saved = decode_link(token)
    except InputError:
        _refused_in_one_line(token)
        return
    _in_range(saved)


@pytest.mark.parametrize(
    ("edit", "why"),
    [
        (lambda r: [row.__setitem__(0, 1e308) for row in r["trajectory"]["p"]], "goes beyond 10 m"),
        (lambda r: r["trajectory"]["t"].__setitem__(-1, 1e308), "lasts more than 3600 s"),
        (lambda r: r["trajectory"]["t"].__setitem__(1, 5e-324), "too close in time"),
        (lambda r: r["load"].__setitem__("f_ext", [1e308, 0.0]), "load.f_ext must be from -100000 to 100000 N"),
        (lambda r: r["load"].__setitem__("ddp", [0.0, -1e6]), "load.ddp must be from"),
        (lambda r: r.__setitem__("player_t", 1e308), "player_t must be from 0 to 3600 s"),
        (lambda r: r["sample"].__setitem__("duration", -1.0), "sample.duration must be from 0 to 3600 s"),
        (lambda r: r.__setitem__("p", [1e308, 0.0]), "p must be from -10 to 10 m"),
        (lambda r: r.__setitem__("player_t", 10**400), "player_t is not finite"),
    ],
    ids=["p-1e308", "t-1e308", "t-subnormal", "f_ext", "ddp", "player_t", "duration", "pose", "int-1e400"],
)
def test_the_issues_link_and_its_kin_are_refused_saying_which_field(edit, why):
    raw = json.loads(json.dumps(RAW))
    edit(raw)
    assert why in str(_refused_in_one_line(_token(raw)))


def test_a_link_within_the_ranges_still_opens():
    raw = json.loads(json.dumps(RAW))
    raw["load"]["f_ext"] = [MAX_FORCE, -MAX_FORCE]  # the ends of the ranges are in them
    raw["player_t"] = 0.4
    saved = decode_link(_token(raw))
    _in_range(saved)
    assert saved.state.load.f_ext == (MAX_FORCE, -MAX_FORCE)
