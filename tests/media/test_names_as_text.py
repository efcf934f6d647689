"""A file name is text in every output that shows it (issue 35, item 7): ``x$\\frac{$.csv`` made ``tpm-viz report``
and ``clip`` exit 1 with a 55-line matplotlib traceback, and any ``$…$`` in a name was set as maths in titles.

Each hostile name (mathtext that does not parse, mathtext that does, underscores, Hangul, 200 characters, HTML) goes
through the report (its HTML and its force figure), the clip as GIF and MP4, the app's force figures (PNG, SVG) and
its 3D-view clip frames: exit 0 and no warning, and the name is found as it was typed, in the report's text and in
the matplotlib ``Text`` that draws it (``parse_math`` off: never read as maths).
"""

from __future__ import annotations

import html
import re

import numpy as np
import pytest
from matplotlib.text import Text

from tpm_viz.app.runs import Source, build_run
from tpm_viz.cli import main
from tpm_viz.core.params import Params
from tpm_viz.drawing import figures
from tpm_viz.drawing.palette import PALETTE
from tpm_viz.media.clips import ClipRenderer
from tpm_viz.media.views3d import Camera, View3dRenderer
from tpm_viz.paper.trajectories import parse_trajectory_csv

NAMES = ["x$\\frac{$", "$x^2$", "a_b_c", "한국어 궤적", "L" * 200, "<b>&amp;<i> $$", "$\\alpha$ \\n"]
CSV = "t,p1,p2\n0,0,0\n0.1,0.01,0\n0.2,0.02,0.01\n0.3,0.03,0.01\n"
IDS = ["frac", "x2", "underscores", "hangul", "long", "html", "alpha"]


def _texts_showing(fig, text: str) -> list[Text]:
    return [t for t in fig.findobj(Text) if text in t.get_text()]


def _shown_as_text(fig, text: str, draw: bool = True) -> None:
    """``text`` is in a Text of ``fig`` as it was typed, and that Text never reads it as maths; drawing ``fig`` raises
    nothing (mathtext would have raised on the first name; ``draw=False`` where the caller renders it anyway)."""
    found = _texts_showing(fig, text)
    assert found, f"{text!r} is not in any text of the figure"
    assert all(not t.get_parse_math() for t in found)
    if draw:
        fig.canvas.draw()


@pytest.fixture
def csv_named(tmp_path):
    def make(name: str):
        path = tmp_path / f"{name}.csv"
        path.write_text(CSV)
        return path

    return make


@pytest.mark.parametrize("name", NAMES, ids=IDS)
def test_the_report_shows_a_name_as_it_was_typed(name, csv_named, tmp_path, capsys):
    out = tmp_path / "report.html"
    assert main(["report", "--trajectory", str(csv_named(name)), "--samples", "11", "--output", str(out)]) == 0
    err = capsys.readouterr().err  # no traceback, no warning (a Hangul glyph missing is not said per glyph)
    assert err.count("\n") == 1 and err.startswith(f"tpm-viz report: {out}: ") and "Traceback" not in err
    page = out.read_text(encoding="utf-8")
    title = re.search(r"<title>(.*?)</title>", page, re.S).group(1)
    heading = re.search(r"<h1>(.*?)</h1>", page, re.S).group(1)
    for part in (title, heading):
        assert f"{name}.csv" in html.unescape(part)
    assert "<b>&amp;<i>" not in page  # the HTML name is escaped, never markup


@pytest.mark.parametrize("fmt", ["gif", "mp4"])
@pytest.mark.parametrize("name", NAMES, ids=IDS)
def test_the_clip_is_made_whatever_the_name(name, fmt, csv_named, tmp_path, capsys):
    out = tmp_path / f"clip.{fmt}"
    argv = ["clip", "--trajectory", str(csv_named(name)), "--samples", "5", "--size", "320x180", "--output", str(out)]
    assert main(argv) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith(f"tpm-viz clip: {out}"), err  # its one line, nothing else
    assert out.stat().st_size > 0


def _run(name: str):
    params = Params.paper()
    source = Source.from_trajectory(parse_trajectory_csv(CSV, name=f"{name}.csv"))
    return build_run(params, source, None, samples=5)


@pytest.mark.parametrize("name", NAMES, ids=IDS)
def test_the_clips_title_is_text_not_maths(name):
    run = _run(name)
    renderer = ClipRenderer(run, run.source.label, (320, 180))
    _shown_as_text(renderer.fig, f"{name}.csv")
    assert renderer.frame(len(renderer) - 1).shape == (180, 320, 3)


@pytest.mark.parametrize("name", NAMES, ids=IDS)
def test_the_force_figures_title_is_text_not_maths(name):
    run = _run(name)
    title = f"Actuator forces: {run.source.label}"  # as the player's downloads and the report title it
    fig = figures._force_figure(run.t, run.tau, None, title, 50)
    _shown_as_text(fig, f"{name}.csv", draw=False)  # the same figure is drawn into the PNG just below
    assert figures.force_plot_png(run.t, run.tau, None, title=title, dpi=30).startswith(b"\x89PNG")
    svg = figures.force_plot_svg(run.t, run.tau, np.asarray(run.tau) * 1.001, title=title)
    assert svg.lstrip().startswith(b"<?xml")


@pytest.mark.parametrize("name", NAMES, ids=IDS)
def test_the_3d_clip_frames_draw_any_title(name):
    run = _run(name)
    camera = Camera.looking_at((0.0, -0.6, 0.6), (0.0, 0.0, 0.0), (0.0, 0.0, 1.0), 0.9, 16 / 9)
    colours = {**PALETTE, "marker": (255, 0, 255), "path": (234, 179, 8), "trace": (15, 23, 42)}
    renderer = View3dRenderer(run, run.source.label, (320, 180), camera, colours)
    assert renderer.title == run.source.label  # kept as typed; the frame cuts it to the box with an ellipsis
    assert renderer.frame(0).shape == (180, 320, 3)
