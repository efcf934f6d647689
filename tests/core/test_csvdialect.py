"""Real-world CSV dialects (docs/csv.md): one test per dialect, through the reader the CLI and the upload share."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.core.csvio import decode_text, format_columns, parse_columns, parse_lines, time_unit_note
from tpm_viz.core.errors import InputError
from tpm_viz.paper.trajectories import parse_trajectory_csv

T = [0.0, 0.1, 0.2, 0.3]
P1 = [0.0, 0.01, 0.02, 0.03]
P2 = [0.0, -0.005, 0.0025, 0.5]


def check(table, t=T, p1=P1, p2=P2):
    assert list(table) == ["t", "p1", "p2"]
    assert table["t"] == pytest.approx(t, abs=1e-15)
    assert table["p1"] == pytest.approx(p1, abs=1e-15)
    assert table["p2"] == pytest.approx(p2, abs=1e-15)


def test_semicolon_with_decimal_comma():
    text = "t;p1;p2\n0;0;0\n0,1;0,01;-0,005\n0,2;0,02;0,0025\n0,3;0,03;0,5\n"
    check(parse_columns(text, ["t", "p1", "p2"]))


def test_tab_separated():
    text = "t\tp1\tp2\n0\t0\t0\n0.1\t0.01\t-0.005\n0.2\t0.02\t2.5e-3\n0.3\t0.03\t5e-1\n"
    check(parse_columns(text, ["t", "p1", "p2"]))


def test_units_in_headers_are_converted_to_si():
    text = "t [s],p1 (mm),p2/cm\n0,0,0\n0.1,10,-0.5\n0.2,20,0.25\n0.3,30,50\n"
    table = parse_columns(text, ["t", "p1", "p2"])
    check(table)
    assert table.units == {"t": "s", "p1": "mm", "p2": "cm"}
    dyn = parse_columns("p1 [mm],p2,dp1 [mm/s],dp2,ddp1 [mm/s²],ddp2\n5,0,250,0,1000,0\n", ["p1", "dp1", "ddp1"])
    assert [dyn["p1"][0], dyn["dp1"][0], dyn["ddp1"][0]] == pytest.approx([0.005, 0.25, 1.0])


def test_time_in_milliseconds_from_the_header():
    for head in ("t_ms", "t [ms]", "Time (ms)"):
        text = f"{head},p1,p2\n0,0,0\n100,0.01,-0.005\n200,0.02,0.0025\n300,0.03,0.5\n"
        table = parse_columns(text, ["t", "p1", "p2"])
        check(table)
        assert time_unit_note(table) is None
    plain = parse_columns("t,p1,p2\n0,0,0\n100,0,0\n200,0,0\n300,0,0\n", ["t", "p1", "p2"])
    assert "t_ms" in time_unit_note(plain)  # a hint, not a silent 300 s run


def test_excel_export_bom_crlf_sep_line_quotes_trailing_empty_columns():
    text = (
        "sep=;\r\n"
        '"t [s]";"p1 [m]";"p2 [m]";;\r\n'
        '"0";"0";"0";;\r\n'
        '"0,1";"0,01";"-0,005";;\r\n'
        '"0,2";"0,02";"0,0025";;\r\n'
        '"0,3";"0,03";"0,5";;\r\n'
    )
    for data in (("\ufeff" + text).encode("utf-8"), text.encode("utf-16"), text.encode("cp1252")):
        check(parse_columns(decode_text(data), ["t", "p1", "p2"]))


def test_quoted_cells_with_a_decimal_comma_in_a_comma_file():
    text = 't,p1,p2\n0,0,0\n"0,1","0,01","-0,005"\n0.2,0.02,0.0025\n0.3,"0,03",0.5\n'
    check(parse_columns(text, ["t", "p1", "p2"]))


def test_latin1_header_and_blank_and_comment_lines():
    data = "# exported by a logger\n\nt,p1 [\u00b5m],p2\n0,0,0\n\n0.1,10000,-0.005\n0.2,20000,0.0025\n0.3,30000,0.5\n"
    check(parse_columns(decode_text(data.encode("latin-1")), ["t", "p1", "p2"]))


def test_extra_and_text_columns_are_ignored():
    text = (
        "status,t,p1,p2,note,cond\nok,0,0,0,start,\nbad,0.1,0.01,-0.005,,nan\n"
        "ok,0.2,0.02,0.0025,x,1\nok,0.3,0.03,0.5,,inf\n"
    )
    check(parse_columns(text, ["t", "p1", "p2"]))


@pytest.mark.parametrize(
    ("text", "message"),
    [
        ("a;b;c\n1;2;3\n", "missing column 'p1' (need p1,p2); found header 'a;b;c'"),
        ("p1 [furlong],p2\n1,2\n", "unknown unit 'furlong'"),
        ("p1 [s],p2\n1,2\n", "'s' is a time unit, but p1 is a length"),
        ("p1,p2,P1 [mm]\n1,2,3\n", "'p1' appears twice"),
        ("p1;p2\n0,1;0,1,2\n", "mixes separators"),
        ("p1;p2\n1;2;3\n", "row 2 has 3 cells, the header has 2"),
        ("p1,p2\n" + "1" * 60000 + ",0\n", "too large"),
    ],
)
def test_refusals_quote_what_was_found_on_one_short_line(text, message):
    with pytest.raises(InputError) as exc:
        parse_columns(text, ["p1", "p2"])
    assert message in str(exc.value) and "\n" not in str(exc.value) and len(str(exc.value)) < 300


def test_row_cap_is_stated_and_streaming_stops_there():
    def endless():
        yield "p1,p2\n"
        while True:
            yield "0,0\n"

    with pytest.raises(InputError, match="more than 1000 data rows"):
        parse_lines(endless(), ["p1", "p2"], max_rows=1000)


def test_written_columns_read_back_exactly():
    rng = np.random.default_rng(3)
    cols = {"t": np.sort(rng.random(50)), "p1": rng.normal(size=50) * 1e-3, "p2": rng.normal(size=50) * 1e300}
    back = parse_columns(format_columns(cols), ["t", "p1", "p2"])
    for name, col in cols.items():
        assert np.array_equal(back[name], col)


def test_upload_path_uses_the_same_rules():
    text = 'sep=;\n"t [ms]";"p1 (mm)";"p2 (mm)"\n0;0;0\n100;10;-5\n200;20;2,5\n300;30;500\n'
    traj = parse_trajectory_csv(text)
    assert traj.t == pytest.approx(T) and traj.p[:, 0] == pytest.approx(P1) and traj.p[-1, 1] == 0.5
    assert all(math.isfinite(v) for v in traj.ddp.ravel())
    with pytest.raises(InputError, match="found header"):
        parse_trajectory_csv(io.StringIO("x;y\n1;2\n").getvalue())


CELLS = st.sampled_from(["t", "p1", "p2", "t [ms]", "p1 (mm)", '"0,5"', "1e3", "-", "", " ", "nan", "x", "1,5", "#"])
SEPS = st.sampled_from([",", ";", "\t", "\r\n", "\n", "\r", '"', "sep=;\n", "\ufeff"])


@settings(max_examples=examples(400), deadline=None)
@given(st.lists(st.one_of(CELLS, SEPS, st.text(max_size=6)), max_size=40))
def test_any_text_is_read_or_refused_in_one_line(parts):
    try:
        table = parse_columns("".join(parts), ["t", "p1", "p2"])
    except InputError as exc:
        assert "\n" not in str(exc) and len(str(exc)) < 400
        return
    assert all(np.all(np.isfinite(col)) for col in table.values())
