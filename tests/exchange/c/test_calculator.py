"""The page calculator ``window.tpm`` (issue 39) in headless Chromium: a minimal page from a file:// URL with every
network request blocked, one page load, each batch of calls in one ``page.evaluate``; the answers against the app's
and the library's own functions (:mod:`tests.support.calculator`), and the script's words against the catalogue."""

from __future__ import annotations

import math
import re
import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from tests.support import calculator as calc
from tests.support.browser import launched_chromium
from tpm_viz.core.numbers import fixed
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, catalogue, fields_of
from tpm_viz.exchange.c.calculator import SCRIPT, WORDS, calculator_assets

STATIC = Path(__file__).resolve().parents[3] / "assets" / "calculator" / SCRIPT
LITERAL = re.compile(r'P\(\s*((?:"(?:[^"\\]|\\.)*"\s*\+?\s*)+)')


def script_templates(source: str) -> set[str]:
    """The English templates the script renders: the (concatenated) string literal of every ``P(...)``."""
    return {"".join(re.findall(r'"((?:[^"\\]|\\.)*)"', found)) for found in LITERAL.findall(source)}


def test_the_script_is_valid_javascript_with_and_without_its_configuration(tmp_path):
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed (Debian package nodejs)")
    assets = calculator_assets()
    (tmp_path / "assembled.js").write_text(assets.js)
    for path in (STATIC, tmp_path / "assembled.js"):
        done = subprocess.run([node, "--check", str(path)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr


def test_every_word_of_the_script_is_listed_has_its_korean_and_nothing_closes_the_page_script():
    source = STATIC.read_text()
    assert script_templates(source) == {w.template for w in WORDS}
    ko = catalogue(Lang.KO)
    for phrase in WORDS:
        assert phrase.template in ko, phrase.template
        assert fields_of(ko[phrase.template]) == fields_of(phrase.template), phrase.template
        assert "{{" not in phrase.template and "}}" not in phrase.template
    assets = calculator_assets()
    for text in (assets.js, assets.html()):
        lowered = text.lower()
        assert lowered.count("</script") == (2 if text is not assets.js else 0) and "<!--" not in lowered
    assert re.fullmatch(r"[A-Za-z0-9+/]+=*", assets.wasm_b64)


# ------------------------------------------------------------------------------------------------ the browser
@pytest.fixture(scope="module")
def page(tmp_path_factory):
    """One headless page with the calculator, from a file:// URL; every other request is blocked and recorded."""
    folder = tmp_path_factory.mktemp("calculator")
    html = folder / "calculator.html"
    html.write_text(f"<!doctype html><html><head><meta charset='utf-8'>{calculator_assets().html()}</head></html>")
    blocked: list[str] = []

    def route(r):
        if r.request.url == html.as_uri():
            r.continue_()
        else:
            blocked.append(r.request.url)
            r.abort()

    with launched_chromium() as browser:
        context = browser.new_context()
        context.route("**/*", route)
        tab = context.new_page()
        errors: list[str] = []
        tab.on("pageerror", lambda exc: errors.append(str(exc)))
        tab.goto(html.as_uri())
        tab.wait_for_function("window.tpm !== undefined", timeout=30_000)
        yield tab
        assert errors == [] and blocked == [], (errors, blocked)
        context.close()


@pytest.mark.browser
def test_window_tpm_equals_the_app_on_10000_random_states_over_random_parameter_sets(page):
    cases = calc.random_cases(seed=39, sets=125, per=80)
    assert len(cases) == 10_000
    got = page.evaluate(calc.RUN_JS, cases)
    result = calc.compare(cases, got)
    print("worst relative errors", result["worst"], "refusals", result["refused"])
    assert result["problems"] == [], "\n".join(result["problems"][:20])
    # the cases exercise both outcomes of every function, and every kind of refusal
    assert all(500 < n < 9000 for n in result["refused"].values()), result["refused"]
    words = " ".join(answer["inverseDynamics"].get("error", "") for answer in got)
    for kind in ("parameters refused", "would leave its stroke", "inverse singularity", "direct singularity"):
        assert kind in words, kind
    assert "out of reach" in words and "must be finite" in words and "overflowed" in words
    accepted = len(cases) - result["refused"]["inverseDynamics"]
    doc = (Path(__file__).resolve().parents[3] / "docs" / "realtime.md").read_text()
    assert f"on the {accepted:,} accepted states" in doc, accepted  # docs/realtime.md quotes this run


def boundary_cases() -> list[dict]:
    """Poses on the edges of the app's rules: 0.5 nm and 2 nm past each stroke end (the app allows 1 nm),
    ``|p_j| = l_a`` to the last bit and one ulp beyond."""
    params = Params.paper()
    la, off = params.l_a, params.offset
    p2 = 0.01
    cases = []
    for end, outwards in ((0.0, -1.0), (params.stroke, 1.0)):
        for past in (2e-9, 0.5e-9, -0.5e-9):
            d1 = end + outwards * past
            p1 = d1 - off + math.sqrt(la * la - p2 * p2)  # eq. (4) solved for p_1
            cases.append({"params": {}, "p": [p1, p2], "dp": [0.1, 0.2], "ddp": [1.0, -1.0]})
    for edge in (la, math.nextafter(la, 1.0), math.nextafter(la, 0.0)):
        for p in ([edge, 0.05], [0.05, -edge], [-edge, edge]):
            cases.append({"params": {}, "p": p, "dp": [0.1, 0.2], "ddp": [1.0, -1.0]})
    return cases


@pytest.mark.browser
def test_the_edges_of_the_stroke_and_of_reach_are_where_the_app_puts_them(page):
    cases = boundary_cases()
    got = page.evaluate(calc.RUN_JS, cases)
    result = calc.compare(cases, got)
    assert result["problems"] == [], "\n".join(result["problems"])
    accepted = [("error" not in g["inverseKinematics"]) for g in got[:6]]
    assert accepted == [False, True, True] * 2  # 2 nm past an end refused, 0.5 nm allowed (the app's 1 nm)


GARBAGE_JS = """
async () => {
  const tpm = await window.tpmReady;
  const ok = {};
  const p = [0.01, 0.02], dp = [0.3, -0.2], ddp = [2, 1];
  const calls = [
    () => tpm.inverseDynamics(null, p, dp, ddp), () => tpm.inverseDynamics(5, p, dp, ddp),
    () => tpm.inverseDynamics("a=1", p, dp, ddp), () => tpm.inverseDynamics([1, 2], p, dp, ddp),
    () => tpm.inverseDynamics({a: {}}, p, dp, ddp), () => tpm.inverseDynamics({a: [0.5]}, p, dp, ddp),
    () => tpm.inverseDynamics({a: 10n}, p, dp, ddp), () => tpm.inverseDynamics(ok, "0.01,0.02", dp, ddp),
    () => tpm.inverseDynamics(ok, [0.01], dp, ddp), () => tpm.inverseDynamics(ok, [0.01, 0.02, 0.03], dp, ddp),
    () => tpm.inverseDynamics(ok, ["0.01", 0.02], dp, ddp), () => tpm.inverseDynamics(ok, {x: 0.01, y: 0.02}, dp, ddp),
    () => tpm.inverseDynamics(ok, p, undefined, ddp), () => tpm.inverseDynamics(ok, p, dp, null),
    () => tpm.inverseDynamics(ok, p, [true, 0], ddp), () => tpm.inverseKinematics(ok, [NaN, NaN]),
    () => tpm.evaluate(ok, [Infinity, 0]), () => tpm.evaluate(ok, p, [1e308, 1e308], [1e308, 1e308]),
    () => tpm.inverseKinematics(ok, [1e308, -1e308]), () => tpm.inverseKinematics({l_a: -0}, p),
  ];
  return calls.map((call) => {
    const r = call();
    const numbers = JSON.stringify(r, (k, v) => (typeof v === "number" && !Number.isFinite(v) ? "NOT FINITE" : v));
    return {r, numbers};
  });
}
"""


@pytest.mark.browser
def test_garbage_nan_and_1e308_are_refused_in_words_and_nothing_returned_is_nan(page):
    for answer in page.evaluate(GARBAGE_JS):
        assert set(answer["r"]) == {"error"}, answer
        assert isinstance(answer["r"]["error"], str) and len(answer["r"]["error"]) > 10
        assert "NOT FINITE" not in answer["numbers"]
    # the numeric ones word as the app does (NaN, inf, 1e308 as parameters, positions, motions)
    cases = []
    for bad in (math.nan, math.inf, -math.inf, 1e308, -1e308, -0.0):
        cases.append({"params": {"m_p": bad}, "p": [0.01, 0.02], "dp": [0.3, -0.2], "ddp": [2.0, 1.0]})
        cases.append({"params": {"a": bad}, "p": [0.01, 0.02], "dp": [0.3, -0.2], "ddp": [2.0, 1.0]})
        for k in ("p", "dp", "ddp"):
            case = {"params": {}, "p": [0.01, 0.02], "dp": [0.3, -0.2], "ddp": [2.0, 1.0]}
            case[k] = [bad, 0.5] if k == "p" else [bad, bad]
            cases.append(case)
    got = page.evaluate(calc.RUN_JS, cases)
    result = calc.compare(cases, got)
    assert result["problems"] == [], "\n".join(result["problems"])
    assert result["refused"]["inverseDynamics"] == len(cases) - 2  # only dp or ddp = (-0, -0) make a state


FORMAT_JS = (
    "async (cases) => { const tpm = await window.tpmReady; return cases.map(([x, spec]) => tpm.fixed(x, spec)); }"
)


@pytest.mark.browser
def test_numbers_are_written_as_the_app_writes_them(page):
    """``tpm.fixed`` (which every number in the words goes through) against :func:`tpm_viz.core.numbers.fixed`: halves
    that are exact in binary (round half to even), every magnitude, signs, zeros, non-finite values."""
    rng = np.random.default_rng(7)
    values = [0.0, -0.0, 0.5, 1.5, 2.5, -0.5, 0.125, 0.375, 2.675, 1e-5, 9.9999995e-5, 999999.5, 1e16, 5e-324]
    values += [math.nan, math.inf, -math.inf, 1e308, -1e-320, 0.0005, -0.0004, 123456.5, 0.1 + 0.2]
    values += (rng.choice([-1, 1], 400) * 10.0 ** rng.uniform(-12, 12, 400)).tolist()
    values += (np.round(rng.uniform(-1000, 1000, 200) * 8) / 8).tolist()  # binary halves, quarters, eighths
    cases = [[float(x), spec] for x in values for spec in (".0f", ".1f", ".3f", ".6g", ".2g", ".17g")]
    assert len(cases) == 3738  # as docs/realtime.md says
    got = page.evaluate(FORMAT_JS, cases)
    wrong = [(x, spec, g, fixed(x, spec)) for (x, spec), g in zip(cases, got, strict=True) if g != fixed(x, spec)]
    assert wrong == [], wrong[:10]
