"""The Korean catalogue (``assets/words/ko.toml``) against the words the app really uses, read two ways:

- from the source, as ``xgettext`` does: the literal first argument of every ``Phrase("...")`` and ``T("...")``,
  the template of every ``say(lang, "...")``, and the literal text given to a method that shows it to a tab
  (``view.tell("...")``, ``view.refuse("...")``, ``set_class_info``, the login's ``show``), or a module constant
  named there;
- from the wire: what two real tabs are sent when they open (in classroom mode: the presenter's, with the
  *Lecturer* folder, and a student's, with the login folder): every label, hint, option, tab name, chart title and
  series label, the text each markdown element is created with and every text between two tags of the HTML it is
  created with (style rules aside), and the names of the tabs, as they arrive in the websocket messages. Texts
  written later (numbers, states) are the producers' ``Phrase`` s, found in the source.

Then: every one of them has a Korean entry (a); each entry keeps exactly the ``{fields}`` of its English key (b);
every entry is used by one of the two routes or is the title of a packaged lesson (c); every entry renders with
values for its fields without an error (d); and each packaged lesson has its Korean paragraph.
"""

from __future__ import annotations

import ast
import html
import re
import time
import tomllib
from pathlib import Path

import msgspec
import pytest
import viser
from websockets.sync.client import connect as connect_sync

from tests.support.pages import classroom_app
from tests.support.protocol import CAMERA, decode_batch
from tpm_viz.app.lessons import DEMOS
from tpm_viz.core.words import Lang, Phrase, catalogue, fields_of

pytestmark = pytest.mark.slow  # the one-minute loop (-m "not slow") leaves this file out

__all__ = ["classroom_app"]  # the fixture, imported

ROOT = Path(__file__).resolve().parents[2]
CATALOGUE = ROOT / "assets" / "words" / "ko.toml"
SINKS = {"tell", "refuse", "set_class_info", "show"}
"""Methods whose literal text reaches a tab's page: ClientView's (rendered with ``say``) and the login's status line
(a whole markdown text, shown in the tab's language on the way out)."""
LANGUAGE_NAMES = {lang.label for lang in Lang}
"""Shown in their own language, never translated (the options of the language selector)."""
WORD = re.compile(r"[A-Za-z]{2,}")
TEXT_NODE = re.compile(r">([^<>]+)<")
STYLE = re.compile(r"<style>.*?</style>", re.S)
HANGUL = re.compile("[\uac00-\ud7a3]")
LIVE = re.compile(r"<math\b|\bdata-q=")
"""HTML with numbers (``data-q`` values, MathML): viser sends an element's creation with the content written last
(the first frame's readouts), rendered by its producer from the phrases of the source route; of its texts only the
whole phrases of the catalogue count as used on the wire (static tables of numbers are translated text by text)."""


def _literal(node: ast.AST | None, constants: dict[str, str]) -> str | None:
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return node.value
    if isinstance(node, ast.Name):
        return constants.get(node.id)
    return None


def source_templates() -> dict[str, str]:
    """Every template written in the package's source -> where (``path:line``)."""
    found: dict[str, str] = {}
    for path in sorted((ROOT / "tpm_viz").rglob("*.py")):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        constants = {
            target.id: node.value.value
            for node in tree.body
            if isinstance(node, ast.Assign)
            and isinstance(node.value, ast.Constant)
            and isinstance(node.value.value, str)
            for target in node.targets
            if isinstance(target, ast.Name)
        }
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            name = func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""
            arg = None
            if name in ("Phrase", "T") and node.args:
                arg = node.args[0]
            elif name == "say" and len(node.args) >= 2:
                arg = node.args[1]
            elif name in SINKS and isinstance(func, ast.Attribute) and node.args:
                arg = node.args[0]
            text = _literal(arg, constants)
            if text and WORD.search(text):
                found.setdefault(text, f"{path.relative_to(ROOT)}:{node.lineno}")
    return found


def _texts_of(message: dict) -> list[str]:
    """The words of one GUI element as the wire carries them."""
    props = message.get("props")
    if not isinstance(props, dict):
        return []
    out: list[str] = []
    for name in ("label", "hint", "title", "_markdown"):
        if isinstance(props.get(name), str):
            out.append(props[name])
    for name in ("options", "_tab_labels"):
        out += [v for v in props.get(name) or () if isinstance(v, str)]
    for name in ("series", "axes"):
        out += [v["label"] for v in props.get(name) or () if isinstance(v, dict) and isinstance(v.get("label"), str)]
    if isinstance(props.get("content"), str):
        markup = STYLE.sub("", props["content"])
        out += [html.unescape(t).strip() for t in TEXT_NODE.findall(markup)]
    return out


def wire_texts(port: int, seconds: float = 4.0) -> set[str]:
    """The words of every GUI element a new tab of the app on ``port`` is sent in its first ``seconds``."""
    seen: set[str] = set()
    messages: list[dict] = []  # in order, across frames: a window of 128 may end between an element and its content
    ws = connect_sync(
        f"ws://127.0.0.1:{port}", subprotocols=[f"viser-v{viser.__version__}"], max_size=None, compression=None
    )
    try:
        ws.send(msgspec.msgpack.encode(CAMERA))
        deadline = time.monotonic() + seconds
        while time.monotonic() < deadline:
            try:
                raw = ws.recv(timeout=0.2)
            except TimeoutError:
                continue
            messages.extend(decode_batch(raw))
    finally:
        ws.close()
    for message, after in zip(messages, [*messages[1:], {}], strict=True):
        if message["type"].startswith("Gui") and message["type"] != "GuiUpdateMessage":
            props = message.get("props")
            if isinstance(props, dict) and LIVE.search(str(props.get("content", ""))):
                texts = _texts_of(message)
                message = {**message, "props": {k: v for k, v in props.items() if k != "content"}}
                seen.update(set(texts) & set(catalogue(Lang.KO)))
            seen.update(_texts_of(message))
            if after.get("type") == "GuiUpdateMessage" and after.get("uuid") == message.get("uuid"):
                seen.update(_texts_of({"props": after.get("updates")}))  # add_markdown's own content
        elif message["type"] == "GuiUpdateMessage" and "_tab_labels" in (message.get("updates") or {}):
            seen.update(_texts_of({"props": {"_tab_labels": message["updates"]["_tab_labels"]}}))  # add_tab
    return seen


def needs_words(text: str) -> bool:
    """A text a Korean reader should see in Korean: it has words, and it is not a language's own name, an address
    or a lesson's own paragraph (those have their Korean in the lesson file)."""
    paragraphs = {d.text for d in DEMOS}
    return (
        bool(WORD.search(text))
        and text not in LANGUAGE_NAMES
        and text not in paragraphs
        and not text.startswith(("http://", "https://"))
    )


@pytest.fixture(scope="module")
def korean() -> dict[str, str]:
    with CATALOGUE.open("rb") as f:
        return tomllib.load(f)


@pytest.fixture
def used(classroom_app) -> set[str]:
    """Every template of the source and every word a presenter's and a student's tab are sent."""
    sent = wire_texts(classroom_app.port) | wire_texts(classroom_app.port)  # the first tab is the presenter
    return set(source_templates()) | {t for t in sent if needs_words(t)}


def test_every_word_of_the_app_has_korean(used, korean):
    missing = sorted(used - set(korean))
    where = source_templates()
    assert not missing, f"{len(missing)} without Korean (assets/words/ko.toml):\n" + "\n".join(
        f"  {where.get(t, 'sent to a tab')}: {t!r}" for t in missing[:80]
    )


def test_each_korean_entry_keeps_the_fields_of_its_english(korean):
    wrong = {k: v for k, v in korean.items() if fields_of(k) != fields_of(v)}
    assert not wrong, wrong


def test_no_entry_is_stale(used, korean):
    titles = {d.title for d in DEMOS}
    stale = sorted(set(korean) - used - titles)
    assert not stale, f"{len(stale)} entries no code uses: {stale[:40]}"


def test_every_entry_renders_in_both_languages(korean):
    assert catalogue(Lang.KO) == korean  # the app reads the same file
    for key in korean:
        values = {name: 1.5 for name in fields_of(key)}
        english, hangul = Phrase(key, **values).render(Lang.EN), Phrase(key, **values).render(Lang.KO)
        assert english == key.format(**values)
        assert hangul == korean[key].format(**values) and hangul.strip()
        assert HANGUL.search(hangul) or korean[key] == key, f"{key!r}: not Korean"  # or the same in both (PD)


def test_every_packaged_lesson_has_its_korean_paragraph_with_the_same_numbers():
    for demo in DEMOS:
        ko = demo.text_in("ko")
        assert ko != demo.text and HANGUL.search(ko), demo.title
        numbers = sorted(re.findall(r"\d+(?:\.\d+)?", demo.text))
        assert sorted(re.findall(r"\d+(?:\.\d+)?", ko)) == numbers, demo.title
        assert fields_of(ko) == fields_of(demo.text), demo.title


def test_the_language_names_are_not_in_the_catalogue(korean):
    assert not LANGUAGE_NAMES & set(korean)  # each language's name is shown in that language, in every tab
