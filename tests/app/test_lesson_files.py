"""assets/: lessons as TOML files (loaded, refused with file and line, their stated numbers recomputed), the
example trajectories and the parameter presets; the Demos tab on a lecturer's own lessons."""

from __future__ import annotations

import html
import pathlib
import re
import shutil
import tomllib
from types import SimpleNamespace

import numpy as np
import pytest

from tests.support.fake_viser import FakeApi
from tests.support.fixtures import app, connect  # noqa: F401  (the served app, for the last test)
from tpm_viz import Params
from tpm_viz.app.demos import CHECK_NAMES
from tpm_viz.app.lesson_files import line_of
from tpm_viz.app.lessons import (
    CHECKS,
    DEMOS,
    PROBLEMS,
    Check,
    assets_dir,
    check_values,
    demo_by_key,
    demo_params,
    demo_pose,
    demo_source,
    effect,
    load_lessons,
    load_preset,
    verify,
)
from tpm_viz.app.runs import Source, build_run
from tpm_viz.core.errors import InputError
from tpm_viz.core.words import Lang
from tpm_viz.paper.trajectories import parse_trajectory_csv

ASSETS = assets_dir()
LESSONS = ASSETS / "lessons"
P = Params.paper()

GOOD = """title = "7. Mine"
[text]
en = "A lesson of my own, for the tests."
[pose]
p = [0.0, 0.0]
"""


def test_the_packaged_assets_are_found_and_the_tour_loads_without_problems():
    for folder in ("lessons", "trajectories", "presets"):
        assert (ASSETS / folder / "README.md").is_file()
    assert PROBLEMS == ()
    assert [pathlib.Path(d.source).name for d in DEMOS] == sorted(p.name for p in LESSONS.glob("*.toml"))
    assert [d.key for d in DEMOS] == ["direct", "workspace", "speed", "agreement", "modes", "inverse"]
    assert all(d.checks for d in DEMOS)


@pytest.mark.parametrize("demo", DEMOS, ids=[d.key for d in DEMOS])
def test_every_number_a_lesson_states_is_recomputed_and_true(demo):
    from tpm_viz.multibody.model import inverse_dynamics as pinocchio

    assert verify(demo, reference=pinocchio) == []
    values = check_values(demo, reference=pinocchio)
    assert set(values) == {c.name for c in demo.checks} and all(np.isfinite(v) for v in values.values())


def test_a_stated_number_that_is_wrong_is_caught():
    demo = demo_by_key("workspace")
    wrong = demo.__class__(**{**demo.__dict__, "checks": (Check("workspace_cm2", 800.0),)})
    (line,) = verify(wrong)
    assert "checks.workspace_cm2 states 800, the scene gives 770.5" in line and line.startswith(demo.source)
    assert verify(demo.__class__(**{**demo.__dict__, "checks": (Check("workspace_cm2", 800.0, tol=30.0),)})) == []


def test_every_check_name_is_computed_and_documented():
    assert set(CHECKS) == set(CHECK_NAMES)
    readme = (LESSONS / "README.md").read_text()
    assert all(f"`{name}`" in readme for name in CHECK_NAMES)
    with pytest.raises(InputError, match="unknown check 'nope'"):
        check_values(DEMOS[0], ["nope"])


def test_the_effect_lines_are_those_of_the_tour():
    assert "×7.0" in str(effect(demo_by_key("direct"))) and "944 → 771 cm²" in str(effect(demo_by_key("workspace")))


def _folder(tmp_path, files: dict[str, str]) -> pathlib.Path:
    folder = tmp_path / "lessons"
    folder.mkdir()
    for name, text in files.items():
        (folder / name).write_text(text, encoding="utf-8")
    return folder


BAD = {
    "syntax": ('title = "x"\n[text]\nen = "y"\nmap = = 3\n', 4, "TOML: Invalid value (column 7)"),
    "unknown_top": ("colour = 3\n" + GOOD, 1, "unknown key 'colour'; known: key, title, text"),
    "in_pose": (GOOD + "colour = 3\n", 6, "unknown key pose.colour; known: p, d, mode"),
    "unknown_in_table": (GOOD + "[view]\nmap = 'off'\nellipse = true\n", 8, "unknown key view.ellipse; known: map"),
    "wrong_type": (GOOD.replace("p = [0.0, 0.0]", 'p = "centre"'), 5, "pose.p must be a list of 2 numbers"),
    "param_refused": (GOOD + "[params]\nm_p = 1.0\nl_a = -0.2\n", 8, "parameters refused: parameter l_a must be"),
    "unknown_param": (GOOD + "[params]\nlength = 0.2\n", 7, "unknown key params.length; known: a, b, l_a"),
    "no_english": (GOOD.replace('en = "A', 'ko = "A'), 2, "missing text.en"),
    "language": (GOOD.replace('en = "A', 'en = "B"\nfr = "A'), 4, "unknown key text.fr; known: en, ko"),
    "no_title": (GOOD.replace('title = "7. Mine"', ""), 1, "missing title"),
    "unreachable": (
        GOOD.replace("[0.0, 0.0]", "[0.3, 0.0]"),
        4,
        "the pose: platform position (300.0, 0.0) mm is unreachable",
    ),
    "both": (GOOD + "[motion]\nkind = 'line'\nduration = 0.2\n", 4, "give [pose] or [motion], not both"),
    "map": (GOOD + "[view]\nmap = 'heat'\n", 7, "view.map must be one of off, workspace, det_jx, cond"),
    "check_name": (GOOD + "[checks]\npeak = 3.0\n", 7, "unknown key checks.peak"),
    "check_table": (GOOD + "[checks]\ndet_jx = { value = 1.0, tolerance = 0.1 }\n", 7, "checks.det_jx: unknown key"),
    "segment": (
        GOOD.replace("[pose]\np = [0.0, 0.0]\n", "[motion]\nkind = 'segment'\nduration = 0.5\nstart = [0, 0]\n"),
        5,
        "a segment motion needs motion.end",
    ),
    "crossing": (
        GOOD.replace("[pose]\np = [0.0, 0.0]\n", "[motion]\nkind = 'csv'\nfile = 'csv/cross.csv'\n"),
        4,
        "the motion: at t = 0.820 s, p = (-181.6, -181.6) mm: the platform would come too close to the direct "
        "singularity",
    ),
    "missing_csv": (
        GOOD.replace("[pose]\np = [0.0, 0.0]\n", "[motion]\nkind = 'csv'\nfile = 'nope.csv'\n"),
        6,
        "motion.file 'nope.csv': cannot open (No such file or directory)",
    ),
}


@pytest.mark.parametrize("case", sorted(BAD))
def test_a_lesson_with_a_mistake_is_refused_with_file_line_and_what_and_the_others_still_load(tmp_path, case):
    text, line, what = BAD[case]
    folder = _folder(tmp_path, {"01-first.toml": GOOD, "02-bad.toml": text, "03-last.toml": GOOD.replace("7.", "8.")})
    (folder / "csv").mkdir()  # a lesson's CSV lives inside the lessons folder
    shutil.copy(ASSETS / "trajectories" / "singular_crossing.csv", folder / "csv" / "cross.csv")
    lessons, problems = load_lessons(folder)
    assert [d.key for d in lessons] == ["first", "last"]
    assert [d.title for d in lessons] == ["7. Mine", "8. Mine"]
    (problem,) = problems
    assert problem.startswith(f"{folder / '02-bad.toml'}:{line}: "), problem
    assert what in problem, problem
    assert "\n" not in problem


def test_duplicate_titles_and_empty_or_missing_folders_are_refused(tmp_path):
    folder = _folder(tmp_path, {"a.toml": GOOD, "b.toml": 'key = "other"\n' + GOOD, "c.toml": GOOD})
    lessons, problems = load_lessons(folder)
    assert [d.key for d in lessons] == ["a"]
    assert problems[0].startswith(f"{folder / 'b.toml'}:2: title '7. Mine' is already used by")
    assert problems[1].startswith(f"{folder / 'c.toml'}:1: title '7. Mine' is already used by {folder / 'a.toml'}")
    assert load_lessons(tmp_path / "nope") == ((), (f"{tmp_path / 'nope'}: not a folder of lessons",))
    (tmp_path / "empty").mkdir()
    (tmp_path / "empty" / ".#backup.toml").write_text("not a lesson")  # editor files are not lessons
    assert load_lessons(tmp_path / "empty")[1] == (f"{tmp_path / 'empty'}: no lesson files (*.toml)",)
    assert [d.key for d in load_lessons(folder / "c.toml")[0]] == ["c"]  # one file is a tour of one lesson


def test_a_lecturer_lesson_may_play_a_csv_omit_the_camera_and_carry_a_korean_text(tmp_path):
    text = (
        'title = "Figure eight"\n[text]\nen = """\nA figure eight\nthrough the centre."""\nko = "팔자 궤적"\n'
        "[motion]\nkind = 'csv'\nfile = '../trajectories/figure_eight.csv'\nduration = 4.0\ncompare = [2.0, 4.0]\n"
        "[checks]\npeak_ratio = { value = 4.0, tol = 1e-6 }\ndet_jx_start = 1.0\n"
    )
    folder = _folder(tmp_path, {"eight.toml": text.replace("../trajectories/", "trajectories/")})
    shutil.copytree(ASSETS / "trajectories", folder / "trajectories")  # inside the lessons folder
    (demo,), problems = load_lessons(folder)
    assert problems == ()
    assert demo.key == "eight" and demo.camera is None and demo.text == "A figure eight through the centre."
    assert demo.text_in("ko") == "팔자 궤적" and demo.text_in("de") == demo.text
    source = demo_source(demo)
    assert source.kind == "csv" and source.duration == pytest.approx(4.0)  # the file's 2 s, retimed
    run = build_run(P, source)
    np.testing.assert_allclose(run.p[0], demo_pose(demo, P).p, atol=1e-12)
    assert verify(demo) == []
    assert effect(demo).startswith("peak |τ_i| at motion.compare[0] / at motion.compare[1]: 4")


def test_line_of_finds_keys_in_tables_dotted_keys_and_skips_multiline_text():
    text = 'title = "t"\ntext.en = """\nmap = 1\n"""\n[view]\nmap = "off"\n[checks]\ncond = { value = 1 }\n'
    assert line_of(text, "", "title") == 1 and line_of(text, "text") == 2 and line_of(text, "text", "en") == 2
    assert line_of(text, "view", "map") == 6 and line_of(text, "view") == 5 and line_of(text, "checks", "cond") == 8
    assert line_of(text, "params", "l_a") == 1


TRAJECTORIES = sorted((ASSETS / "trajectories").glob("*.csv"))


@pytest.mark.parametrize("path", TRAJECTORIES, ids=[p.stem for p in TRAJECTORIES])
def test_each_example_trajectory_is_a_documented_si_csv(path):
    text = path.read_text()
    assert text.splitlines()[0] == "t,p1,p2"
    assert f"## {path.name}" in (ASSETS / "trajectories" / "README.md").read_text()
    traj = parse_trajectory_csv(text, path.stem)
    assert traj.t[0] == 0.0 and np.all(np.diff(traj.t) > 0) and np.all(np.abs(traj.p) < P.l_a)
    source = Source.from_trajectory(traj)
    if path.stem == "singular_crossing":  # crosses the direct singularity on purpose
        with pytest.raises(InputError, match=r"at t = 0\.820 s.*direct singularity"):
            build_run(P, source)
    else:
        run = build_run(P, source)
        assert 10.0 < run.peak < 50.0
        np.testing.assert_allclose(run.p[[0, -1]], traj.p[[0, -1]], atol=1e-12)


def test_the_presets_are_the_paper_and_its_variants():
    presets = {p.stem: load_preset(p) for p in sorted((ASSETS / "presets").glob("*.toml"))}
    assert presets["paper"] == P and len(presets) >= 2
    assert presets["short_links"] == P.replace(l_a=0.2) and presets["heavy_payload"] == P.replace(m_p=4.21)
    readme = (ASSETS / "presets" / "README.md").read_text()
    assert all(f"`{name}.toml`" in readme for name in presets)


def test_a_bad_preset_is_refused_with_its_line(tmp_path):
    path = tmp_path / "bad.toml"
    path.write_text('name = "bad"\n[params]\nl_a = 0.26\nstroke = 0.0\n')
    with pytest.raises(InputError, match="parameters refused: parameter stroke must be positive") as exc:
        load_preset(path)
    assert exc.value.line == 4


def test_the_demos_tab_takes_a_lecturers_lessons_and_lists_the_refused_files(tmp_path):
    from tpm_viz.ui.teaching.lessons import DemosView

    folder = _folder(tmp_path, {"01-a.toml": GOOD, "02-b.toml": GOOD + "colour = 1\n"})
    lessons, problems = load_lessons(folder)
    view = DemosView(SimpleNamespace(lang=Lang.EN), None, None, lambda: 1.0, lessons=lessons, problems=problems)
    gui = FakeApi()
    view.build(gui)
    assert view.choice.value == "7. Mine" and "A lesson of my own" in view.text.content
    (note,) = [n for n in gui.nodes if n.kind == "add_html" and "demo-problems" in n.content]
    assert "1 lesson file(s) refused" in note.content and re.search(r"02-b\.toml:6: unknown key", note.content)
    empty = DemosView(
        SimpleNamespace(lang=Lang.EN), None, None, lambda: 1.0, lessons=(), problems=("x: no lesson files",)
    )
    empty.build(FakeApi())
    assert empty.choice.disabled and empty.play.disabled and "No lessons" in empty.text.content
    default = DemosView(SimpleNamespace(lang=Lang.EN), None, None, lambda: 1.0)
    assert default.lessons == DEMOS and default.problems == ()


def test_a_refused_lesson_file_is_listed_in_the_tabs_language(tmp_path):
    from tpm_viz.ui.teaching.lessons import problems_html

    folder = _folder(tmp_path, {"01-a.toml": GOOD, "02-b.toml": GOOD.replace("[pose]", "[pose]\nmode = 2")})
    _lessons, (problem,) = load_lessons(folder)
    where = f"{folder / '02-b.toml'}:5: "
    assert problem == where + "pose.mode must be 1 (working) or -1, got 2"  # English: the command line, the log
    korean = problems_html((problem,), Lang.KO)
    assert html.escape(where) in korean and "pose.mode" in korean and "1 (작업)" in korean
    words = korean.replace(html.escape(where), "")  # the folder's name is the test's, in English
    assert "must be" not in words and "refused" not in words


def test_a_lecturer_lesson_without_camera_is_shown_in_the_app(request, tmp_path):
    from tests.support.protocol import wait_for

    folder = _folder(tmp_path, {"a.toml": GOOD.replace("[0.0, 0.0]", "[0.05, -0.02]") + "[params]\nm_p = 3.0\n"})
    (lesson,), _ = load_lessons(folder)
    _client, view = request.getfixturevalue("connect")()  # tests.support.fixtures
    demos = view.teaching.demos
    demos.lessons, demos.titles = (lesson,), (lesson.title,)
    demos.show(0)
    wait_for(lambda: view.session.state.params == demo_params(lesson), what="the lesson's mechanism")
    np.testing.assert_allclose(view.session.state.pose.p, (0.05, -0.02))
    assert "A lesson of my own" in demos.text.content and demos.play.disabled
    assert "demo-effect" not in demos.text.content  # no [checks]: no line of numbers


def test_pyproject_installs_assets_as_tpm_viz_assets_with_every_file_and_every_package():
    """What makes a wheel (and an editable install) ship assets/ as tpm_viz.assets: the explicit package list names
    every subpackage of tpm_viz, and a package-data pattern covers every file of assets/ (building a wheel is too
    slow for the suite)."""
    root = pathlib.Path(__file__).resolve().parents[2]
    setuptools = tomllib.loads((root / "pyproject.toml").read_text())["tool"]["setuptools"]
    packages = {".".join(p.parent.relative_to(root).parts) for p in (root / "tpm_viz").rglob("__init__.py")}
    assert set(setuptools.get("packages", [])) == packages | {"tpm_viz.assets"}, "pyproject: [tool.setuptools] packages"
    assert setuptools["package-dir"] == {"tpm_viz.assets": "assets"}
    assets = root / "assets"
    patterns = setuptools["package-data"]["tpm_viz.assets"]
    shipped = {path for pattern in patterns for path in assets.glob(pattern)}
    files = {p for p in assets.rglob("*") if p.is_file() and "__pycache__" not in p.parts and p.suffix != ".py"}
    assert files - shipped == set(), "files of assets/ that no package-data pattern ships"
