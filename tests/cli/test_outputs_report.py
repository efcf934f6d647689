"""``tpm-viz report``: the HTML parsed back, its numbers against ``tpm-viz trajectory`` (closed form and Pinocchio),
its embedded CSV against ``tpm-viz trajectory``'s, in English and Korean, and opened in Chromium with the network
off (nothing fetched, printed to PDF)."""

from __future__ import annotations

import base64
import csv
import html.parser
import io
import os
import pathlib
import re
import urllib.parse

import numpy as np
import pytest

from tests.support.browser import CHROMIUM, CHROMIUM_ARGS
from tpm_viz.cli import main
from tpm_viz.core.words import Lang, catalogue

DATE = "2026-01-02"


class Report(html.parser.HTMLParser):
    """What a reader takes from the report: numbers by key, headings, links, the meta line, inline SVGs."""

    def __init__(self, text: str) -> None:
        super().__init__()
        self.values: dict[str, list[float]] = {}
        self.h2: list[str] = []
        self.links: dict[str, str] = {}
        self.meta: dict[str, str] = {}
        self.svgs = 0
        self.lang = ""
        self._key: str | None = None
        self._in_h2 = False
        self.feed(text)

    def handle_starttag(self, tag, attrs):
        a = dict(attrs)
        if tag == "html":
            self.lang = a.get("lang", "")
        if tag == "tr":
            self._key = a.get("data-key")
        if tag == "td" and "data-value" in a and self._key:
            self.values.setdefault(self._key, []).append(float(a["data-value"]))
        if tag == "h2":
            self._in_h2 = True
            self.h2.append("")
        if tag == "a" and "id" in a:
            self.links[a["id"]] = a["href"]
        if tag == "p" and a.get("id") == "meta":
            self.meta = a
        if tag == "svg":
            self.svgs += 1

    def handle_endtag(self, tag):
        if tag == "h2":
            self._in_h2 = False

    def handle_data(self, data):
        if self._in_h2:
            self.h2[-1] += data


def trajectory_csv(capsys, *extra: str) -> str:
    assert main(["trajectory", "--kind", "circle", "--samples", "401", *extra]) == 0
    return capsys.readouterr().out


def table(text: str) -> dict[str, list[str]]:
    rows = list(csv.DictReader(io.StringIO(text)))
    return {k: [r[k] for r in rows] for k in rows[0]}


def report(tmp_path: pathlib.Path, *extra: str) -> tuple[str, Report]:
    out = tmp_path / "report.html"
    assert main(["report", "--trajectory", "circle", "--output", str(out), "--date", DATE, *extra]) == 0
    text = out.read_text(encoding="utf-8")
    return text, Report(text)


@pytest.fixture(scope="module")
def english(tmp_path_factory):
    return report(tmp_path_factory.mktemp("report"))


def test_numbers_equal_the_command_lines(english, capsys):
    _, rep = english
    paper = {k: np.array(v, float) for k, v in table(trajectory_csv(capsys)).items() if k != "status"}
    pin = {
        k: np.array(v, float) for k, v in table(trajectory_csv(capsys, "--model", "pinocchio")).items() if k != "status"
    }
    tau = np.stack([paper["tau1"], paper["tau2"]], -1)
    tau_pin = np.stack([pin["tau1"], pin["tau2"]], -1)
    k = int(np.argmax(np.abs(tau).max(axis=1)))
    assert rep.values["peak"] == [pytest.approx(np.abs(tau).max(), rel=1e-12)]
    assert rep.values["peak"][0] == pytest.approx(177.1, abs=0.05)  # the circle at 0.5 s of docs/teaching.md
    assert rep.values["peak_t"] == [pytest.approx(paper["t"][k], abs=1e-15)]
    assert rep.values["peak_tau1"] == [pytest.approx(tau[k, 0], rel=1e-12)]
    assert rep.values["max_diff"] == [pytest.approx(np.abs(tau_pin - tau).max(), rel=1e-6, abs=1e-12)]
    assert 0 < rep.values["max_diff"][0] < 1e-9
    assert rep.values["a"] == [482.0] and rep.values["l_a"] == [260.0] and rep.values["m_p"] == [2.21]


def test_the_embedded_csv_is_the_trajectory_commands(english, capsys):
    _, rep = english
    href = rep.links["csv"]
    assert href.startswith("data:text/csv;charset=utf-8;base64,")
    embedded = table(base64.b64decode(href.split(",", 1)[1]).decode("utf-8"))
    reference = table(trajectory_csv(capsys))
    shared = set(embedded) & set(reference)
    assert shared >= {"t", "p1", "p2", "dp1", "ddp2", "d1", "dd2", "ddd1", "tau1", "tau2"}
    for name in shared:
        assert embedded[name] == reference[name], name
    assert len(embedded["t"]) == 401 and "tau1_pinocchio" in embedded


def test_self_contained_with_procedure_errata_version_and_date(english):
    text, rep = english
    assert rep.meta["data-date"] == DATE and rep.meta["data-version"] == "0.1.0"
    assert rep.svgs == 2 and "<math" in text and "(a) Inverse kinematics" in text and "Eq. (15)" in text
    assert rep.h2[:3] == ["Parameters", "The path", "Actuator forces"]
    bare = re.sub(r'xmlns(:\w+)?="[^"]*"', "", text)  # namespace names are not fetched
    for needle in ("http://", "https://", "<script", "<link", "src=", "url(http", "url(//", "@import"):
        assert needle not in bare, needle


def test_korean(tmp_path):
    _text, rep = report(tmp_path, "--lang", "ko", "--set", "l_a=0.27")
    ko = catalogue(Lang.KO)
    assert rep.lang == "ko"
    assert rep.h2[:3] == [ko["Parameters"], ko["The path"], ko["Actuator forces"]]
    assert rep.values["l_a"] == [270.0]


def test_a_report_of_your_own_csv(tmp_path):
    t = np.linspace(0.0, 0.4, 9)
    path = tmp_path / "path.csv"
    path.write_text("t,p1,p2\n" + "".join(f"{a},{0.05 * np.sin(5 * a)},{0.04 * a}\n" for a in t))
    out = tmp_path / "r.html"
    assert main(["report", "--trajectory", str(path), "--output", str(out), "--samples", "21"]) == 0
    rep = Report(out.read_text(encoding="utf-8"))
    assert len(base64.b64decode(rep.links["csv"].split(",", 1)[1]).decode().splitlines()) == 22


@pytest.mark.parametrize(
    ("extra", "message"),
    [(["--output", "r.pdf"], "--output must end in .html or .htm"), (["--output", "r.html", "--date", "x"], "--date")],
)
def test_bad_input_is_one_line(tmp_path, capsys, monkeypatch, extra, message):
    monkeypatch.chdir(tmp_path)
    assert main(["report", "--trajectory", "line", *extra]) == 2
    err = capsys.readouterr().err
    assert message in err and err.count("\n") == 1 and not list(tmp_path.iterdir())


@pytest.mark.browser
def test_it_opens_offline_in_chromium_and_prints(english, tmp_path):
    if not os.path.exists(CHROMIUM):
        pytest.skip(f"{CHROMIUM} is not installed")
    sync_api = pytest.importorskip("playwright.sync_api")
    text, _ = english
    path = tmp_path / "report.html"
    path.write_text(text, encoding="utf-8")
    requested: list[str] = []
    with sync_api.sync_playwright() as pw:
        browser = pw.chromium.launch(executable_path=CHROMIUM, args=CHROMIUM_ARGS, headless=True)
        try:
            context = browser.new_context(offline=True)
            page = context.new_page()
            page.on("request", lambda r: requested.append(r.url))
            page.goto(path.as_uri())
            assert page.locator("h1").inner_text().startswith("Lab report: circle")
            sizes = page.evaluate(
                "[...document.querySelectorAll('figure svg')].map(s => s.getBoundingClientRect().width)"
            )
            assert len(sizes) == 2 and min(sizes) > 200
            assert page.locator("math").count() >= 5
            href = page.locator("a#csv").get_attribute("href")
            assert page.evaluate("h => fetch(h).then(r => r.text())", href).startswith("t,")
            pdf = page.pdf(format="A4")
            assert pdf.startswith(b"%PDF") and len(pdf) > 20_000
        finally:
            browser.close()
    fetched = [u for u in requested if urllib.parse.urlsplit(u).scheme not in ("file", "data")]
    assert fetched == []
