"""Saved sessions (tpm_viz.classroom.sessionfile): round trip, uploaded trajectories, refusals of bad or old files."""

from __future__ import annotations

import json

import numpy as np
import pytest

from tpm_viz import InputError
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load
from tpm_viz.app.runs import Source
from tpm_viz.app.state import AppState, TrajectorySample
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.sessionfile import KEEP_SECONDS, Document, Saved
from tpm_viz.core.params import Params
from tpm_viz.paper.trajectories import Trajectory


def _csv_source() -> Source:
    t = np.linspace(0.0, 0.4, 9)
    p = np.column_stack([0.05 * np.sin(5 * t), 0.03 * t])
    return Source.from_trajectory(Trajectory("mine", t, p, np.zeros_like(p), np.zeros_like(p)))


def _state() -> AppState:
    params = Params.paper(l_a=0.28)
    pose = Pose.working(params, (0.02, -0.01))
    return AppState(params, pose, Load("static", f_ext=(5.0, -3.0)), TrajectorySample("csv", 0.4, 0.1))


def test_round_trip_keeps_everything_the_lecturer_set():
    source = _csv_source()
    doc = Document(Saved(_state(), source, 0.1, {"labels": False}), lesson_step=3)
    doc.tabs["c:" + "a" * 32] = [{"private": True, "saved": Saved(_state(), Source.paper("line")), "left_at": 1e9}]
    back = sessionfile.loads(sessionfile.dumps(doc), now=1e9 + 10)
    s = back.shared.state
    assert s.params == _state().params and s.load == _state().load and s.trajectory == _state().trajectory
    np.testing.assert_allclose(s.pose.p, (0.02, -0.01))
    assert back.shared.source.kind == "csv" and back.shared.source.duration == pytest.approx(0.4)
    np.testing.assert_allclose(back.shared.source.knots[1], source.knots[1])
    assert back.shared.playing_t == 0.1 and back.shared.show == {"labels": False} and back.lesson_step == 3
    (record,) = back.tabs["c:" + "a" * 32]
    assert record["private"] and record["saved"].source.kind == "line"


def test_tabs_older_than_30_minutes_are_dropped():
    doc = Document(Saved(_state()), tabs={"k": [{"private": True, "saved": Saved(_state()), "left_at": 0.0}]})
    assert sessionfile.loads(sessionfile.dumps(doc), now=KEEP_SECONDS + 1).tabs == {}


@pytest.mark.parametrize(
    ("edit", "message"),
    [
        (lambda d: d.update(version=0), "version"),
        (lambda d: d.update(format="other"), "not a tpm-viz session"),
        (lambda d: d["shared"]["params"].update(l_a=-1.0), "positive"),
        (lambda d: d["shared"]["params"].update(zz=1.0), "unknown parameter"),
        (lambda d: d["shared"].update(p=[1.0]), "two numbers"),
        (lambda d: d["shared"]["load"].update(mode="fast"), "load mode"),
        (lambda d: d["shared"]["trajectory"].update(t=[0.0, 0.0, 0.1, 0.2, 0.3]), "samples|increase"),
        (lambda d: d["shared"]["trajectory"].update(kind="spiral"), "trajectory kind"),
        (lambda d: d.update(shared="nope"), "session file"),
    ],
)
def test_bad_or_old_documents_are_one_line_refusals(edit, message):
    raw = json.loads(sessionfile.dumps(Document(Saved(_state(), _csv_source()))))
    edit(raw)
    with pytest.raises(InputError, match=message) as info:
        sessionfile.loads(json.dumps(raw))
    assert "\n" not in str(info.value) and str(info.value).startswith("session file")


@pytest.mark.parametrize("text", ["", "{", "[]", "null", '{"format": "tpm-viz-session"}', "x" * 100])
def test_garbage_is_refused(text):
    with pytest.raises(InputError, match="session file"):
        sessionfile.loads(text)


def test_write_is_atomic_and_leaves_no_temporary_file(tmp_path):
    path = tmp_path / "deep" / "session.json"
    sessionfile.write_atomic(path, "one")
    sessionfile.write_atomic(path, "two")
    assert path.read_text() == "two" and [p.name for p in path.parent.iterdir()] == ["session.json"]
    with pytest.raises(InputError, match="session file"):
        sessionfile.read_file(tmp_path / "missing.json")


@pytest.mark.parametrize(
    ("data", "message"),
    [
        (b"[" * 200_000, "nested deeper"),  # RecursionError in json before
        (b"\x89PNG\r\n\x1a\n\x00\x00\x00\rIHDR\xff\xfe" * 50, "not UTF-8"),  # a picture chosen by mistake
        (b'{"format": "tpm-viz-session", "version": 1, "shared": ' + b"{" * 5000, "nested deeper|not valid JSON"),
    ],
)
def test_open_session_refuses_deep_or_binary_files_in_one_plain_line(data, message):
    with pytest.raises(InputError, match=message) as info:
        sessionfile.loads(data)
    text = str(info.value)
    assert text.startswith("session file") and "\n" not in text and "codec" not in text and "\\x" not in text


def test_open_session_checks_the_lesson_step_against_the_lessons():
    raw = json.loads(sessionfile.dumps(Document(Saved(_state()), lesson_step=3)))
    assert sessionfile.loads(json.dumps(raw), steps=4).lesson_step == 3
    for bad in (999, 4, -1, 2.5, True, "2"):
        raw["lesson_step"] = bad
        with pytest.raises(InputError, match="lesson step"):
            sessionfile.loads(json.dumps(raw), steps=4)
