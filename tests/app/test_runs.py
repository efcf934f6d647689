"""Trajectory runs (tpm_viz.app.runs) against the library they are built from, the CSV upload's checks, the
CSV export and the force-plot PNG. No viser."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import InputError, Params, actuator_acceleration, actuator_velocity, inverse_dynamics
from tpm_viz.app.inputs import read_upload
from tpm_viz.app.runs import RUN_SAMPLES, Source, build_run, check_path
from tpm_viz.core.csvio import format_columns, parse_columns
from tpm_viz.drawing.figures import force_plot_png, force_plot_svg
from tpm_viz.paper.trajectories import circle_state, line_state

P = Params.paper()


def _csv(t, p) -> bytes:
    rows = "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n" for a, (b, c) in zip(t, p, strict=True))
    return ("t,p1,p2\n" + rows).encode()


def test_paper_sources_default_to_the_conventions_durations():
    assert Source.paper("line").duration == 0.2 and Source.paper("circle").duration == 0.5
    assert Source.paper("circle", 1.0).label == "circle (Fig. 5), T = 1 s"
    for bad in (0.0, -1.0, float("nan"), 1e9, "x"):
        with pytest.raises(InputError):
            Source.paper("line", bad)
    with pytest.raises(InputError):
        Source.paper("spiral")


def test_a_run_is_the_procedure_a_to_e_at_every_sample():
    run = build_run(P, Source.paper("circle"))
    assert len(run.t) == RUN_SAMPLES and run.t[-1] == pytest.approx(0.5)
    p, dp, ddp = circle_state(run.t, 0.5)
    np.testing.assert_allclose(run.p, p)
    np.testing.assert_allclose(run.dd, actuator_velocity(P, p, dp), atol=1e-12)
    np.testing.assert_allclose(run.ddd, actuator_acceleration(P, p, dp, ddp), atol=1e-9)
    np.testing.assert_allclose(run.tau, inverse_dynamics(P, p, dp, ddp), atol=1e-9)
    assert run.tau_ref is None and run.max_diff is None and run.ref_note
    assert run.peak == pytest.approx(np.max(np.abs(run.tau)))


def test_state_at_is_exact_between_samples_and_index_at_is_the_nearest_sample():
    run = build_run(P, Source.paper("line"))
    t, p, dp, ddp = run.state_at(0.0123)
    ref = line_state(0.0123, 0.2)
    assert t == 0.0123
    for got, want in zip((p, dp, ddp), ref, strict=True):
        np.testing.assert_allclose(got, want)
    assert run.state_at(9.0)[0] == 0.2 and run.state_at(-1.0)[0] == 0.0
    assert run.index_at(0.1) == (RUN_SAMPLES - 1) // 2 and run.index_at(1e9) == RUN_SAMPLES - 1


def test_the_pinocchio_forces_are_computed_once_per_run_and_agree():
    from tpm_viz.multibody.model import inverse_dynamics as pinocchio

    calls = []

    def reference(params, p, dp, ddp):
        calls.append(len(p))
        return pinocchio(params, p, dp, ddp)

    run = build_run(P, Source.paper("line"), reference)
    assert calls == [RUN_SAMPLES]  # one vectorised call for the whole run
    assert np.max(np.abs(run.tau_ref - run.tau) / (1.0 + np.abs(run.tau))) < 1e-9
    broken = build_run(P, Source.paper("line"), lambda *a: np.full((RUN_SAMPLES, 2), np.nan))
    assert broken.tau_ref is None and "non-finite" in str(broken.ref_note)


def test_peak_force_goes_as_one_over_t_squared():
    fast, slow = (build_run(P, Source.paper("circle", t)).peak for t in (0.5, 1.0))
    assert fast / slow == pytest.approx(4.0, rel=1e-9)


@pytest.mark.parametrize(
    ("p", "words"),
    [
        ((0.30, 0.0), "out of reach"),
        ((0.20, 0.0), "actuator 1 would leave its stroke"),
        ((-0.235, -0.2599), "inverse singularity"),
        ((-0.182, -0.182), "direct singularity"),
    ],
)
def test_check_path_names_the_first_bad_sample(p, words):
    t = np.linspace(0.0, 1.0, 5)
    path = np.zeros((5, 2))
    path[3] = p
    with pytest.raises(InputError) as info:
        check_path(P, t, path, "my path")
    text = str(info.value)
    assert words in text and "t = 0.750 s" in text and "\n" not in text and text.startswith("my path: ")


def test_a_segment_through_a_singularity_is_refused():
    with pytest.raises(InputError, match="direct singularity"):
        build_run(P, Source.segment((0.0, 0.0), (-0.2, -0.2), 0.5))


def test_an_uploaded_csv_is_checked_then_played_through_its_spline():
    t = np.linspace(0.0, 2.0, 41)
    p = np.stack([0.05 * np.sin(np.pi * t), 0.04 * (1 - np.cos(np.pi * t))], -1)
    source = Source.from_trajectory(read_upload(_csv(t, p), "../../etc/my path.csv"))
    assert source.kind == "csv" and source.label == "my path.csv, T = 2 s" and source.duration == 2.0
    run = build_run(P, source)
    np.testing.assert_allclose(run.p[::10], p, atol=1e-12)  # through the knots (uniform run grid)
    assert np.all(np.isfinite(run.tau))


@pytest.mark.parametrize(
    ("content", "words"),
    [
        (b"", "empty"),
        (b"t,x,y\n0,0,0\n", "missing column"),
        (b"t,p1,p2\n0,0,0\n1,nan,0\n2,0,0\n3,0,0\n", "not finite"),
        (b"t,p1,p2\n0,0,0\n1,0,0\n1,0,0\n3,0,0\n", "increase strictly"),
        (b"t,p1,p2\n0,0,0\n1,0,0\n", "at least 4"),
        (b"\xff\xfe\x00t", "not"),
        (b"t,p1,p2\n" + b"0,0,0\n" * 200_000, "too large"),
    ],
    ids=["empty", "columns", "nan", "time", "rows", "binary", "size"],
)
def test_bad_uploads_are_refused_in_one_line(content, words):
    with pytest.raises(InputError) as info:
        Source.from_trajectory(read_upload(content, "bad.csv"))
    assert words in str(info.value) and "\n" not in str(info.value)


def test_an_unreachable_upload_is_refused_by_the_run_not_the_parser():
    t = np.linspace(0.0, 1.0, 6)
    p = np.zeros((6, 2))
    p[3] = (0.3, 0.0)  # a sample beyond l_a: the user's own samples are checked first
    source = Source.from_trajectory(read_upload(_csv(t, p), "far.csv"))
    with pytest.raises(InputError, match=r"far\.csv, T = 1 s: at t = 0\.600 s, p = \(300\.0, 0\.0\) mm: out of reach"):
        build_run(P, source)


def test_the_csv_export_round_trips_and_leaves_missing_reference_cells_empty():
    run = build_run(P, Source.paper("line"))
    text = format_columns(run.columns())
    header = text.splitlines()[0].split(",")
    assert header[:3] == ["t", "p1", "p2"] and header[-2:] == ["tau1_pinocchio", "tau2_pinocchio"]
    assert text.splitlines()[1].endswith(",,")  # no reference model: empty cells, never "nan"
    cols = parse_columns(text.replace(",,", ",0,0"), [h for h in header if h != "t"])
    np.testing.assert_array_equal(cols["tau1"], run.tau[:, 0])  # 17 significant digits: lossless
    np.testing.assert_array_equal(cols["ddd2"], run.ddd[:, 1])


def test_the_force_plot_is_a_print_size_png_or_an_svg_with_or_without_the_reference():
    run = build_run(P, Source.paper("line"))
    for ref in (None, run.tau + 1e-13):
        png = force_plot_png(run.t, run.tau, ref, title="line")
        assert png[:8] == b"\x89PNG\r\n\x1a\n"
        width = int.from_bytes(png[16:20], "big")  # the IHDR chunk: width, then height, big-endian
        assert width >= 1600  # issue 13: print size
        svg = force_plot_svg(run.t, run.tau, ref, title="line")
        assert svg.lstrip().startswith(b"<?xml") and b"<svg" in svg[:2000]


def test_trace_segments_and_the_summary_never_show_nan():
    from tpm_viz.classroom.runhub import PlayerSession
    from tpm_viz.ui.teaching.player.text import summary_html
    from tpm_viz.ui.teaching.player.trace import segments

    p = np.stack([np.linspace(0, 0.1, 1001), np.zeros(1001)], -1)
    segs = segments(p, 0.08, 150)
    assert segs.dtype == np.float32 and len(segs) <= 150 and np.allclose(segs[-1, 1, :2], (0.1, 0.0))
    assert np.all(segs[1:, 0] == segs[:-1, 1]) and np.all(segs[..., 2] == np.float32(0.08))  # a chained polyline
    assert segments(p[:1], 0.0, 10).shape == (1, 2, 3)
    run = build_run(P, Source.paper("line"))
    ps = PlayerSession(run=run, previous=("circle", float("nan")))
    text = summary_html(ps, run, None)
    assert "nan" not in text.lower() and "moved by hand" in text and "151.1" in text
    assert "<b>line (Fig. 4), T = 0.2 s</b>" in summary_html(PlayerSession(), run, 0.1)
