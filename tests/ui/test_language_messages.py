"""Refusals and notes reach a Korean tab in Korean (issue 13): the errors the library raises for what a user types,
uploads or drags carry a :class:`~tpm_viz.core.words.Phrase`, so ``say(Lang.KO, exc)`` is Korean with the same numbers
and quotes, while ``str(exc)`` (the command line, the logs) keeps its English words.

Each case triggers a real refusal through the public functions, then checks three things independently of the
code under test: the English line (written here), that the Korean line has Hangul and no English word left (units,
file formats and symbols aside), and that every number and quoted input of the English line is in the Korean one.
"""

from __future__ import annotations

import re

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.app import transitions
from tpm_viz.app.inputs import MAX_UPLOAD_BYTES, read_upload
from tpm_viz.app.moves import Pose
from tpm_viz.app.planner import Limits
from tpm_viz.app.planning import parse_waypoints
from tpm_viz.app.readouts import evaluate
from tpm_viz.app.runs import Source, build_run
from tpm_viz.app.state import AppState
from tpm_viz.classroom import sessionfile
from tpm_viz.classroom.access import Access
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.numbers import unit_factor
from tpm_viz.core.words import Lang, T, say
from tpm_viz.paper.kinematics import forward_kinematics
from tpm_viz.paper.trajectories import parse_trajectory_csv

P = Params.paper()
HANGUL = re.compile("[\uac00-\ud7a3]")
ALLOWED = {"csv", "mib", "utf", "json", "tpm", "viz", "rms", "nan", "inf", "sqrt", "pinocchio", "ext"}
"""Latin words a Korean line may keep: file formats, names, units and symbols (``l_a``, ``p_j`` are 1-letter;
``f_ext``)."""


def english_words(text: str) -> list[str]:
    """Words of three or more Latin letters that are not in :data:`ALLOWED`, outside quoted inputs (what the user
    typed or sent is quoted as it is)."""
    return [w for w in re.findall(r"[A-Za-z]{3,}", re.sub(r"'[^']*'", "", text)) if w.lower() not in ALLOWED]


def tokens(text: str) -> list[str]:
    """The numbers and the quoted inputs of a line."""
    return re.findall(r"'[^']*'|-?\d+(?:\.\d+)?", text)


def refusal(fn) -> TpmVizError:
    with pytest.raises(TpmVizError) as info:
        fn()
    return info.value


def _lockout() -> None:
    clock = [0.0]
    access = Access("secret", clock=lambda: clock[0])
    for _ in range(50):
        access.login(object(), "wrong", source="10.0.0.7")


CASES = {
    "a CSV without a column": (
        lambda: parse_trajectory_csv("t,p1\n0,0\n1,0\n"),
        "the trajectory CSV: missing column 'p2' (need t,p1,p2); found header 't,p1'",
    ),
    "a CSV with too few rows": (
        lambda: parse_trajectory_csv("t,p1,p2\n0,0,0\n1,0,0\n"),
        "a trajectory needs at least 4 samples, got 2",
    ),
    "a CSV whose times go back": (
        lambda: parse_trajectory_csv("t,p1,p2\n0,0,0\n1,0,0\n0.5,0,0\n2,0,0\n"),
        "time must increase strictly: t[2] = 0.5 s after t[1] = 1 s",
    ),
    "two waypoints at one place": (
        lambda: parse_waypoints("0,0; 10,x"),
        "waypoint 2 ('10,x') must be two numbers 'x,y' in mm",
    ),
    "a force limit below zero": (
        lambda: Limits(force=-5.0),
        "the force limit must be a positive, finite number of newtons, got -5",
    ),
    "a session file of another program": (
        lambda: sessionfile.loads('{"format": "other"}'),
        "session file: not a tpm-viz session",
    ),
    "a session file of another version": (
        lambda: sessionfile.loads('{"format": "tpm-viz-session", "version": 99}'),
        "session file: version 99, this tpm-viz reads version 1",
    ),
    "actuators the legs cannot join": (
        lambda: forward_kinematics(P, [0.0, 2.0]),
        "actuators at (0.0, 2000.0) mm cannot be assembled: the leg circles are more than 2 l_a apart",
    ),
    "too many wrong tokens": (
        _lockout,
        "too many wrong presenter tokens from this address; try again in 60 s",
    ),
    "an upload that is too large": (
        lambda: read_upload(b"t,p1,p2\n" + b"0" * MAX_UPLOAD_BYTES),
        "the file is too large (1048584 bytes; at most 1048576 bytes)",
    ),
    "a text where an actuator position is due": (
        lambda: transitions.drive(AppState.initial(), 0, "1;2"),
        "d1 must be a number, got '1;2'",
    ),
    "a list where the external force is due": (
        lambda: transitions.set_load(AppState.initial(), "static", [1, 2, 3], (0, 0), (0, 0)),
        "f_ext must be two numbers, got [1, 2, 3]",
    ),
    "an unknown unit": (
        lambda: unit_factor("furlong", "length", T("the trajectory CSV"), "p1"),
        "the trajectory CSV has an unknown unit 'furlong' (use m or mm)",
    ),
    "a time unit for a length": (
        lambda: unit_factor("ms", "length", T("the trajectory CSV"), "p1"),
        "the trajectory CSV: 'ms' is a time unit, but p1 is a length in m",
    ),
    "a position in millimetres": (
        lambda: read_upload(b"t,p1,p2\n0,0,0\n1,50,0\n2,100,0\n3,150,0\n"),
        "a position in the file is beyond 10 m (the file is in metres)",
    ),
}


@pytest.mark.parametrize("case", list(CASES))
def test_a_refusal_is_english_on_the_command_line_and_korean_in_a_korean_tab(case):
    fn, english = CASES[case]
    exc = refusal(fn)
    assert str(exc) == english
    korean = say(Lang.KO, exc)
    assert HANGUL.search(korean), korean
    assert not english_words(korean), (korean, english_words(korean))
    assert sorted(tokens(korean)) == sorted(tokens(english)), korean


def test_a_trajectory_that_leaves_the_workspace_is_refused_in_korean_with_its_reason_inside():
    far = Source.segment((0.0, 0.0), (0.0, 0.9 * P.l_a), 0.5)  # straight up: actuator 2 runs out of its stroke
    exc = refusal(lambda: build_run(P, far))
    english = str(exc)
    assert english.startswith("the trajectory segment, T = 0.5 s: at t = ") and "actuator 2 would leave" in english
    korean = say(Lang.KO, exc)
    assert HANGUL.search(korean) and "구동기 2" in korean  # the nested reason (moves.why_not) is Korean too
    assert not [w for w in english_words(korean) if w != "segment"], korean  # the run's own label stays a name
    assert sorted(tokens(korean)) == sorted(tokens(english))


def test_the_banner_warnings_of_a_pose_are_korean_in_a_korean_tab():
    d = np.array([0.0, 0.5 * P.stroke])  # actuator 1 at the start of its stroke
    pose = Pose(forward_kinematics(P, d), d)
    alerts = evaluate(P, pose).alerts
    assert [a.kind for a in alerts] == ["stroke"]
    english, korean = str(alerts[0].text), say(Lang.KO, alerts[0].text)
    assert english.startswith("Slider 1 is against its end-stop (d1 = 0.0 mm)")
    assert HANGUL.search(korean) and "d1 = 0.0 mm" in korean and not english_words(korean)


def test_a_csv_header_with_an_unknown_unit_is_refused_in_korean_with_the_same_quotes():
    """Through the CSV reader: the unit's words are Korean; the column's label is written by the reader."""
    header = "t,p1 [furlong],p2\n0,0,0\n1,0,0\n2,0,0\n3,0,0\n"
    exc = refusal(lambda: parse_trajectory_csv(header))
    english = str(exc)
    assert english == "the trajectory CSV: column 'p1 [furlong]' has an unknown unit 'furlong' (use m or mm)"
    korean = say(Lang.KO, exc)
    assert HANGUL.search(korean) and "'furlong'" in korean and "'p1 [furlong]'" in korean, korean
    assert sorted(tokens(korean)) == sorted(tokens(english))
    label = set(
        english_words("the trajectory CSV: column")
    )  # the label csvio builds (English text until it is a phrase)
    assert set(english_words(korean)) <= label, korean
