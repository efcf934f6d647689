"""The page script is a real JavaScript file (``tpm_viz/viserkit/page.js``): node parses it, it builds no code or
markup from data, its one input from Python is JSON data in an element of its own (escaped for HTML, read back by
node's own ``JSON.parse``), and the page the app serves carries it exactly once, before ``</body>``, gzipped or not.
That it still works in a browser (keys, live region, labels, axe-core) is ``tests/e2e/test_browser_keyboard.py``."""

from __future__ import annotations

import gzip
import json
import pathlib
import re
import shutil
import subprocess
import tomllib
import urllib.request

import pytest

from tpm_viz.viserkit import page

ROOT = pathlib.Path(__file__).resolve().parents[2]
PAGE_JS = ROOT / "tpm_viz" / "viserkit" / "page.js"
NODE = shutil.which("node")
needs_node = pytest.mark.skipif(NODE is None, reason="node is not installed: the JavaScript syntax check needs it")


def _node(*args: str, stdin: str = "") -> str:
    assert NODE is not None
    done = subprocess.run([NODE, *args], input=stdin, capture_output=True, text=True, timeout=60)
    assert done.returncode == 0, done.stderr
    return done.stdout


@needs_node
def test_node_parses_the_page_script():
    _node("--check", str(PAGE_JS))


def test_the_module_serves_the_file_as_it_is():
    assert page.SCRIPT == PAGE_JS.read_text(encoding="utf-8")


def test_the_script_builds_no_code_and_no_markup_from_data():
    """No ``eval``, ``Function``, string timers or HTML sinks: everything it writes is ``textContent``, attributes or
    CSS text; a reviewer needs no linter to see that data never becomes code or markup."""
    code = re.sub(r"//[^\n]*", "", page.SCRIPT)  # comments may name what the code must not do
    sinks = r"\beval\s*\(|\bnew\s+Function\b|\bFunction\s*\(|innerHTML|outerHTML|insertAdjacentHTML|document\.write"
    assert re.findall(sinks, code) == []
    assert re.findall(r"\b(?:setTimeout|setInterval)\s*\(\s*[\"'`]", code) == []
    assert code.count('"use strict"') == 1


def test_the_script_reads_exactly_the_settings_python_sends():
    read = set(re.findall(r"\bCONFIG\.(\w+)", page.SCRIPT))
    read |= set(re.findall(r"\)\.(\w+);", page.SEEN_SCRIPT.split("JSON.parse(", 1)[1].split("\n", 1)[0]))  # seen.js
    assert read == set(page.CONFIG), (
        f"read but not sent: {read - set(page.CONFIG)}; sent, unread: {set(page.CONFIG) - read}"
    )
    assert page.CONFIG["keys"] == list(page.KEYS) and page.CONFIG["path"] == page.KEY_PATH


@needs_node
def test_the_settings_survive_any_text_and_cannot_end_their_element():
    hostile = {
        "path": "</script><script>alert(1)</script>",
        "keys": ["<!--", "-->", "a&b", "\u2028", "'\"\\"],
        "notice": "</SCRIPT >",
        "gap": 8,
    }
    text = page.config_json(hostile)
    assert "<" not in text and ">" not in text and "&" not in text
    assert (
        json.loads(
            _node(
                "-e",
                "let s='';process.stdin.on('data',d=>s+=d).on('end',()=>"
                "process.stdout.write(JSON.stringify(JSON.parse(s))))",
                stdin=text,
            )
        )
        == hostile
    )
    tag = page.page_tag(hostile, "void 0;").decode()
    assert tag.lower().count("</script") == 3  # the element's own end, the script's and seen.js's, nothing in between
    assert page.SEEN_SCRIPT in tag and "</script" not in page.SEEN_SCRIPT.lower()
    with pytest.raises(ValueError, match="</script"):
        page.page_tag(page.CONFIG, "const x = '</script>';")


def _served(port: int, encoding: str) -> bytes:
    request = urllib.request.Request(f"http://127.0.0.1:{port}/", headers={"Accept-Encoding": encoding})
    with urllib.request.urlopen(request, timeout=30) as response:
        body = response.read()
        assert response.status == 200 and int(response.headers["Content-Length"]) == len(body)
        return gzip.decompress(body) if response.headers.get("Content-Encoding") == "gzip" else body


@pytest.mark.parametrize("encoding", ["gzip", "identity"])
def test_the_served_page_carries_the_script_once_after_its_settings(app, encoding):
    for _ in range(2):  # the second answer comes from the cache of edited bodies: still once
        html = _served(app.port, encoding).decode()
        assert html.count(page.SCRIPT) == 1 and html.count('id="tpmviz-page-config"') == 1
        start = html.index('<script type="application/json" id="tpmviz-page-config">')
        data = html[start:].split(">", 1)[1].split("</script>", 1)[0]
        assert json.loads(data) == page.CONFIG
        assert start < html.index(page.SCRIPT) < html.rindex("</body>")


def test_the_wheel_ships_the_script():
    setuptools = tomllib.loads((ROOT / "pyproject.toml").read_text())["tool"]["setuptools"]
    patterns = setuptools["package-data"]["tpm_viz.viserkit"]
    assert any(PAGE_JS.match(pattern) for pattern in patterns)
