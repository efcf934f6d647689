"""Bad input everywhere, app side, without a browser: generated widget values through the app's update path.

The callbacks of ``tpm_viz.ui.client`` are ``transitions.<control>(state, raw widget values)`` plus
``Hub.commit``; these property tests drive exactly that path with values a hostile or careless browser could send
(NaN, ±inf, 1e300, negative and zero sizes, text such as ``"nan"`` or ``"1e999"`` that viser casts to floats,
None, booleans, lists of the wrong length, unreachable poses, impossible geometries) and check that

- every refusal is a ``TpmVizError`` with a one-line message, and the session keeps its last good state;
- every accepted state is valid (finite pose, on its leg branches, inside the stroke, clear of both singularities);
- nothing non-finite is ever written to a scene node or a panel widget (the real ``MechanismScene`` and ``Panel``
  run on checking stand-ins, ``tests/fake_viser.py``), and the readout, dashboard and equations hold no NaN/inf.

Generated inputs (``derandomize=True``, so every run is the same): sequences 1 500 examples x 1-6 controls
(~5 050 control inputs), single controls 5 000, uploads 1 200: ~11 250 app-side inputs, on top of the 10 200
library cases of ``test_robustness.py``. The real-server subset is in ``test_reliability_server.py``.
"""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.support.fake_viser import FakeView, assert_clean
from tests.support.hypo import examples
from tpm_viz import InputError, Params, TpmVizError
from tpm_viz.app import transitions as T
from tpm_viz.app.inputs import MAX_UPLOAD_BYTES, read_choice, read_flag, read_number, read_upload, read_vec2
from tpm_viz.app.moves import check, ik_branch
from tpm_viz.app.state import AppState
from tpm_viz.classroom.session import Hub
from tpm_viz.core.params import PARAM_INFO
from tpm_viz.paper.status import PoseStatus

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

P = Params.paper()
BAD_TEXT = re.compile(r"\bnan\b|\binf\b|infinity", re.IGNORECASE)


def _settings(n: int):
    return settings(
        max_examples=examples(n),
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )


# -- what a browser (or a hand-written client) can send ---------------------------------------------------------
NASTY_FLOAT = st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from(
    [0.0, -0.0, 1e-300, -1e-300, 1e300, -1e300, 1e308, -1e308, 5e-324]
)
NASTY = (
    NASTY_FLOAT
    | st.integers(-(10**6), 10**6)
    | st.sampled_from(["nan", "inf", "-inf", "1e999", "abc", "", " 12 ", "0x10", None, True, False])
    | st.lists(st.floats(allow_nan=True), max_size=3)
)
MM = st.floats(-600.0, 600.0) | st.sampled_from([260.0, -260.0, 259.999, 300.0, 299.9999, 0.0, -0.0])
M = st.floats(-0.6, 0.6) | st.sampled_from([0.26, -0.26, 0.2599999, 0.0])


def vec(component) -> st.SearchStrategy:
    return st.tuples(component, component) | NASTY


def mostly_valid(*valid: st.SearchStrategy) -> st.SearchStrategy:
    """Tuples of valid values, a third of them with one value replaced by a nasty one."""
    good = st.tuples(*valid)
    spoiled = st.tuples(good, st.integers(0, len(valid) - 1), NASTY).map(
        lambda g: (*g[0][: g[1]], g[2], *g[0][g[1] + 1 :])
    )
    return good | good | spoiled


NUM_MM = MM | NASTY
VEC_MM = vec(MM | NASTY_FLOAT)
PARAM_RAW = st.dictionaries(
    st.sampled_from(sorted(PARAM_INFO)),
    st.floats(0.5, 1500.0) | st.sampled_from([1e-9, 1e9, 0.0, -1.0]) | NASTY,
    max_size=4,
)

ACTIONS = st.one_of(
    st.tuples(st.just("drag"), st.tuples(M | NASTY_FLOAT, M | NASTY_FLOAT, st.just(0.09)) | NASTY),
    st.tuples(st.just("move"), VEC_MM),
    st.tuples(st.just("drive"), st.sampled_from([0, 1]), NUM_MM),
    st.tuples(st.just("switch")),
    st.tuples(st.just("home")),
    st.tuples(st.just("demo"), st.sampled_from(["inverse", "direct", "stroke"]) | NASTY),
    st.tuples(
        st.just("load"),
        mostly_valid(
            st.sampled_from(["static", "dynamic"]),
            st.tuples(st.floats(-1e3, 1e3), st.floats(-1e3, 1e3)),
            st.tuples(st.floats(-5.0, 5.0), st.floats(-5.0, 5.0)),
            st.tuples(st.floats(-100.0, 100.0), st.floats(-100.0, 100.0)),
        ),
    ).map(lambda a: (a[0], *a[1])),
    st.tuples(st.just("params"), PARAM_RAW),
    st.tuples(st.just("paper")),
)


def apply(state: AppState, action: tuple) -> AppState:
    """The transition a callback runs for ``action`` (may raise TpmVizError)."""
    kind, *args = action
    if kind == "drive":
        return T.drive(state, *args)
    fn = {
        "drag": T.drag,
        "move": T.move,
        "switch": T.switch,
        "home": T.home,
        "demo": T.demo,
        "load": T.set_load,
        "params": T.apply_params,
        "paper": T.paper_params,
    }[kind]
    return fn(state, *args)


def assert_valid(state: AppState) -> None:
    """A state the app may show: finite, on the pose's leg branches, inside the stroke, clear of singularities."""
    params, pose = state.params, state.pose
    assert np.all(np.isfinite(pose.p)) and np.all(np.isfinite(pose.d))
    np.testing.assert_allclose(pose.d, ik_branch(params, pose.p, pose.branch(params)), atol=1e-9)
    assert check(params, pose) == PoseStatus.REGULAR, (params, pose)
    assert not BAD_TEXT.search(str(state.note))
    for value in (*state.load.f_ext, *state.load.dp, *state.load.ddp, state.trajectory.duration, state.trajectory.t):
        assert math.isfinite(value)


def assert_frame_clean(frame) -> None:
    """Every number of the readout and every drawn text of the frame is finite."""
    r = frame.readout
    for name in ("p", "d", "theta", "det_jx", "det_jq", "cond", "other_p"):
        assert_clean(f"readout.{name}", getattr(r, name))
    for name in ("tau", "tau_ref"):
        assert_clean(f"forces.{name}", getattr(r.forces, name))
    mp = frame.mechanism
    assert_clean("mechanism", [mp.p, mp.d, mp.theta, mp.A, mp.B, mp.links])
    assert_clean("links", list(frame.links))
    assert_clean("dashboard", frame.dashboard)
    assert_clean("equations", frame.equations)


def _refusal(exc: TpmVizError) -> None:
    text = str(exc)
    assert text and "\n" not in text and len(text) < 400, text


@_settings(1500)
@given(actions=st.lists(ACTIONS, min_size=1, max_size=6))
def test_control_sequences_keep_a_valid_state_and_draw_only_finite_values(actions):
    hub = Hub(AppState.initial(P))
    view, other = _VIEWS
    hub.join(view, private=False)
    hub.join(other, private=False)
    for action in actions:
        before = hub.shared.state
        try:
            new = apply(before, action)
            hub.commit(hub.shared, new, origin=view, dragging=action[0] == "drag")
        except TpmVizError as exc:
            _refusal(exc)
            assert hub.shared.state is before  # the last good state stays
        assert not view.failures and not other.failures, (view.failures or other.failures)[0]
        assert_valid(hub.shared.state)
    assert_frame_clean(hub.shared.frame)


class _LazyViews:
    """Two fake tabs built once per test session (building the trimesh parts takes ~0.5 s)."""

    def __iter__(self):
        if not hasattr(self, "views"):
            self.views = (FakeView(AppState.initial(P)), FakeView(AppState.initial(P)))
        for v in self.views:
            v.failures.clear()
            v.panel.forget()
            v.scene.forget()
            v.mechanism.forget()
        return iter(self.views)


_VIEWS = _LazyViews()

START = st.sampled_from(["home", "inverse", "direct", "stroke", "other-mode", "small"])


def _start(kind: str) -> AppState:
    state = AppState.initial(P)
    if kind in ("inverse", "direct", "stroke"):
        return T.demo(state, kind)
    if kind == "other-mode":
        return T.switch(T.drive(T.drive(state, 0, 200.0), 1, 250.0))
    if kind == "small":
        return T.apply_params(state, {"a": 48.2, "b": 9.2, "l_a": 26.0, "stroke": 30.0, "pivot_spacing": 6.0})
    return state


@_settings(5000)
@given(start=START, action=ACTIONS)
def test_each_control_from_edge_states_refuses_or_gives_a_clean_frame(start, action):
    hub = Hub(AppState.initial(P))
    state = _START_STATES[start]
    assert_valid(state)
    try:
        new = apply(state, action)
    except TpmVizError as exc:
        _refusal(exc)
        return
    assert_valid(new)
    frame = hub.frame(new, dragging=action[0] == "drag")
    assert_frame_clean(frame)


_START_STATES = {k: _start(k) for k in ("home", "inverse", "direct", "stroke", "other-mode", "small")}


# -- uploads -------------------------------------------------------------------------------------------------------
CELL = st.one_of(
    st.floats(allow_nan=True, allow_infinity=True).map(repr),
    st.floats(-0.3, 0.3).map(lambda x: f"{x:.6f}"),
    st.sampled_from(["", "nan", "inf", "abc", "1e999", "-0", "0x1", " ", '"1"']),
)
ROW = st.lists(CELL, min_size=2, max_size=4).map(",".join)
HEADER = st.sampled_from(["t,p1,p2", "p1,p2,t", "t,p1", "t,p1,p2,p3", "time,x,y", "", "t,t,p1"])
CSV_TEXT = st.tuples(HEADER, st.lists(ROW, max_size=12)).map(lambda h: "\n".join([h[0], *h[1]]))
GOOD_ROWS = st.lists(
    st.tuples(st.floats(0.0, 1e-3), st.floats(-0.2, 0.2), st.floats(-0.2, 0.2)), min_size=0, max_size=12
)


def _timed(rows) -> str:
    t, lines = 0.0, ["t,p1,p2"]
    for dt, x, y in rows:
        t += dt
        lines.append(f"{t!r},{x!r},{y!r}")
    return "\n".join(lines)


UPLOAD = st.one_of(
    CSV_TEXT.map(str.encode),
    GOOD_ROWS.map(_timed).map(str.encode),
    st.binary(max_size=200),
    st.sampled_from([b"\xff\xfe t,p1,p2", b"t,p1,p2\n\x00\x01", "t,p1,p2\n0,0,0\n".encode("utf-16")]),
    st.just(None),
    st.just("t,p1,p2\n0,0,0"),
)


@_settings(1200)
@given(content=UPLOAD, name=st.text(max_size=30) | st.just("../../etc/passwd"))
def test_uploads_are_read_or_refused_in_one_line(content, name):
    try:
        traj = read_upload(content, name)
    except TpmVizError as exc:
        _refusal(exc)
        return
    for arr in (traj.t, traj.p, traj.dp, traj.ddp):
        assert np.all(np.isfinite(arr))
    assert "/" not in traj.name and len(traj.name) <= 80


def test_upload_limits():
    row = "0.001,0.01,-0.02\n"
    with pytest.raises(InputError, match="too large"):
        read_upload(("t,p1,p2\n" + row * (MAX_UPLOAD_BYTES // len(row) + 1)).encode())
    with pytest.raises(InputError, match="not UTF-8"):
        read_upload(b"t,p1,p2\n\xff,0,0\n")
    with pytest.raises(InputError, match="not a text"):
        read_upload(b"t,p1,p2\n0,0,0\x00\n")
    with pytest.raises(InputError, match="beyond"):
        read_upload(b"t,p1,p2\n0,0,0\n1,0,0\n2,100,0\n3,0,0\n")
    with pytest.raises(InputError):
        read_upload(b"t,p1,p2\n0,0,0\n0,0,0\n1,0,0\n2,0,0\n")  # times not increasing
    good = read_upload(b"\xef\xbb\xbft,p1,p2\n0,0,0\n0.1,0.01,0\n0.2,0.02,0\n0.3,0.03,0\n", "C:\\x\\my path.csv")
    assert good.name == "my path.csv" and good.t[-1] == pytest.approx(0.3)


def test_readers():
    assert read_number("12.5", "x", scale=1e-3) == pytest.approx(0.0125)
    for bad in (math.nan, math.inf, "abc", None, True, [1], "1e999"):
        with pytest.raises(InputError):
            read_number(bad, "x")
    with pytest.raises(InputError, match="too large"):
        read_number(1e308, "x", scale=10.0)
    for bad in ("12", b"12", {"a": 1, "b": 2}, (1, math.nan), (1, 2, 3)):
        with pytest.raises(InputError):
            read_vec2(bad, "p")
    assert read_choice("line", "k", ("line",)) == "line"
    for bad in ("x", 1, None):
        with pytest.raises(InputError):
            read_choice(bad, "k", ("line",))
    assert read_flag(1, "f") is True and read_flag(False, "f") is False
    with pytest.raises(InputError):
        read_flag("yes", "f")
    long = "x" * 10_000
    with pytest.raises(InputError) as info:
        read_number(long, "x")
    assert len(str(info.value)) < 100  # a huge value is never echoed whole
