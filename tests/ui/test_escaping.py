"""One escaping layer for every HTML and Markdown element (``tpm_viz.core.markup``, applied by ``tpm_viz.ui.worded``).

- The layer itself, checked by independent parsers: text escaped for HTML parses (``html.parser``) to no element and
  the same text; text escaped for Markdown renders (markdown-it, CommonMark with raw HTML on, as viser's page) to one
  paragraph of the same text, no tag, link or image. Phrases keep their template's markup and escape their values.
- Every element a tab makes escapes what is not marked as the code's markup (a real viser server's handles).
- Every call site: each ``add_html`` / ``add_markdown`` / ``.content =`` of the package passes a literal, or markup
  built by the layer (its functions, a function annotated ``-> Html`` / ``-> Markdown``, a constant or a local
  variable made so), found by reading the source. A new call that passes a variable of unknown origin fails here.
"""

from __future__ import annotations

import ast
import functools
import html
import html.parser
import pathlib

import pytest
import viser
from hypothesis import example, given, settings
from hypothesis import strategies as st
from markdown_it import MarkdownIt

from tests.support.hypo import examples
from tpm_viz.core.markup import Html, Markdown, escape, markdown_text, say_html, say_markdown
from tpm_viz.core.markup import html as fill
from tpm_viz.core.words import Lang, Phrase, T
from tpm_viz.ui.worded import TabGui

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"

PAYLOADS = (
    "<iframe srcdoc=\"<script>parent.document.title='pwned'</script>\"></iframe>",
    '<img src=x onerror="window.__x=1">',
    "<svg onload=window.__x=1>",
    '<a href="javascript:window.__x=1">click</a>',
    "[click](javascript:window.__x=1)",
    "![x](http://127.0.0.2:9/x.png)",
    "<http://127.0.0.2:9/auto>",
    "www.example.com and http://127.0.0.2:9/y",
    "**bold** _it_ `code` # head\n- item\n    indented",
    "{0} {name} {{braces}} %s \\ & \"quotes\" 'single'",
)


# -- the layer, against independent parsers --------------------------------------------------------------------------
class _Parsed(html.parser.HTMLParser):
    def __init__(self) -> None:
        super().__init__(convert_charrefs=True)
        self.tags: list[str] = []
        self.text = ""

    def handle_starttag(self, tag, attrs) -> None:
        self.tags.append(tag)

    def handle_data(self, data) -> None:
        self.text += data


def _parse(markup: str) -> _Parsed:
    parsed = _Parsed()
    parsed.feed(markup)
    parsed.close()
    return parsed


@functools.cache
def _commonmark() -> MarkdownIt:
    return MarkdownIt("commonmark")  # raw HTML passed through, as react-markdown with rehype-raw in viser's page


@pytest.mark.parametrize("payload", PAYLOADS)
def test_text_escaped_for_html_is_no_element_and_the_same_text(payload):
    parsed = _parse(escape(payload))
    assert parsed.tags == [] and parsed.text == payload


@pytest.mark.parametrize("payload", PAYLOADS)
def test_text_escaped_for_markdown_renders_as_one_paragraph_of_the_same_text(payload):
    rendered = _commonmark().render(markdown_text(payload))
    parsed = _parse(rendered)
    assert parsed.tags == ["p"], rendered
    assert parsed.text.strip() == " ".join(payload.splitlines())


@given(st.text(max_size=200))
@settings(max_examples=examples(200))
@example("\t0")  # a leading tab (or four spaces) started a code block (found by this test under CI's counts)
@example("    indented")
def test_any_text_is_shown_literally_in_html_and_markdown(text):
    assert _parse(escape(text)).tags == [] and html.unescape(escape(text)) == text
    parsed = _parse(_commonmark().render(markdown_text(text)))
    assert set(parsed.tags) <= {"p"}  # nothing but the paragraph: no tag, link, image, emphasis, heading, list


def test_a_phrase_keeps_its_template_as_markup_and_escapes_its_values():
    payload = PAYLOADS[1]
    phrase = Phrase("<b>{name}</b> on {what}", name=payload, what=Phrase("the {x}", x="<i>"))
    shown = say_html(Lang.EN, phrase)
    assert isinstance(shown, Html) and _parse(shown).tags == ["b"]
    assert _parse(shown).text == f"{payload} on the <i>"
    korean = say_html(Lang.KO, Phrase("Previous run: {name}, peak {peak} N", name=payload, peak="1.0"))
    assert _parse(korean).tags == [] and payload in _parse(korean).text and "이전" in korean
    assert fill("<p>{a}{b:.2f}</p>", a=Html("<br>"), b=1.0) == "<p><br>1.00</p>"  # markup values kept
    assert escape(Html("<br>")) == "<br>" and Html("<b>") + "<i>" == "<b>&lt;i&gt;" and Html("<b>") + Html("<i>")
    md = say_markdown(Lang.EN, Phrase("**Refused**: {why}", why=PAYLOADS[4]))
    assert isinstance(md, Markdown) and _parse(_commonmark().render(md)).tags == ["p", "strong"]
    assert say_html(Lang.EN, ValueError(T("a <b> text"))) == "a <b> text"  # a phrase's template is the code's markup
    assert say_html(Lang.EN, ValueError("plain <b> text")) == "plain &lt;b&gt; text"  # any other text is text


# -- every element of a tab escapes what is not the code's markup ---------------------------------------------------
@pytest.fixture
def gui():
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    yield server.gui
    server.stop()


@pytest.mark.parametrize("lang", [Lang.EN, Lang.KO])
def test_every_element_escapes_unmarked_text(gui, lang):
    tab = TabGui(gui, lang)
    payload = PAYLOADS[0]
    as_html = tab.add_html(payload)
    assert as_html.handle.content == html.escape(payload) and _parse(as_html.handle.content).tags == []
    as_html.content = PAYLOADS[1]
    assert _parse(as_html.handle.content).text == PAYLOADS[1] and _parse(as_html.handle.content).tags == []
    as_html.content = Html("<b>ok</b>")
    assert as_html.handle.content == "<b>ok</b>"
    as_md = tab.add_markdown(PAYLOADS[5])
    rendered = _commonmark().render(as_md.handle.content)
    assert _parse(rendered).tags == ["p"] and "127.0.0.2" in rendered  # the text, no image
    as_md.content = PAYLOADS[4] + " " + PAYLOADS[2]
    assert _parse(_commonmark().render(as_md.handle.content)).tags == ["p"]
    as_md.content = Markdown("*fine*")
    assert as_md.handle.content == "*fine*"
    assert not as_md.handle.content.startswith("![")  # viser's server never reads an image path from user text


# -- every call site goes through the layer --------------------------------------------------------------------------
LAYER = {"Html", "Markdown", "escape", "html", "join", "say_html", "say_markdown", "markdown_text", "as_html"}
LAYER |= {"as_markdown"}
SINKS = {"add_html", "add_markdown"}
SKIP = {PACKAGE / "ui" / "worded.py"}  # the sinks themselves (they apply the layer to what they get)


@functools.cache
def _trees() -> dict[pathlib.Path, ast.Module]:
    return {p: ast.parse(p.read_text()) for p in sorted(PACKAGE.rglob("*.py"))}


@functools.cache
def _marked_functions() -> frozenset[str]:
    """Names of the package's functions and methods annotated to return Html or Markdown."""
    names = set()
    for tree in _trees().values():
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)) and isinstance(node.returns, ast.Name):
                if node.returns.id in ("Html", "Markdown"):
                    names.add(node.name)
    return frozenset(names)


@functools.cache
def _marked_constants() -> frozenset[str]:
    """Module-level names of the package assigned markup made by the layer (style sheets, the guide)."""
    names: set[str] = set()
    for _ in range(2):  # a constant made of another
        for tree in _trees().values():
            for node in tree.body:
                if isinstance(node, ast.Assign) and _marked(node.value, frozenset(names), {}):
                    names |= {t.id for t in node.targets if isinstance(t, ast.Name)}
    return frozenset(names)


def _name(func: ast.expr) -> str:
    return func.id if isinstance(func, ast.Name) else func.attr if isinstance(func, ast.Attribute) else ""


def _marked(node: ast.expr | None, constants: frozenset[str], local: dict[str, list[ast.expr]]) -> bool:
    """Whether ``node`` is markup made by the layer (see the module docstring)."""
    if node is None:
        return False
    if isinstance(node, ast.Call):
        name = _name(node.func)
        if name == "str" and len(node.args) == 1:  # a plain str of markup, for viser's own handles
            return _marked(node.args[0], constants, local)
        return name in LAYER or name in _marked_functions()
    if isinstance(node, ast.Name):
        if node.id in constants:
            return True
        values = local.get(node.id)
        return bool(values) and all(_marked(v, constants, {}) or _empty(v) for v in values)
    if isinstance(node, ast.Attribute):
        return node.attr in constants
    if isinstance(node, ast.IfExp):
        return all(_marked(b, constants, local) or _empty(b) for b in (node.body, node.orelse))
    if isinstance(node, ast.BinOp) and isinstance(node.op, ast.Add):  # Html + Html is Html
        return _marked(node.left, constants, local) and _marked(node.right, constants, local)
    return False


def _empty(node: ast.expr) -> bool:
    return isinstance(node, ast.Constant) and node.value == ""


def _plain_literal(node: ast.expr, sink: str) -> bool:
    """A literal with nothing a page would read as markup (it is shown as text)."""
    if not isinstance(node, ast.Constant) or not isinstance(node.value, str):
        return False
    special = "<&" if sink == "add_html" else "<&*_`[]!#\\"
    return not any(c in node.value for c in special)


def _call_sites():
    """``(where, sink, argument, local assignments)`` of every element content the package writes."""
    for path, tree in _trees().items():
        if path in SKIP:
            continue
        for func in [n for n in ast.walk(tree) if isinstance(n, (ast.FunctionDef, ast.AsyncFunctionDef))] + [tree]:
            local: dict[str, list[ast.expr]] = {}
            body = [func] if isinstance(func, ast.Module) else func.body
            for stmt in body:
                for node in ast.walk(stmt):
                    if isinstance(node, ast.Assign):
                        for target in node.targets:
                            if isinstance(target, ast.Name):
                                local.setdefault(target.id, []).append(node.value)
            for stmt in body:
                for node in ast.walk(stmt):
                    where = f"{path.relative_to(PACKAGE.parent)}:{getattr(node, 'lineno', 0)}"
                    if isinstance(node, ast.Call) and _name(node.func) in SINKS and node.args:
                        yield where, _name(node.func), node.args[0], local
                    elif isinstance(node, ast.Assign):
                        for target in node.targets:
                            if isinstance(target, ast.Attribute) and target.attr == "content":
                                yield where, "content", node.value, local


def test_every_element_content_goes_through_the_layer():
    constants = _marked_constants()
    sites = list(dict.fromkeys((w, s, ast.dump(a)) for w, s, a, _l in _call_sites()))
    assert len(sites) > 60  # the scan finds the call sites (a broken scan would pass everything)
    bad = sorted(
        {
            f"{where} {sink}: {ast.unparse(arg)[:90]}"
            for where, sink, arg, local in _call_sites()
            if not (_marked(arg, constants, local) or _plain_literal(arg, sink) or _empty(arg))
        }
    )
    assert not bad, "content not made by tpm_viz.core.markup (a literal, Html(...), escape(...), html(...)):\n" + (
        "\n".join(bad)
    )
