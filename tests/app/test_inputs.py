"""The refusals of what a browser sends, the unit checks, the run's reference note and the explorer's legend carry
phrases (issue 13), and their English lines are the ones the app always showed: each expected line is written here
by hand, from the limits and the inputs, never read from the code under test."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.app import transitions
from tpm_viz.app.inputs import read_choice, read_flag, read_number, read_params, read_upload, read_vec2
from tpm_viz.app.overlays import colour_scale
from tpm_viz.app.runs import Source, build_run
from tpm_viz.app.state import AppState
from tpm_viz.core.errors import InputError, TpmVizError
from tpm_viz.core.numbers import parse_number, unit_factor
from tpm_viz.core.words import Lang, Phrase, T, say
from tpm_viz.paper.trajectories import parse_trajectory_csv

P = Params.paper()
MIB = 1 << 20


def refused(fn) -> TpmVizError:
    with pytest.raises(TpmVizError) as info:
        fn()
    exc = info.value
    assert isinstance(exc.args[0], Phrase), f"{exc!r} carries no phrase"
    return exc


def _rows(t_end: float, p1: float) -> bytes:
    """A 4-sample trajectory CSV reaching ``p1`` [m] at ``t_end`` [s]."""
    rows = "".join(f"{t_end * k / 3},{p1 * k / 3},0\n" for k in range(4))
    return ("t,p1,p2\n" + rows).encode()


ENGLISH = {
    "a text for a number": (lambda: read_number("abc", "d1"), "d1 must be a number, got 'abc'"),
    "a boolean for a number": (lambda: read_number(True, "d1"), "d1 must be a number, got True"),
    "NaN": (lambda: read_number(float("nan"), "d1"), "d1 must be finite, got nan"),
    "too large once scaled": (lambda: read_number(1e308, "d1", scale=1e3), "d1 is too large, got 1e+308"),
    "one number for two": (lambda: read_vec2("1,2", "f_ext"), "f_ext must be two numbers, got '1,2'"),
    "three numbers for two": (lambda: read_vec2([1, 2, 3], "f_ext"), "f_ext must be two numbers, got [1, 2, 3]"),
    "not an option": (
        lambda: read_choice("hot", "load", ("static", "dynamic")),
        "load must be one of static, dynamic, got 'hot'",
    ),
    "not a checkbox value": (lambda: read_flag(2, "loop"), "loop must be on or off, got 2"),
    "an unknown parameter": (lambda: read_params(P, {"l_z": 1.0}), "unknown parameter 'l_z'"),
    "not bytes": (lambda: read_upload("t,p1,p2"), "the upload is not a file"),
    "a file too large": (
        lambda: read_upload(b"x" * (MIB + 1)),
        "the file is too large (1048577 bytes; at most 1048576 bytes)",
    ),
    "a binary file": (lambda: read_upload(b"t,p1,p2\n0,0,0\x00\n"), "the file is not a text CSV file (binary content)"),
    "not UTF-8": (lambda: read_upload(b"t,p1,p2\n\xff,0,0\n"), "the file is not UTF-8 text"),
    "a position in millimetres": (
        lambda: read_upload(_rows(1.0, 150.0)),
        "a position in the file is beyond 10 m (the file is in metres)",
    ),
    "a trajectory of two hours": (
        lambda: read_upload(_rows(7200.0, 0.01)),
        "the trajectory lasts 7200 s (at most 3600 s)",
    ),
    "an unknown unit": (
        lambda: parse_trajectory_csv("t,p1 [furlong],p2\n0,0,0\n1,0,0\n2,0,0\n3,0,0\n"),
        "the trajectory CSV: column 'p1 [furlong]' has an unknown unit 'furlong' (use m or mm)",
    ),
    "a unit of another quantity": (
        lambda: parse_trajectory_csv("t,p1 [s],p2\n0,0,0\n1,0,0\n2,0,0\n3,0,0\n"),
        "the trajectory CSV: column 'p1 [s]': 's' is a time unit, but p1 is a length in m",
    ),
}


@pytest.mark.parametrize("case", list(ENGLISH))
def test_the_english_line_of_a_refusal_is_unchanged(case):
    fn, english = ENGLISH[case]
    exc = refused(fn)
    assert str(exc) == english
    assert say(Lang.EN, exc) == english


def test_units_name_the_quantity_and_a_phrase_label_stays_a_phrase():
    exc = refused(lambda: unit_factor("s", None, "the session", "k"))
    assert str(exc) == "the session: 's' is a time unit, but k takes no unit"
    exc = refused(lambda: unit_factor("lb", "force", T("the trajectory CSV"), "f"))
    assert str(exc) == "the trajectory CSV has an unknown unit 'lb' (use N or kN)"
    assert exc.args[0].values["label"] == T("the trajectory CSV")  # not flattened to English text
    exc = refused(lambda: unit_factor("lb", None, "x", "k"))
    assert str(exc) == "x has an unknown unit 'lb'"
    assert unit_factor("mm", "length", "x", "p1") == (1.0, 1000.0)


def test_a_field_named_by_a_phrase_keeps_its_phrase():
    exc = refused(lambda: parse_number(True, T("time t"), "s"))
    assert str(exc) == "time t [s] must be a number, got True"
    label = exc.args[0].values["label"]
    assert isinstance(label, Phrase) and label.values["name"] == T("time t")
    exc = refused(lambda: parse_number("x", "a very long name " * 5))
    assert str(exc).startswith("a very long name a very long name a very: 'x' is not a number")  # cut at 40
    exc = refused(lambda: read_number("x", T("time t")))
    assert str(exc) == "time t must be a number, got 'x'" and exc.args[0].values["name"] == T("time t")


@pytest.mark.parametrize(
    ("refuse", "english", "korean"),
    [
        (lambda s: transitions.move(s, ("a", 1)), "platform position p must be a number, got 'a'", "플랫폼 위치 p"),
        (lambda s: transitions.drag(s, (1.0,)), "platform position must be two numbers, got [1.0]", "플랫폼 위치"),
        (
            lambda s: transitions.drive_both(s, (1, 2, 3)),
            "actuator positions d must be two numbers, got",
            "구동기 위치 d",
        ),
        (
            lambda s: transitions.set_load(s, "fast", (0, 0), (0, 0), (0, 0)),
            "load must be one of static, dynamic, got 'fast'",
            "하중",
        ),
        (
            lambda s: transitions.set_load(s, "dynamic", (0, 0), ("x", 0), (0, 0)),
            "platform velocity must be a number",
            "플랫폼 속도",
        ),
        (
            lambda s: transitions.set_load(s, "dynamic", (0, 0), (0, 0), (1, 2, 3)),
            "platform acceleration must be two",
            "플랫폼 가속도",
        ),
        (lambda s: transitions.demo(s, "dance"), "demo must be one of", "시연"),
    ],
)
def test_the_widget_a_refusal_names_is_in_the_tabs_language(refuse, english, korean):
    exc = refused(lambda: refuse(AppState.initial(P)))
    assert str(exc).startswith(english)
    text = say(Lang.KO, exc.args[0])
    assert text.startswith(korean) and not any(w in text for w in ("platform", "actuator", "load", "demo"))


def test_the_reference_note_of_a_run_says_why_there_is_no_reference():
    line = Source.paper("line")
    assert str(build_run(P, line).ref_note) == "no reference model"

    def broken(*_):
        raise InputError(Phrase("no closed-loop configuration found at ({x}, {y}) mm", x="1.0", y="2.0"))

    run = build_run(P, line, broken)
    assert (
        run.tau_ref is None
        and str(run.ref_note) == "reference model: no closed-loop configuration found at (1.0, 2.0) mm"
    )
    nan = build_run(P, line, lambda *a: np.full((len(a[1]), 2), np.nan))
    assert str(nan.ref_note) == "reference model: non-finite forces"
    assert build_run(P, line, lambda params, p, dp, ddp: np.zeros_like(p)).ref_note is None


def test_the_legends_words_are_phrases_with_the_same_english():
    cond = colour_scale("cond")
    assert str(cond.title) == "condition number of J (log scale)"
    assert str(cond.note) == "1 = isotropic; ≥ 100 saturates"
    ws = colour_scale("workspace")
    assert [str(label) for label, _ in ws.stops] == ["in stroke", "reachable, out of stroke"]
    assert str(ws.note) == "transparent: unreachable (|p_j| ≥ l_a)"
    det = colour_scale("det_jx")
    assert (
        str(det.title) == "det J_x = cos(θ1+θ2) (dimensionless)" and str(det.note) == "white band: direct singularity"
    )
    off = colour_scale("off")
    assert str(off.title) == "no map" and off.stops == () and off.note is None
