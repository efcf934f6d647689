"""The offline page's scripts (issue 39) without a browser: valid JavaScript (``node --check``), every phrase they
render listed with its Korean, Python's character classes as the grader receives them, and nothing that closes the
page's ``<script>``. The grading itself is checked in the page, against ``tpm-viz exercise grade``
(tests/ui/test_takehome.py).
"""

from __future__ import annotations

import json
import re
import shutil
import subprocess
import sys
import unicodedata
from pathlib import Path

import pytest

from tpm_viz.core.words import Lang, catalogue, fields_of
from tpm_viz.media import page_grader
from tpm_viz.media.page_grader import WORDS, grader_config, grader_script
from tpm_viz.media.page_html import PAGE_WORDS, SCRIPTS

MEDIA = Path(page_grader.__file__).parent
ALL_SCRIPTS = (page_grader.SCRIPT, *SCRIPTS)


def literals(source: str, call: str) -> set[str]:
    """The (concatenated) string literal that starts each ``call("...")`` of a script (``P``, ``W``)."""
    found = re.findall(rf'(?<![A-Za-z_]){call}\(\s*((?:"(?:[^"\\]|\\.)*"\s*\+?\s*)+)', source)
    return {json.loads('"' + "".join(re.findall(r'"((?:[^"\\]|\\.)*)"', f)) + '"') for f in found}


@pytest.mark.parametrize("name", ALL_SCRIPTS)
def test_each_script_is_valid_javascript(name, tmp_path):
    node = shutil.which("node")
    if node is None:
        pytest.skip("node is not installed (Debian package nodejs)")
    paths = [MEDIA / name]
    if name == page_grader.SCRIPT:  # and with its configuration written in, in both languages
        for lang in Lang:
            paths.append(tmp_path / f"grader-{lang.value}.js")
            paths[-1].write_text(grader_script(lang))
    for path in paths:
        done = subprocess.run([node, "--check", str(path)], capture_output=True, text=True, timeout=60)
        assert done.returncode == 0, done.stderr


def test_every_phrase_of_the_grader_is_listed_and_has_its_korean_with_the_same_fields():
    rendered = literals((MEDIA / page_grader.SCRIPT).read_text(), "P")
    rendered |= literals((MEDIA / "page_calc.js").read_text(), "tpmGrader.P")
    assert rendered == {w.template for w in WORDS}
    ko = catalogue(Lang.KO)
    config = grader_config(Lang.KO)
    for template in [w.template for w in WORDS] + list(config["quantities"].values()):
        assert template in ko, template
        assert fields_of(ko[template]) == fields_of(template), template
        assert config["ko"][template] == ko[template]
    assert grader_config(Lang.EN)["ko"] == {}


def test_every_template_the_page_scripts_fill_in_is_listed_and_has_its_korean():
    filled = set()
    for name in SCRIPTS:
        filled |= literals((MEDIA / name).read_text(), "W")
    assert filled == {w.template for w in PAGE_WORDS}
    ko = catalogue(Lang.KO)
    for phrase in PAGE_WORDS:
        assert fields_of(ko[phrase.template]) == fields_of(phrase.template), phrase.template


def test_the_character_classes_are_pythons_own():
    config = grader_config(Lang.EN)
    spaces, starts, digitish = config["spaces"], config["decimal_starts"], config["digitish"]
    assert set(spaces) == {chr(c) for c in range(sys.maxunicode + 1) if chr(c).isspace()}
    assert {"\u00a0", "\u2009", "\u3000", "\x1c", "\x85"} <= set(spaces) and "\ufeff" not in spaces
    decimals = {chr(s + k) for s in starts for k in range(10)}
    assert decimals == {chr(c) for c in range(sys.maxunicode + 1) if unicodedata.decimal(chr(c), -1) >= 0}
    assert {"٣", "３", "𝟓"} <= decimals and float("٣.５") == 3.5  # what float() reads, the grader reads
    assert {"²", "³", "①"} <= set(digitish) and not set(digitish) & decimals
    assert config["units"]["kn"] == ["force", 1000.0, 1.0] and config["si"]["angle"] == "rad"


@pytest.mark.parametrize("lang", list(Lang))
def test_no_inlined_script_can_close_the_page_script(lang):
    for text in (grader_script(lang), *((MEDIA / name).read_text() for name in SCRIPTS)):
        lowered = text.lower()
        assert "</script" not in lowered and "<!--" not in lowered
