"""The type check of every incoming message (viserkit/transport.py ``message_problem``), built once per message class: a
valid message passes, and each kind of wrong field is named with its fix-worthy problem (the expected lines are
written here by hand). Also the real viser messages a tab sends while dragging and uploading."""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any, Literal, Optional

import pytest

from tpm_viz.viserkit.probe import messages as _messages
from tpm_viz.viserkit.transport import message_problem


@dataclass
class Sample:
    count: int
    scale: float
    flag: bool
    label: str
    blob: bytes
    nothing: None
    kind: Literal["a", "b"]
    pair: tuple[float, float]
    many: tuple[int, ...]
    maybe: Optional[str]  # noqa: UP045 (the typing form viser's messages use)
    either: int | str
    table: dict[str, Any]
    items: list[int]
    anything: Any


GOOD = dict(
    count=3,
    scale=0.5,
    flag=True,
    label="x",
    blob=b"\x00",
    nothing=None,
    kind="a",
    pair=(1.0, 2),
    many=[1, 2, 3],
    maybe=None,
    either="text",
    table={},
    items=(1,),
    anything=object(),
)


def test_a_valid_message_passes():
    assert message_problem(Sample(**GOOD)) is None
    assert message_problem(Sample(**{**GOOD, "maybe": "set", "either": 4, "many": []})) is None


@pytest.mark.parametrize(
    ("field", "value", "problem"),
    [
        ("count", "3", "a number is due, got str"),
        ("count", True, "a number is due, got bool"),
        ("scale", math.nan, "not a finite number"),
        ("scale", -math.inf, "not a finite number"),
        ("flag", 1, "a boolean is due, got int"),
        ("label", 5, "text is due, got int"),
        ("label", "x" * 4097, "text too long"),
        ("blob", "text", "bytes are due"),
        ("nothing", 0, "None is due"),
        ("kind", "c", "not one of the allowed values"),
        ("pair", 1.0, "a sequence is due, got float"),
        ("pair", (1.0, 2.0, 3.0), "2 items are due, got 3"),
        ("pair", (1.0, "2"), "a number is due, got str"),
        ("many", (1, 2, math.inf), "not a finite number"),
        ("many", (1, None), "a number is due, got NoneType"),
        ("maybe", 3, "text is due, got int"),
        ("either", 2.5e300, None),  # a float is a number
        ("either", [], "a number is due, got list"),
        ("table", [], "a map is due"),
        ("items", "12", "a list is due"),
    ],
)
def test_each_wrong_field_is_named_with_its_problem(field, value, problem):
    found = message_problem(Sample(**{**GOOD, field: value}))
    assert found == (None if problem is None else f"Sample.{field}: {problem}")


def test_the_messages_a_dragging_tab_sends():
    good = _messages.TransformControlsUpdateMessage("/gizmo", (1.0, 0.0, 0.0, 0.0), (0.01, 0.02, 0.09), "7")
    assert message_problem(good) is None
    bad = _messages.TransformControlsUpdateMessage("/gizmo", (1.0, 0.0, 0.0, 0.0), (0.01, math.nan, 0.09), "7")
    assert message_problem(bad) == "TransformControlsUpdateMessage.position: not a finite number"
    short = _messages.TransformControlsUpdateMessage("/gizmo", (1.0, 0.0, 0.0, 0.0), (0.01, 0.02), "7")
    assert message_problem(short) == "TransformControlsUpdateMessage.position: 3 items are due, got 2"
    part = _messages.FileTransferPart(None, "t", 0, "not bytes")
    assert message_problem(part) == "FileTransferPart.content: bytes are due"


def test_a_browser_camera_is_never_refused_for_a_non_finite_number():
    camera = _messages.ViewerCameraMessage(
        (1.0, 0.0, 0.0, 0.0), (0.0, 0.0, 1.0), math.inf, 0.01, 100.0, 768, 1024, (0.0, 0.0, 0.0), (0.0, 0.0, 1.0)
    )
    assert message_problem(camera) is None
