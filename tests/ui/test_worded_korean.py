"""A tab in Korean reads Korean everywhere (issue 25): every text of every GUI element a Korean tab holds, as the
tab received it over the websocket (label, hint, markdown, HTML content, options, tab names, chart titles and series
labels), with the Equations tab at a regular pose, after a control-lab lesson (its summary, table and lesson) and a
planner run (its result and sizing table), has no English sentence left.

What is allowed: symbols (``det J_x``, ``ω_n``, ``K_p``), units (mm, N, Hz, µm, rad/s), numbers, equation and figure
references, and a short list of proper names and acronyms (:data:`NAMES`). What is not: three or more English words
in a row (:func:`english_runs`), the test's own definition, independent of the catalogue.
"""

from __future__ import annotations

import html
import re

import pytest

from tests.support.protocol import ProtocolClient, wait_for
from tpm_viz.app.overlays import MAP_KINDS
from tpm_viz.app.run_names import label_words, reference_words
from tpm_viz.app.runs import Source, build_run
from tpm_viz.core.params import Params
from tpm_viz.core.words import Lang, T, catalogue, say
from tpm_viz.media.report import report_html
from tpm_viz.ui.language import show_text
from tpm_viz.viserkit.probe import widget_uuid

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

HANGUL = re.compile("[\uac00-\ud7a3]")
NAMES = {
    # proper names, products, libraries, file formats, acronyms, keys of the keyboard
    "pinocchio", "adams", "mujoco", "toppra", "viser", "csv", "png", "svg", "pdf", "html", "json", "toml", "mjcf",
    "urdf", "tpm", "viz", "pham", "kim", "kaist", "ppa", "abb", "irb", "flexpicker", "scara", "rms", "pd", "ctc",
    "id", "ok", "url", "http", "https", "utf", "readme", "tpm-viz", "english", "enter", "shift", "esc", "ctrl",
    "webgl", "gpu",
    # units
    "mm", "hz", "khz", "kg", "rad", "deg", "µm", "mib", "kib", "ms",
    # mathematical symbols and functions
    "sin", "cos", "tan", "atan", "diag", "det", "cond", "max", "min", "log", "exp", "sqrt", "ref", "ext", "eq",
    "eqs", "fig", "figs", "dt", "nan", "inf",
}  # fmt: skip
"""Latin words a Korean text may keep (lower case)."""
WORD = r"[A-Za-z][A-Za-z'’-]*[A-Za-z]"
RUN = re.compile(rf"{WORD}(?:[\s,;:()“”\"/]+{WORD}){{2,}}")
"""Three or more Latin words (of two letters or more) in a row, only spaces and light punctuation between them."""


class TextClient(ProtocolClient):
    """A protocol tab that also keeps the text properties of every GUI element it holds (uuid -> props), the
    creation's and every later update's, as they arrive."""

    def __init__(self, port: int) -> None:
        self.gui: dict[str, dict] = {}
        super().__init__(port)

    def take(self, m: dict, now: float) -> None:
        kind = m["type"]
        if kind == "GuiRemoveMessage":
            self.gui.pop(m.get("uuid"), None)
        elif kind == "GuiUpdateMessage":
            if m.get("uuid") in self.gui and isinstance(m.get("updates"), dict):
                self.gui[m["uuid"]].update(m["updates"])
        elif kind.startswith("Gui") and isinstance(m.get("props"), dict) and "uuid" in m:
            self.gui[m["uuid"]] = dict(m["props"])
        super().take(m, now)

    def holds(self, handle) -> bool:
        """The tab shows the content the server last wrote to ``handle`` (an HTML or markdown element)."""
        shown = show_text(Lang.KO, "content", handle.content)  # as a Korean tab is sent it
        return self.gui.get(widget_uuid(handle), {}).get("content") == shown

    def texts(self) -> list[str]:
        """Every text of every element the tab holds now."""
        out: list[str] = []
        for props in list(self.gui.values()):
            for name in ("label", "hint", "title", "_markdown", "content"):
                if isinstance(props.get(name), str):
                    out.append(props[name])
            for name in ("options", "_tab_labels"):
                out += [v for v in props.get(name) or () if isinstance(v, str)]
            for name in ("series", "axes"):
                out += [
                    v["label"] for v in props.get(name) or () if isinstance(v, dict) and isinstance(v.get("label"), str)
                ]
        return out


def plain(text: str) -> str:
    """The words of a text: no style or script, no tags, entities decoded, no ``data-q`` names."""
    text = re.sub(r"<(style|script)\b.*?</\1>", " ", text, flags=re.S | re.I)
    text = re.sub(r"<math\b.*?</math>", " ", text, flags=re.S | re.I)  # MathML: symbols and numbers only
    text = re.sub(r"<[^>]+>", " ", text)
    return html.unescape(text)


def english_runs(text: str) -> list[str]:
    """The runs of three or more English words in ``text`` once symbols, units, numbers, equation references and
    :data:`NAMES` are taken out; in a text with Korean words, every English word of three letters or more left."""
    words = plain(text)
    words = re.sub(r"\b(?:eqs?|Eqs?|Fig|Figs|Table|Tables|Section|Sections)\.?\s*\(?[\d\s,()–-]+\)?", " ", words)
    words = re.sub(r"\b[A-Za-z]+_[A-Za-z0-9]+\b", " ", words)  # symbols: ω_n, K_p, J_x, f_ext, l_a
    # file names and docs pages (a Korean particle may follow: "docs/model.md와")
    words = re.sub(r"[\w./-]+\.(?:csv|json|png|svg|html|toml|xml|urdf|md)(?![A-Za-z0-9])", " ", words, flags=re.I)
    words = re.sub(r"https?://\S+", " ", words)
    words = re.sub(r"\{\w+\}", " ", words)  # a template's field, filled by the page script (a panel's name)
    kept = re.sub(WORD, lambda m: " " if m.group(0).lower() in NAMES else m.group(0), words)
    runs = RUN.findall(kept)
    if HANGUL.search(kept):  # a Korean sentence: no English word at all (of three letters or more)
        runs += [w for w in re.findall(WORD, kept) if len(w) >= 3 and not any(w in run for run in runs)]
    return runs


def test_the_rule_finds_english_and_spares_symbols_units_and_names():
    assert english_runs("<p><b>(a) Inverse kinematics, eq. (4).</b> Each slider sits behind</p>")
    assert english_runs("<b>PD</b>: line 추종, 0.200 s, 1000 Hz")  # a Korean sentence with an English word
    assert not english_runs("<b>PD</b> 직선, 0.200 s, 1000 Hz, det J_x = cos(θ1 + θ2), ω_n = 10 Hz, RMS 3.2 µm")
    assert not english_runs("Pinocchio, ADAMS, MuJoCo (MJCF), URDF, CSV, PNG, SVG: eqs. (28)-(29), 그림 4")


def test_a_korean_tab_has_no_english_sentence_on_any_tab(app):
    client = TextClient(app.port)
    try:
        view = wait_for(lambda: next(iter(app.views.values()), None), what="the app to build the tab's view")
        equations = lambda: view.panel.equations is not None and view.panel.equations.content  # noqa: E731
        wait_for(lambda: view.session.readout is not None and equations(), what="the first render")
        view.words.set(Lang.KO)
        cv, pv, pl = view.teaching.control, view.teaching.planner, view.teaching.player
        player = view.teaching.services.runs
        ko = catalogue(Lang.KO)  # the page shows, and sends back, the options in Korean
        client.set_value(pl.choice, ko["line (Fig. 4)"])  # the player's summary: the paper's line, its peak force
        wait_for(lambda: (r := player.of(view.session).run) is not None and r.source.kind == "line", what="the line")
        client.set_value(pl.controls, ko["Pause"])  # a summary that stays still
        wait_for(lambda: not player.of(view.session).playing, what="the pause")
        client.click(cv.lesson)  # the three controllers on the line: run summary, table and lesson
        wait_for(
            lambda: len(cv.table) == 3 and not cv.busy and cv.lesson_text.content and "run-rms" in cv.summary.content,
            timeout=60,
            what="the control lesson",
        )
        wait_for(lambda: pv.result is not None and pv.sizing.content, timeout=60, what="the first plan")
        shown = (pl.summary, cv.summary, cv.table_html, cv.lesson_text, pv.result_html, pv.sizing)
        wait_for(lambda: all(client.holds(handle) for handle in (*shown, view.panel.equations)), what="the texts")
        line = view.panel.class_info  # the classroom line: written again for the new language (coalesced, a moment)
        held = lambda: client.gui.get(widget_uuid(line), {}).get("content") or ""  # noqa: E731  (its HTML)
        wait_for(lambda: HANGUL.search(line.content) and held() == line.content, what="the classroom line in Korean")
        texts = client.texts()
        equations = client.gui[widget_uuid(view.panel.equations)]["content"]
        assert "<math" in equations and HANGUL.search(plain(equations))  # the procedure, in Korean
        for kind in MAP_KINDS:  # every floor map's legend (the Maps tab)
            with view.hub.lock:
                view.teaching.explorer.set(kind=kind)
            wait_for(lambda: client.holds(view.teaching.explorer.legend), what=f"the legend of {kind}")
            texts += client.texts()
        found = {}
        for text in texts:
            runs = english_runs(text)
            if runs:
                found[plain(text).strip()[:160]] = runs
        assert HANGUL.search(" ".join(client.texts()))
        assert not found, f"{len(found)} texts with English in a Korean tab:\n" + "\n".join(
            f"  {runs} in {text!r}" for text, runs in found.items()
        )
    finally:
        count = len(app.views)
        client.close()
        wait_for(lambda: len(app.views) < count, what="the app to drop the closed tab")


def test_the_korean_lab_report_has_no_english_sentence():
    """``tpm-viz report --lang ko``: the procedure (a)-(e), the errata, the parameters' descriptions and the path's
    name in Korean (the same phrases as the Equations tab); the English report keeps its English words."""
    run = build_run(Params.paper(), Source.paper("line"), samples=41)
    korean = report_html(run, Lang.KO)
    procedure = re.search(r'<section id="procedure".*?</section>', korean, re.S)
    assert procedure and "<math" in procedure.group(0) and HANGUL.search(plain(procedure.group(0)))
    words = re.sub(r"<svg\b.*?</svg>", " ", korean, flags=re.S)  # the force plot: matplotlib has no Hangul font
    words = re.sub(r'(<tr data-key="\w+">)<td>\w+</td>', r"\1", words)  # the parameters' names (--set a=...)
    assert english_runs(words) == []
    english = report_html(run, Lang.EN)
    for text in ("(a) Inverse kinematics", "Errata confirmed numerically", "line (Fig. 4), T = 0.2 s: 41 samples"):
        assert text in english


def test_the_papers_paths_are_named_in_the_readers_language_and_files_as_they_are():
    for source in (Source.paper("line"), Source.paper("circle", 0.75)):
        words = label_words(source.label)
        assert say(Lang.EN, words) == source.label  # the English text unchanged
        korean = say(Lang.KO, words)
        assert HANGUL.search(korean) and korean.endswith(f", T = {source.duration:g} s") and "Fig" not in korean
    assert say(Lang.KO, reference_words("circle")) == say(Lang.KO, T("circle (Fig. 5)")) != "circle (Fig. 5)"
    for name in ("line (Fig. 4).csv, T = 1 s", "{x}.csv, T = 2 s"):  # a file's name, braces included
        assert say(Lang.KO, label_words(name)) == name
    assert say(Lang.KO, reference_words("wave.csv")) == "wave.csv"
