"""The offline lesson page (issue 39) in headless Chromium, every network request but the page itself aborted and
recorded: every shipped lesson's page loads with no request and no error, is at most 5,000,000 bytes, draws the
platform where the lesson's camera puts it (a projection of ``p(t)``, checked on the canvas's pixels), follows viser's
time slider (the platform moves, the calculator shows that frame), and grades its exercises as ``tpm-viz exercise
grade`` does (a corpus of answers per exercise, every one compared). Once: ``window.tpm`` against the Python closed
form on 10,000 random states, answers typed in the page with the score kept over a reload, the Korean page, and the
SCORM 1.2 package inside a stub LMS served over http.
"""

from __future__ import annotations

import functools
import http.server
import json
import re
import threading
import urllib.parse
import zipfile
from pathlib import Path

import numpy as np
import pytest

from tests.support import calculator as calc
from tests.support.browser import launched_chromium
from tests.support.takehome import (
    PLATFORM_TOP,
    Opened,
    canvas_box,
    canvas_image,
    choice_answers,
    cli_grade,
    cli_json,
    number_answers,
    open_offline,
    pause,
    platform_at,
    pose_answers,
    project,
    random_answers,
    ready,
    seek,
    violations,
)
from tpm_viz.app.exercises.grading import variant_of
from tpm_viz.app.exercises.tasks import zero_pose
from tpm_viz.app.lessons import DEMOS
from tpm_viz.app.moves import Pose
from tpm_viz.app.readouts import Load, evaluate
from tpm_viz.app.transitions import MAX_ACCEL, MAX_POSITION, MAX_SPEED
from tpm_viz.cli import main
from tpm_viz.core.errors import InputError
from tpm_viz.core.numbers import fixed, parse_quantity
from tpm_viz.core.params import Params
from tpm_viz.ui.widgets.typed import Quantity

pytestmark = pytest.mark.browser

LESSONS = list(range(1, len(DEMOS) + 1))
LIMIT = 5_000_000  # bytes, the bound on every shipped lesson's page


@pytest.fixture(scope="module")
def pages(tmp_path_factory) -> dict[str, Path]:
    """Every shipped lesson's page (English, seed 0), the Korean page of lesson 4 (seed 3) and its SCORM package."""
    folder = tmp_path_factory.mktemp("pages")
    built = {}
    for n in LESSONS:
        built[str(n)] = folder / f"lesson-{n}.html"
        assert main(["page", "--lesson", str(n), "--output", str(built[str(n)])]) == 0
    built["ko"] = folder / "lesson-4-ko.html"
    built["scorm"] = folder / "lesson-4.zip"
    argv = ["page", "--lesson", "4", "--lang", "ko", "--seed", "3", "--output", str(built["ko"])]
    assert main(argv) == 0
    assert main(["page", "--lesson", "4", "--scorm", str(built["scorm"])]) == 0
    return built


@pytest.fixture
def chromium():
    """A fresh headless Chromium per test (a browser that has drawn several lessons in software slows down)."""
    with launched_chromium() as browser:
        yield browser


def corpus(entry: dict, seed: int) -> list[str]:
    rng = np.random.default_rng([seed, *entry["id"].encode()])
    if entry["kind"] == "number":
        return number_answers(entry, rng)
    if entry["kind"] == "choice":
        return choice_answers(entry)
    shown = cli_json("exercise", "show", entry["id"], "--seed", str(seed), "--reveal")
    exercise = next(ex for demo in DEMOS for ex in demo.exercises if ex.id == entry["id"])
    other = zero_pose(variant_of(exercise, seed), 1)
    return pose_answers(entry, shown, None if other is None else other * 1e3, rng)


def check_grading(page, seed: int, lang: str) -> int:
    """Every graded exercise of the page on its corpus, attempts 1 and 2 (when the ladder has them): the page's JSON
    is ``tpm-viz exercise grade``'s. Returns how many answers were compared."""
    compared = 0
    for entry in page.evaluate("tpmPage.data.exercises"):
        assert entry["seed"] == seed
        if not entry["graded"]:
            continue
        attempts = [1] if entry["ladder"] is not None and len(entry["ladder"]) == 1 else [1, 2]
        asked = [(text, k) for text in corpus(entry, seed) for k in attempts]
        asked += [(text, 1) for text in random_answers(np.random.default_rng([seed, len(entry["id"])]), 40)]
        got = page.evaluate("([id, asked]) => asked.map(([t, k]) => tpmPage.grade(id, t, k))", [entry["id"], asked])
        want = [cli_grade(entry["id"], seed, text, k, lang) for text, k in asked]
        for (text, k), g, w in zip(asked, got, want, strict=True):
            assert g == w, f"{entry['id']} answer {text!r} attempt {k}: page {g} but tpm-viz exercise grade {w}"
        kinds = {("format" if w["format_error"] else w["score"]) for w in want}
        assert "format" in kinds and 1.0 in kinds and len(kinds) >= 3, (entry["id"], kinds)  # a corpus that bites
        compared += len(want)
    return compared


@pytest.mark.parametrize("lesson", LESSONS)
def test_each_lesson_page_works_offline_draws_follows_the_slider_and_grades_as_the_cli(pages, chromium, lesson):
    path = pages[str(lesson)]
    assert path.stat().st_size <= LIMIT
    demo = DEMOS[lesson - 1]
    opened = open_offline(chromium, path.as_uri(), viewport=(1000, 700))  # SwiftShader draws every pixel: keep it small
    page = opened.page
    try:
        data = page.evaluate("tpmPage.data")
        camera = (np.array(demo.camera.position), np.array(demo.camera.look_at))
        box = canvas_box(page)

        def at(k: int) -> np.ndarray:
            p = data["frames"]["p"][k]
            return project(camera, np.array([p[0], p[1], PLATFORM_TOP]), round(box["width"]), round(box["height"]))

        if len(data["frames"]["t"]) > 1:  # a motion: pause, then two times of the slider
            pause(page)
            p = np.array(data["frames"]["p"])
            n = len(p) - 1
            farthest = max((0.4, 0.55, 0.7, 0.9), key=lambda f: np.linalg.norm(p[round(f * n)] - p[round(0.1 * n)]))
            a = seek(page, 0.1)
            image_a = wait_for_platform(page, at(a))
            b = seek(page, farthest)  # the time farthest from the first along the path (a circle comes back)
            image_b = wait_for_platform(page, at(b))
            assert np.linalg.norm(at(a) - at(b)) > 30  # the platform moved far on the canvas ...
            assert not platform_at(image_b, at(a))  # ... and left its first place
            assert np.abs(image_a - image_b).mean() > 0.5
            shown = page.evaluate("tpmPage.calc.state()")
            assert shown == {"frame": b, "follow": True}
        else:
            wait_for_platform(page, at(0))
        assert violations(page) == []  # viser's client and the page need nothing the page's policy forbids
        ready(page, view=False)  # the drawing is checked: the rest is the panel's
        panel = page.inner_text("#tpm-calculator")
        assert "NaN" not in panel and "undefined" not in panel
        assert page.inner_text("#tpm-score") == f"Score: 0 / {sum(e['graded'] for e in data['exercises'])}"
        for entry in data["exercises"]:  # the seed's prompts; a gains exercise says it needs the app
            card = f"#ex-{entry['id']}"
            assert page.get_attribute(card, "data-seed") == "0"
            assert (
                page.text_content(f"{card} .tpm-prompt")
                == cli_json("exercise", "show", entry["id"], "--seed", "0")["prompt"]
            )
            assert page.locator(f"{card} .tpm-needs-app").count() == (0 if entry["graded"] else 1)
            assert page.locator(f"{card} .tpm-check").count() == (1 if entry["graded"] else 0)
        assert check_grading(page, 0, "en") > 50
        assert opened.errors == []
        assert opened.requests == [path.as_uri()]  # the page itself, nothing else
    finally:
        opened.context.close()


def wait_for_platform(page, xy: np.ndarray, tries: int = 120) -> np.ndarray:
    """The canvas once the platform is drawn at pixel ``xy`` (viser draws a frame after the slider moves)."""
    for _ in range(tries):
        image = canvas_image(page)
        if platform_at(image, xy):
            return image
        page.wait_for_timeout(250)
    raise AssertionError(f"the platform is not drawn at {xy} on the canvas")


def test_window_tpm_is_the_python_closed_form_and_the_panel_refuses_in_the_apps_words(pages, chromium):
    """The calculator of a lesson page: 10,000 random states over random parameter sets against the app's and the
    library's functions (tests/support/calculator.py); then the panel: typed text read with the app's rules (the
    field's own route, tpm_viz.ui.widgets.typed.Quantity), its refusals word for word, never NaN."""
    opened = open_offline(chromium, pages["1"].as_uri(), viewport=(1000, 700), view=False)
    page = opened.page
    try:
        cases = calc.random_cases(39, 125, 80)
        result = calc.compare(cases, page.evaluate(calc.RUN_JS, cases))
        assert len(cases) == 10_000 and result["problems"] == []
        assert all(v <= calc.TOL for v in result["worst"].values()) and min(result["refused"].values()) > 100
        params = Params.paper()
        fields = {"p1": "12,5 mm", "p2": "−0.04 m", "dp1": "250 mm/s", "dp2": "0", "ddp1": "3,5", "ddp2": "-2 m/s²"}
        for key, text in fields.items():
            page.fill(f'#tpm-calculator [data-q="{key}"]', text)
        assert page.evaluate("tpmPage.calc.state().follow") is False  # typing leaves the player
        p, dp, ddp = np.array([0.0125, -0.04]), np.array([0.25, 0.0]), np.array([3.5, -2.0])
        readout = evaluate(params, Pose.working(params, p), Load("dynamic", dp=tuple(dp), ddp=tuple(ddp)))
        assert page.inner_text('[data-q="tau1"]') == fixed(readout.forces.tau[0], ".2f")
        assert page.inner_text('[data-q="d2"]') == fixed(readout.d[1], ".1f", 1e3)
        assert page.inner_text('[data-q="cond"]') == fixed(readout.cond, ".2f")
        for key, text, quantity in [
            ("p1", "NaN", Quantity("p1", "mm", 1e-3, -MAX_POSITION * 1e3, MAX_POSITION * 1e3)),
            ("ddp1", "1e308", Quantity("p̈1", "m/s²", 1.0, -MAX_ACCEL, MAX_ACCEL)),
            ("dp2", "fast", Quantity("ṗ2", "m/s", 1.0, -MAX_SPEED, MAX_SPEED)),
            ("p2", "12 kg", Quantity("p2", "mm", 1e-3, -MAX_POSITION * 1e3, MAX_POSITION * 1e3)),
        ]:
            page.fill(f'#tpm-calculator [data-q="{key}"]', text)
            with pytest.raises(InputError) as refused:
                quantity.read(text) if key != "p2" else parse_quantity(text, "p2", "mm")
            assert page.inner_text("#tpm-refusal") == str(refused.value)
            assert "NaN" not in page.inner_text("#tpm-calculator").replace("'NaN'", "")
            page.fill(f'#tpm-calculator [data-q="{key}"]', fields[key])
        page.fill('#tpm-calculator [data-q="p1"]', "300")  # out of reach: the app's own refusal
        want = calc.reference("evaluate", {}, [0.3, -0.04], list(dp), list(ddp))["error"]["en"]
        assert page.inner_text("#tpm-refusal") == want and page.inner_text('[data-q="tau1"]') == "—"
        assert opened.errors == [] and opened.requests == [pages["1"].as_uri()]
    finally:
        opened.context.close()


def test_answers_typed_in_the_page_score_as_the_cli_and_the_score_survives_a_reload(pages, chromium):
    opened = open_offline(chromium, pages["4"].as_uri(), viewport=(1000, 700), view=False)
    page = opened.page
    try:
        number, pose = "#ex-force-at-pose", "#ex-zero-force-pose"
        ref = cli_json("exercise", "show", "force-at-pose", "--seed", "0", "--reveal")["answer"][0]
        target = cli_json("exercise", "show", "zero-force-pose", "--seed", "0", "--reveal")["answer"]

        def answer(card: str, text: str | None, attempt: int, ident: str) -> dict:
            if text is not None:
                page.fill(f"{card} .tpm-answer-text", text)
            typed = page.input_value(f"{card} .tpm-answer-text")
            page.click(f"{card} .tpm-check")
            want = cli_grade(ident, 0, typed, attempt)
            expected = (
                f"not graded, no attempt used: {want['format_error']}" if want["format_error"] else want["feedback"]
            )
            page.wait_for_function(
                "([c, t]) => document.querySelector(c + ' .tpm-feedback').textContent.startsWith(t)",
                arg=[card, expected],
                timeout=30_000,
            )
            return want

        assert page.inner_text("#tpm-score") == "Score: 0 / 2"
        assert answer(number, "12 apples", 1, "force-at-pose")["format_error"]  # no attempt used
        assert page.inner_text(f"{number} .tpm-left") == "attempts left: 3"
        assert answer(number, f"{-ref!r}", 1, "force-at-pose")["score"] == 0.5  # the sign slip: half credit
        assert page.inner_text("#tpm-score-line") == "Score: 0.5 / 2"
        assert answer(number, f"{ref:.4f}".replace(".", ",") + " N", 2, "force-at-pose")["score"] == 0.7
        assert (
            page.inner_text("#tpm-score") == "Score: 0.7 / 2"
            and page.inner_text(f"{number} .tpm-left") == "attempts left: 1"
        )
        page.click(f"{pose} .tpm-use-pose")  # the calculator's pose: the lesson's start, far from τ1 = 0
        assert answer(pose, None, 1, "zero-force-pose")["score"] == 0.0
        assert answer(pose, f"{target[0] / 1000!r} m; {target[1] / 1000!r} m", 2, "zero-force-pose")["score"] == 1.0
        assert page.inner_text("#tpm-score") == "Score: 1.7 / 2"
        page.reload()
        ready(page, view=False)
        assert page.inner_text("#tpm-score") == "Score: 1.7 / 2"
        assert page.inner_text(f"{number} .tpm-left") == "attempts left: 1"
        assert answer(number, "1", 3, "force-at-pose")["score"] == 0.0
        assert page.inner_text(f"{number} .tpm-left") == "no attempts left" and page.is_disabled(f"{number} .tpm-check")
        assert page.inner_text("#tpm-score") == "Score: 1.7 / 2"  # the best attempt counts
        stored = page.evaluate("JSON.parse(localStorage.getItem('tpm-viz:page:agreement:0'))")
        assert stored["force-at-pose"]["scores"] == [0.5, 0.7, 0.0] and stored["zero-force-pose"]["scores"] == [
            0.0,
            1.0,
        ]
        assert page.evaluate("tpmPage.scorm.api === null && tpmPage.scorm.calls.length === 0")  # no LMS here
        assert opened.errors == [] and set(opened.requests) == {pages["4"].as_uri()}
    finally:
        opened.context.close()


def test_the_korean_page_grades_in_korean_and_fits_a_phone(pages, chromium):
    opened = open_offline(chromium, pages["ko"].as_uri(), viewport=(390, 844), view=False)
    page = opened.page
    try:
        assert page.get_attribute("html", "lang") == "ko"
        for entry in page.evaluate("tpmPage.data.exercises"):
            shown = cli_json("exercise", "show", entry["id"], "--seed", "3", "--lang", "ko")
            assert page.text_content(f"#ex-{entry['id']} .tpm-prompt") == shown["prompt"]
            assert page.get_attribute(f"#ex-{entry['id']}", "data-seed") == "3"
        assert check_grading(page, 3, "ko") > 50
        assert page.evaluate("document.documentElement.scrollWidth") <= 390  # nothing wider than the phone
        assert page.inner_text("#tpm-score").startswith("점수: 0 / 2")
        assert opened.errors == [] and opened.requests == [pages["ko"].as_uri()]
    finally:
        opened.context.close()


LMS = """<!doctype html><html><head><meta charset="utf-8"><title>stub LMS</title><script>
window.calls = [];
const store = Object.assign({"cmi.core.lesson_status": "not attempted"},
                            location.hash ? JSON.parse(decodeURIComponent(location.hash.slice(1))) : {});
function record(name, args, result) { calls.push([name, ...args]); return result; }
window.API = {
  LMSInitialize: (a) => record("LMSInitialize", [a], "true"),
  LMSFinish: (a) => record("LMSFinish", [a], "true"),
  LMSGetValue: (k) => record("LMSGetValue", [k], k in store ? store[k] : ""),
  LMSSetValue: (k, v) => { store[k] = String(v); return record("LMSSetValue", [k, String(v)], "true"); },
  LMSCommit: (a) => record("LMSCommit", [a], "true"),
  LMSGetLastError: () => "0", LMSGetErrorString: () => "No error", LMSGetDiagnostic: () => "",
};
window.store = store;
</script></head><body><iframe id="course" src="frames.html" style="width:100%;height:96vh;border:0"></iframe>
</body></html>"""
FRAMES = """<!doctype html><html><head><title>course</title></head>
<frameset rows="24,*"><frame name="nav" src="nav.html"><frame name="sco" src="sco/index.html"></frameset></html>"""


class Quiet(http.server.SimpleHTTPRequestHandler):
    def log_message(self, *args) -> None:
        pass


def test_the_scorm_package_finds_the_lms_api_reports_its_score_and_finishes(pages, chromium, tmp_path):
    """A stub LMS served over http on 127.0.0.1: its top page defines ``API`` and records every call; a frameset
    page inside it holds the package's page in a frame (the SCO's parent has no API: the page must climb)."""
    with zipfile.ZipFile(pages["scorm"]) as archive:
        archive.extractall(tmp_path / "sco")
    (tmp_path / "lms.html").write_text(LMS)
    (tmp_path / "frames.html").write_text(FRAMES)
    (tmp_path / "nav.html").write_text("<!doctype html><title>nav</title><p>course navigation</p>")
    server = http.server.ThreadingHTTPServer(("127.0.0.1", 0), functools.partial(Quiet, directory=str(tmp_path)))
    thread = threading.Thread(target=server.serve_forever, daemon=True)
    thread.start()
    base = f"http://127.0.0.1:{server.server_address[1]}/"
    try:
        opened = open_lms(chromium, base, "")
        page, sco = opened.page, opened.page.frame(name="sco")
        calls = page.evaluate("calls")
        assert calls[0] == ["LMSInitialize", ""] and ["LMSGetValue", "cmi.student_data.mastery_score"] in calls
        assert ["LMSSetValue", "cmi.core.lesson_status", "incomplete"] in calls
        ref = cli_json("exercise", "show", "force-at-pose", "--seed", "0", "--reveal")["answer"][0]
        target = cli_json("exercise", "show", "zero-force-pose", "--seed", "0", "--reveal")["answer"]
        assert sco.evaluate("([t]) => tpmPage.submit('force-at-pose', t).score", [repr(ref)]) == 1.0
        store = page.evaluate("store")
        assert (store["cmi.core.score.raw"], store["cmi.core.lesson_status"]) == ("50", "incomplete")
        assert (store["cmi.core.score.min"], store["cmi.core.score.max"]) == ("0", "100")
        text = f"{target[0]!r}; {target[1]!r}"
        assert sco.evaluate("([t]) => tpmPage.submit('zero-force-pose', t).score", [text]) == 1.0
        store = page.evaluate("store")
        assert (store["cmi.core.score.raw"], store["cmi.core.lesson_status"]) == ("100", "passed")
        calls = page.evaluate("calls")
        last_set = max(i for i, c in enumerate(calls) if c[0] == "LMSSetValue")
        assert calls[last_set + 1] == ["LMSCommit", ""] and not any(c[0] == "LMSFinish" for c in calls)
        sco.goto(base + "nav.html")  # the learner leaves the lesson
        page.wait_for_function("calls.some((c) => c[0] === 'LMSFinish')", timeout=30_000)
        calls = page.evaluate("calls")
        assert calls[-1] == ["LMSFinish", ""] and sum(c[0] == "LMSFinish" for c in calls) == 1
        assert calls[-2][:2] == ["LMSSetValue", "cmi.core.session_time"]
        assert re.fullmatch(r"\d{4}:\d{2}:\d{2}\.\d{2}", calls[-2][2])  # SCORM 1.2's CMITimespan
        suspended = store["cmi.suspend_data"]
        assert all(r.startswith(base) for r in opened.requests) and opened.errors == []
        opened.context.close()
        # another browser, the same learner: the attempts come back from the LMS's suspend data
        again = open_lms(chromium, base, urllib.parse.quote(json.dumps({"cmi.suspend_data": suspended})))
        assert again.page.frame(name="sco").inner_text("#tpm-score") == "Score: 2 / 2"
        assert again.page.evaluate("store")["cmi.core.lesson_status"] == "passed"
        again.context.close()
    finally:
        server.shutdown()
        thread.join(timeout=10)


def open_lms(chromium, base: str, fragment: str):
    context = chromium.new_context(viewport={"width": 1000, "height": 700})
    requests: list[str] = []
    errors: list[str] = []

    def route(r) -> None:
        requests.append(r.request.url)
        r.continue_() if r.request.url.startswith(base) else r.abort()

    context.route("**/*", route)
    page = context.new_page()
    page.on("pageerror", lambda exc: errors.append(str(exc)))
    page.goto(base + "lms.html" + (f"#{fragment}" if fragment else ""))
    page.wait_for_function("calls.some((c) => c[0] === 'LMSCommit')", timeout=120_000)
    ready(page.frame(name="sco"), view=False)
    return Opened(context, page, requests, errors)
