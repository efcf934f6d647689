"""Bad input through a real server: generated protocol messages from one tab, checked on every tab.

A :class:`~tpm_viz.ui.app.TpmApp` on ``ViserServer(port=0)`` (loopback) and two protocol-level clients: the
*actor* sends what a hostile or careless browser can send (GUI updates with NaN, ±inf, huge, negative, text such
as ``"nan"``/``"1e999"`` that viser itself casts to floats, None, wrong-length lists; button clicks; gizmo drags
with NaN or far-away positions), the *observer* only watches the shared mechanism. After every
example the test waits until every callback has run (``guard.ACTIVITY``) and checks: no callback raised, every
session holds a valid state, every number in the actor's widgets and in both scenes is finite, no text shows NaN
or inf, and the observer never got a message meant for the actor. (NaN and inf in a GUI update are dropped by
``viserkit/transport.py`` before any callback; the callbacks' own refusal of them is covered by the pure tests.)

A deterministic sweep sends each of 21 nasty values to each of 24 fields (540 messages, each followed by Enter in a
typed field); the property test 300 examples x 1-5 messages (+ an Apply and a sync click each): ~870 generated
messages (GUI updates, Enter, clicks, drags and uploads to the panel, the player, the explorer and the
demonstrations). Typed number fields (text inputs) keep whatever text they were sent (it is the user's, quoted in
their note if refused): for them the check is that the value in use, and every text the app wrote, is finite.
"""

from __future__ import annotations

import threading
import time
import uuid

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from tests.support.fake_viser import assert_clean
from tests.support.hypo import examples
from tests.support.protocol import ProtocolClient, wait_for
from tests.ui.test_client_reliability import CSV_TEXT, GOOD_ROWS, NASTY_FLOAT, _timed, assert_valid
from tpm_viz.classroom.guard import ACTIVITY
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

INT64 = st.integers(-(2**62), 2**62)
NASTY_VALUES = [
    float("nan"),
    float("inf"),
    float("-inf"),
    1e300,
    -1e300,
    5e-324,
    -0.0,
    -1.0,
    2**62,
    "nan",
    "inf",
    "-1e999",
    "abc",
    "",
    None,
    True,
    [],
    [1.0, 2.0, 3.0],
    ["nan", 1.0],
    [float("inf"), 0.0],
    [1e300, -1e300],
]
"""What a browser or a hand-written client can put in a GUI update (viser casts it to the widget's type)."""
RAW = (
    st.sampled_from(NASTY_VALUES)
    | st.floats(allow_nan=True, allow_infinity=True)
    | st.floats(-400.0, 400.0)
    | INT64
    | st.sampled_from(["static", "dynamic", "line", "circle"])
    | st.lists(st.floats(allow_nan=True, allow_infinity=True) | st.sampled_from(["nan", "x"]), max_size=3)
)
FIELDS = [
    "p",
    "d0",
    "d1",
    "load_mode",
    "f_ext",
    "dp",
    "ddp",
    "param:a",
    "param:b",
    "param:l_a",
    "param:stroke",
    "param:m_p",
    "own_copy",
    "show:labels",
    "player:choice",
    "player:duration",
    "player:time",
    "player:speed",
    "player:loop",
    "player:controls",
    "explorer:map_kind",
    "explorer:ellipses",
    "demos:choice",
    "demos:steps",
]
BUTTONS = [
    "switch_mode",
    "home",
    "demo:inverse",
    "demo:direct",
    "demo:stroke",
    "apply",
    "paper",
    "player:export_csv",
    "demos:play",
]
OPTIONS = st.sampled_from(
    ["circle (Fig. 5)", "line (Fig. 4)", "none", "Play", "Pause", "To start", "0.05×", "1× (real time)"]
) | st.sampled_from(["Show this one", "Next", "Previous", "your CSV: upload.csv"])
"""Valid option labels of the player's, explorer's and demonstrations' dropdowns and button groups."""
UPLOAD_BYTES = st.one_of(CSV_TEXT.map(str.encode), GOOD_ROWS.map(_timed).map(str.encode), st.binary(max_size=300))
POSITION = st.tuples(
    st.floats(-0.5, 0.5) | NASTY_FLOAT, st.floats(-0.5, 0.5) | NASTY_FLOAT, st.floats(-1.0, 1.0) | NASTY_FLOAT
)
TEXT = st.floats(-1e6, 1e6).map(lambda x: format(x, "g")) | st.sampled_from(
    ["1e9", "5e-1", "0,25", "-100000", "1,000", "1e999", "\u2212 3", "2.5 mm", "1e-320", "９"]
)
"""Texts typed into a number field (scientific notation, decimal commas, too large, a full-width digit...)."""
TYPED = {"p": ("p", "p1"), "f_ext": ("f_ext", "f_x"), "dp": ("dp", "ṗ2"), "ddp": ("ddp", "p̈1")}
"""Vector fields of the sweep -> (typed box, the field of it that gets the values)."""
MESSAGE = st.one_of(
    st.tuples(st.just("set"), st.sampled_from(FIELDS), RAW | st.tuples(RAW, RAW) | st.tuples(RAW, RAW) | OPTIONS),
    st.tuples(st.just("set"), st.sampled_from([*TYPED, "param:l_a", "param:m_p", "player:duration"]), TEXT),
    st.tuples(st.just("enter"), st.sampled_from([*TYPED, "params", "player:duration"])),
    st.tuples(st.just("upload"), UPLOAD_BYTES),
    st.tuples(st.just("click"), st.sampled_from(BUTTONS)),
    st.tuples(st.just("drag"), st.lists(POSITION, min_size=1, max_size=4), st.booleans()),
)


def _handle(view, name: str):
    panel = view.panel
    if name == "player:duration":
        return view.teaching.player.duration.inputs["T"]
    for part in ("player", "explorer", "demos"):
        if name.startswith(part + ":"):
            return getattr(getattr(view.teaching, part), name[len(part) + 1 :])
    if name.startswith("param:"):
        return panel.params.inputs[name[6:]]
    if name in TYPED:
        box, key = TYPED[name]
        return getattr(panel, box).inputs[key]
    if name.startswith("show:"):
        return panel.show_toggles[name[5:]]
    if name.startswith("demo:"):
        return panel.demo[name[5:]]
    if name in ("d0", "d1"):
        return panel.d[int(name[1])]
    return getattr(panel, name)


def _box(view, name: str):
    """The typed box of a field name (``p``, ``params``, ``player:duration``, ...), or None."""
    if name == "player:duration":
        return view.teaching.player.duration
    if name == "params" or name.startswith("param:"):
        return view.panel.params
    return getattr(view.panel, TYPED[name][0]) if name in TYPED else None


def _numeric_widgets(view):
    p = view.panel
    yield from (*p.d, view.teaching.player.time)


def _typed_boxes(view):
    p = view.panel
    yield from (p.p, p.f_ext, p.dp, p.ddp, p.params, view.teaching.player.duration)


def _scene_values(view):
    s = view.scene
    yield from (s.platform.position, s.gizmo.position, s.ghost.position, *(x.position for x in s.sliders))
    yield from (s.links.batched_positions, s.links.batched_wxyzs, *(f.points for f in s.forces), s.load_arrow.points)


@pytest.fixture
def two_tabs(app, connect, monkeypatch):
    """The actor and the observer; exceptions reported by the background worker or escaping a thread fail the test
    (they would be lines in the server log)."""
    import tpm_viz.classroom.worker as worker_module

    crashes: list[BaseException] = []
    monkeypatch.setattr(worker_module, "report", lambda exc, *a, **k: crashes.append(exc))
    monkeypatch.setattr(threading, "excepthook", lambda args: crashes.append(args.exc_value))
    actor, view = connect()
    _observer, other = connect()
    pinged = threading.Event()
    view.panel.frame_camera.on_click(lambda _event: pinged.set())
    view.crashes = crashes
    return actor, view, other, pinged


def _sync(actor: ProtocolClient, view, pinged: threading.Event) -> None:
    """Wait until every message sent so far has been handled (see the module docstring)."""
    pinged.clear()
    actor.click(view.panel.frame_camera)
    assert pinged.wait(10.0), "the sync click was not handled"
    worker = view.teaching.services.worker
    for _ in range(3):
        time.sleep(0.002)
        assert ACTIVITY.wait_idle(10.0)
        wait_for(lambda: not view.session.drags.has(view), what="pending drags to drain")
        wait_for(worker.idle, what="background runs and maps")


def _upload(client: ProtocolClient, button, content: bytes) -> None:
    """What viser's upload button sends: a transfer start, then the parts."""
    transfer = str(uuid.uuid4())
    parts = [content[i : i + 4096] for i in range(0, len(content), 4096)]
    head = {"source_component_uuid": widget_uuid(button), "transfer_uuid": transfer}
    client.send(
        type="FileTransferStartUpload",
        **head,
        filename="upload.csv",
        mime_type="text/csv",
        part_count=len(parts),
        size_bytes=len(content),
    )
    for k, part in enumerate(parts):
        client.send(type="FileTransferPart", **head, part_index=k, content=part)


def _check(view, other, errors_before: int) -> None:
    """The checks of the module docstring, under the hub's lock."""
    assert ACTIVITY.snapshot()[1] == errors_before, "a callback raised (see the log)"
    assert not view.crashes, view.crashes[0]
    with view.hub.lock:
        for v in (view, other):
            assert_valid(v.session.state)
            assert_clean("dashboard", v.panel.dashboard.content)
            assert_clean("equations", v.panel.equations.content)
            for value in _scene_values(v):
                assert_clean("scene", np.asarray(value, dtype=float))
        for handle in _numeric_widgets(view):
            assert_clean(handle.label, handle.value)
        for box in _typed_boxes(view):  # the values in use, and the texts the app wrote, are finite
            for key, field in box.group.fields.items():
                assert_clean(key, field.value)
                if not field.own:
                    assert_clean(key, box.inputs[key].value)
        teaching = view.teaching
        for chart in teaching.player.charts.handles:  # the plots: no NaN or inf on the wire
            assert_clean("chart", [np.asarray(series, dtype=float) for series in chart.data])
        for text in (teaching.player.summary, teaching.explorer.status, teaching.explorer.readout, teaching.demos.text):
            assert_clean("teaching text", text.content)
        assert other.panel.message.content == ""  # refusals go to the actor only
        if view.session.shared:
            assert view.session.state is other.session.state


def test_every_field_refuses_every_nasty_value(two_tabs):
    """A deterministic sweep: each numeric or choice field gets each of :data:`NASTY_VALUES` (and paired with a
    good number for the vector fields), then Apply; the app must stay clean after each."""
    actor, view, other, pinged = two_tabs
    errors_before = ACTIVITY.snapshot()[1]
    pairs = {"p", "f_ext", "dp", "ddp"}
    for name in FIELDS:
        values = NASTY_VALUES + ([(v, 1.0) for v in NASTY_VALUES[:9]] if name in pairs else [])
        for value in values:
            actor.set_value(_handle(view, name), value)
            box = _box(view, name)
            if box is not None and box is not view.panel.params:
                actor.enter(box)  # Enter in that field
            actor.click(view.panel.apply)
            _sync(actor, view, pinged)
            _check(view, other, errors_before)


def test_generated_protocol_messages_never_break_the_app(two_tabs):
    actor, view, other, pinged = two_tabs
    owner = str(view.client.client_id)
    errors_before = ACTIVITY.snapshot()[1]

    @settings(
        max_examples=examples(300),
        deadline=None,
        derandomize=True,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.function_scoped_fixture],
    )
    @given(messages=st.lists(MESSAGE, min_size=1, max_size=5))
    def run(messages):
        for message in messages:
            kind = message[0]
            if kind == "set":
                actor.set_value(_handle(view, message[1]), message[2])
            elif kind == "enter":
                actor.enter(_box(view, message[1]))
            elif kind == "click":
                actor.click(_handle(view, message[1]))
            elif kind == "upload":
                _upload(actor, view.teaching.player.upload, message[1])
            else:
                actor.drag(view.scene.gizmo, owner, message[1], end=message[2])
        actor.drag(view.scene.gizmo, owner, [], end=True)  # every drag ends (a real mouse is released)
        actor.click(view.panel.apply)  # a refused parameter set reverts the inputs
        _sync(actor, view, pinged)
        _check(view, other, errors_before)

    run()
