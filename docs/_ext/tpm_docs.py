"""tpm-viz's own Sphinx extension: cross-references resolved the way the docstrings are written, and the examples'
pages generated from ``examples/``.

**References.** The docstrings of ``tpm_viz`` name things the way a reader looks them up (checked by
``tests/system/test_docrefs.py``): from the module or class that holds the docstring, then its package and the
packages above it, then ``tpm_viz`` (``:func:`inverse_kinematics``` in :mod:`tpm_viz.paper.dynamics` is the one its
package re-exports); a leading dot searches by suffix (``:mod:`.text``` in a package is its own ``text``). Sphinx looks
in the current module and then anywhere, which finds several ``text`` modules or none. :class:`CanonicalReferences`
runs before Sphinx's resolver and rewrites each Python reference to the full name of the object it names, where
autodoc documented it (``tpm_viz.paper.kinematics.inverse_kinematics``). A name that exists but has no page of its
own (a private helper, a type variable, a dataclass field, and every name of another project: numpy, viser, the
standard library, for which there is no inventory offline) is shown as code without a link; a name that does not
exist is left to Sphinx, which warns (the build runs with ``nitpicky`` and ``-W``).

**Examples.** Each ``examples/NN_group/NN_name.py`` becomes ``docs/examples/NN_group/NN_name.md``: its docstring
(Markdown) as the page's text, the code below it; ``docs/examples/index.md`` lists them by group. The files are
written when the build starts (only when their text changes) into a folder git ignores.
"""

from __future__ import annotations

import ast
import builtins
import functools
import importlib
import inspect
import pathlib
import re
import sys
from collections.abc import Iterator
from typing import Any

from docutils import nodes
from sphinx.addnodes import pending_xref
from sphinx.application import Sphinx
from sphinx.transforms.post_transforms import SphinxPostTransform
from sphinx.util.docutils import SphinxDirective
from sphinx.util.nodes import find_pending_xref_condition

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
MISSING = object()
PACKAGE = "tpm_viz"
ALIASES = {"np": "numpy", "npt": "numpy.typing"}
"""The import aliases the package's annotations use."""


# --------------------------------------------------------------------------------------------------------------------
# references


@functools.cache
def lookup(dotted: str) -> Any:
    """The object an absolute dotted name names (modules imported as needed), or :data:`MISSING`."""
    parts = dotted.split(".")
    if not all(p.isidentifier() for p in parts):
        return MISSING
    for cut in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        except Exception:  # a module that fails to import names nothing
            return MISSING
        for attr in parts[cut:]:
            owner, obj = obj, getattr(obj, attr, MISSING)
            if obj is MISSING:
                return _FIELD if attr in _annotations(owner) else MISSING
        return obj
    return MISSING


_FIELD = object()
"""A dataclass field or annotated attribute without a class-level value: it exists, with no object of its own."""


@functools.cache
def _annotations(owner: Any) -> frozenset[str]:
    names: set[str] = set()
    for klass in getattr(owner, "__mro__", ()):
        names |= set(getattr(klass, "__annotations__", {})) | set(getattr(klass, "__slots__", ()))
    if isinstance(owner, type):
        for klass in owner.__mro__:  # instance attributes a method assigns (self.name = ...)
            try:
                names |= set(re.findall(r"\bself\.([A-Za-z_]\w*)\s*(?::[^=\n]+)?=[^=]", inspect.getsource(klass)))
            except (OSError, TypeError):
                pass
    return frozenset(names)


def _parents(module: str) -> list[str]:
    parts = module.split(".")
    return [".".join(parts[:cut]) for cut in range(len(parts), 0, -1)]


def candidates(target: str, module: str | None, cls: str | None, suffix_search: bool) -> Iterator[str]:
    """Absolute names ``target`` may mean, in the order a reader tries them (lazily: the first that exists wins)."""
    if module and cls:
        yield f"{module}.{cls}.{target}"
    if module:
        yield from (f"{p}.{target}" for p in _parents(module))
    if not suffix_search:
        yield target
        head, _, rest = target.partition(".")
        if head in ALIASES and rest:  # an annotation written with the module's alias: np.ndarray
            yield f"{ALIASES[head]}.{rest}"
    yield f"{PACKAGE}.{target}"
    if module and "." not in target:  # a module docstring's :meth:`update`: a member of one of its classes
        owner = lookup(module)
        for name, value in sorted(vars(owner).items()) if owner is not MISSING else ():
            if isinstance(value, type) and value.__module__ == module:
                if hasattr(value, target) or target in _annotations(value):
                    yield f"{module}.{name}.{target}"


def _common(a: str, b: str) -> int:
    n = 0
    for x, y in zip(a.split("."), b.split("."), strict=False):
        if x != y:
            break
        n += 1
    return n


class CanonicalReferences(SphinxPostTransform):
    """Every ``py`` reference rewritten to the documented full name of what it names (module docstring)."""

    default_priority = 5  # before Sphinx's ReferencesResolver (10)

    def run(self, **kwargs: Any) -> None:
        domain = self.env.get_domain("py")
        objects: dict[str, Any] = domain.objects  # type: ignore[attr-defined]
        by_last: dict[str, list[str]] = {}
        for name in objects:
            by_last.setdefault(name.rsplit(".", 1)[-1], []).append(name)
        for node in list(self.document.findall(pending_xref)):
            if node.get("refdomain") != "py":
                continue
            target = re.sub(r"\s+", "", node["reftarget"])  # a role may wrap a line
            module, cls = node.get("py:module"), node.get("py:class")
            suffix = bool(node.get("refspecific"))
            name = self._documented(target, module, cls, suffix, objects, by_last)
            if name is not None:
                node["reftarget"] = name
                if "refspecific" in node:  # an exact name now: Sphinx's exact search (any role finds it)
                    del node["refspecific"]
            elif self._exists(target, module, cls, suffix):
                shown = find_pending_xref_condition(node, "*")  # a signature's type: its short form
                node.replace_self((shown or node).children or nodes.literal(target, target))

    @staticmethod
    def _exists(target: str, module: str | None, cls: str | None, suffix: bool) -> bool:
        target = re.split(r"[\[,]", target)[0]  # an annotation Sphinx could not parse: dict[str, ... -> dict
        if hasattr(builtins, target) or target in ("None", "True", "False"):
            return True
        return any(lookup(c) is not MISSING for c in candidates(target, module, cls, suffix)) or (
            suffix and any(lookup(f"{m}.{target}") is not MISSING for m in _loaded_modules())
        )

    @staticmethod
    def _documented(
        target: str,
        module: str | None,
        cls: str | None,
        suffix: bool,
        objects: dict[str, Any],
        by_last: dict[str, list[str]],
    ) -> str | None:
        for name in candidates(target, module, cls, suffix):
            if name in objects:
                return name
            obj = lookup(name)
            if obj is MISSING or obj is _FIELD:
                continue
            return _where_documented(obj, name, objects, by_last)
        if suffix:  # Sphinx's suffix search, the nearest match first
            last = target.rsplit(".", 1)[-1]
            matches = [n for n in by_last.get(last, []) if n.endswith("." + target)]
            if matches:
                return max(matches, key=lambda n: (_common(n, module or ""), -len(n)))
        return None


def _where_documented(obj: Any, name: str, objects: dict[str, Any], by_last: dict[str, list[str]]) -> str | None:
    """The documented full name of ``obj``, found as ``name`` (a re-export, an alias), or None."""
    if inspect.ismodule(obj):
        return obj.__name__ if obj.__name__ in objects else None
    module, qualname = getattr(obj, "__module__", None), getattr(obj, "__qualname__", None)
    if isinstance(module, str) and isinstance(qualname, str) and f"{module}.{qualname}" in objects:
        return f"{module}.{qualname}"
    for other in by_last.get(name.rsplit(".", 1)[-1], []):
        if other.startswith(PACKAGE + ".") and lookup(other) is obj:
            return other
    return None


@functools.cache
def _loaded_modules() -> tuple[str, ...]:
    return tuple(m for m in sys.modules if m == PACKAGE or m.startswith(PACKAGE + "."))


# --------------------------------------------------------------------------------------------------------------------
# signatures

ARRAY_LIKE = (
    "~numpy._typing._array_like._Buffer | ~numpy._typing._array_like._SupportsArray[~numpy.dtype[~typing.Any]] | "
    "~numpy._typing._nested_sequence._NestedSequence[~numpy._typing._array_like._SupportsArray[~numpy.dtype["
    "~typing.Any]]] | complex | bytes | str | ~numpy._typing._nested_sequence._NestedSequence[complex | bytes | str]"
)
"""How Sphinx spells ``numpy.typing.ArrayLike`` once it has evaluated the annotation (eight lines per argument)."""
ND_ARRAY = re.compile(r"~numpy\.ndarray\[tuple\[~typing\.Any, \.\.\.\], ~numpy\.dtype\[([^\[\]]+)\]\]")


def short_types(text: str | None) -> str | None:
    """A signature with numpy's aliases written as the code writes them: ``ArrayLike``, ``NDArray[float64]``."""
    if text is None:
        return None
    return ND_ARRAY.sub(r"~numpy.typing.NDArray[\1]", text.replace(ARRAY_LIKE, "~numpy.typing.ArrayLike"))


def on_signature(app: Sphinx, what: str, name: str, obj: Any, options: Any, signature: str | None, ret: str | None):
    return short_types(signature), short_types(ret)


def on_bases(app: Sphinx, name: str, obj: Any, options: Any, bases: list[Any]) -> None:
    """No "Bases: object" under every plain class (the bases that say something, e.g. an error's, stay)."""
    bases[:] = [base for base in bases if base is not object]


# --------------------------------------------------------------------------------------------------------------------
# API pages

LAYERS = (
    "core", "paper", "drawing", "media", "exchange", "multibody", "app", "design", "classroom", "lti", "viserkit",
    "ui", "cli",
)  # fmt: skip
"""The folders of the package bottom up, as ``tests/system/test_layering.py`` orders the layers."""


def package_modules() -> list[str]:
    """Every module of ``tpm_viz`` by dotted name (``__main__`` left out: importing it runs the command line)."""
    base = ROOT / PACKAGE
    found = []
    for path in sorted(base.rglob("*.py")):
        parts = path.relative_to(ROOT).with_suffix("").parts
        if parts[-1] == "__main__":
            continue
        found.append(".".join(parts[:-1] if parts[-1] == "__init__" else parts))
    return found


def children(package: str, modules: list[str]) -> list[str]:
    depth = package.count(".") + 1
    return [m for m in modules if m.startswith(package + ".") and m.count(".") == depth]


def api_page(module: str, modules: list[str]) -> str:
    title = module.replace("_", "\\_")
    lines = [title, "=" * len(title), "", f".. automodule:: {module}", ""]
    if module == PACKAGE:
        lines += [".. tpm-public::", ""]
    elif children(module, modules):
        lines += [".. rubric:: Modules", "", f".. tpm-modules:: {module}", ""]
    return "\n".join(lines)


def write_api_pages(app: Sphinx) -> None:
    """``docs/api/generated/<module>.rst`` for every module of the package."""
    out = pathlib.Path(app.srcdir) / "api" / "generated"
    modules = package_modules()
    wanted = set()
    for module in modules:
        path = out / f"{module}.rst"
        wanted.add(path)
        _write(path, api_page(module, modules))
    for stale in out.glob("*.rst"):
        if stale not in wanted:
            stale.unlink()


def summary(module: str) -> str:
    """The first paragraph of a module's docstring."""
    doc = inspect.getdoc(importlib.import_module(module)) or ""
    return doc.split("\n\n")[0].strip()


class ModulesDirective(SphinxDirective):
    """``.. tpm-modules:: package``: the package's modules, each with the first paragraph of its docstring (its
    references read from that module, as its own page reads them), and a hidden toctree of their pages."""

    required_arguments = 1

    def run(self) -> list[nodes.Node]:
        package = self.arguments[0]
        members = children(package, package_modules())
        items = nodes.definition_list()
        saved = self.env.ref_context.get("py:module")
        try:
            for module in members:
                self.env.ref_context["py:module"] = module
                term = nodes.term()
                term += self.parse_text_to_nodes(f":py:mod:`~{module}`")[0].children
                body = nodes.definition()
                body += self.parse_text_to_nodes(summary(module))
                items += nodes.definition_list_item("", term, body)
        finally:
            self.env.ref_context["py:module"] = saved
        toctree = ".. toctree::\n   :hidden:\n\n" + "".join(f"   {m}\n" for m in members)
        return [items, *self.parse_text_to_nodes(toctree)]


class PublicDirective(SphinxDirective):
    """``.. tpm-public::``: the names ``import tpm_viz as tv`` gives, each linked to where it is documented."""

    def run(self) -> list[nodes.Node]:
        package = importlib.import_module(PACKAGE)
        rows = []
        for name in package.__all__:
            obj = getattr(package, name)
            doc = (inspect.getdoc(obj) or "").split("\n\n")[0] if callable(obj) else ""
            first = " ".join(doc.split())
            rows.append(f"* :py:obj:`tv.{name} <{PACKAGE}.{name}>`" + (f": {first}" if first else ""))
        saved = self.env.ref_context.get("py:module")
        self.env.ref_context["py:module"] = PACKAGE
        try:
            return self.parse_text_to_nodes("\n".join(rows))
        finally:
            self.env.ref_context["py:module"] = saved


# --------------------------------------------------------------------------------------------------------------------
# examples


def example_scripts() -> list[pathlib.Path]:
    """``examples/NN_group/NN_name.py``, in order."""
    return sorted(EXAMPLES.glob("[0-9][0-9]_*/[0-9][0-9]_*.py"))


def words(stem: str) -> str:
    """``01_the_model`` -> ``The model``."""
    text = stem.split("_", 1)[1].replace("_", " ")
    return text[:1].upper() + text[1:]


def example_page(script: pathlib.Path) -> str:
    """The Markdown page of one example: its docstring, then the code without it."""
    source = script.read_text()
    tree = ast.parse(source)
    doc = ast.get_docstring(tree)
    if not doc:
        raise ValueError(f"{script.relative_to(ROOT)} has no docstring (its page's text)")
    title, _, body = doc.partition("\n")
    first = tree.body[0]
    code = "\n".join(source.splitlines()[first.end_lineno :]).strip("\n")
    rel = script.relative_to(ROOT).as_posix()
    return (
        f"# {title.strip()}\n\n{body.strip()}\n\n"
        f"Run it from the repository's root: `python {rel}` (it writes its files into the current folder).\n\n"
        f"```python\n{code}\n```\n"
    )


def example_index(scripts: list[pathlib.Path]) -> str:
    lines = [
        "# Examples",
        "",
        "Numbered scripts in `examples/`, each a page: the text is the script's docstring, the code is below it. "
        "`python -m pytest tests/system/test_examples.py` runs every one (the slow ones are marked `slow`), each in "
        "an empty temporary folder, so they cannot go stale.",
        "",
    ]
    groups: dict[str, list[pathlib.Path]] = {}
    for script in scripts:
        groups.setdefault(script.parent.name, []).append(script)
    for group, members in groups.items():
        lines += ["```{toctree}", f":caption: {words(group)}", ":maxdepth: 1", ""]
        lines += [f"{group}/{s.stem}" for s in members]
        lines += ["```", ""]
    lines += [
        "## The generated C in a 1 kHz loop",
        "",
        "`examples/ctc_loop.c` runs the computed-torque law of the exported C at 1 kHz against the generated forward "
        "dynamics and prints its worst step ([control and C](../control.md#real-time-c), "
        "[realtime.md](../realtime.md)); `tests/exchange/c/` compiles and runs it.",
        "",
        "```{literalinclude} ../../examples/ctc_loop.c",
        ":language: c",
        "```",
        "",
    ]
    return "\n".join(lines)


def _write(path: pathlib.Path, text: str) -> None:
    if not path.exists() or path.read_text() != text:
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_text(text)


def write_example_pages(app: Sphinx) -> None:
    """``docs/examples/`` from ``examples/`` (only changed files are rewritten, so a rebuild stays incremental)."""
    out = pathlib.Path(app.srcdir) / "examples"
    scripts = example_scripts()
    wanted = {out / "index.md"} | {out / s.parent.name / f"{s.stem}.md" for s in scripts}
    for script in scripts:
        _write(out / script.parent.name / f"{script.stem}.md", example_page(script))
    _write(out / "index.md", example_index(scripts))
    for stale in out.rglob("*.md"):
        if stale not in wanted:
            stale.unlink()


def setup(app: Sphinx) -> dict[str, Any]:
    app.add_post_transform(CanonicalReferences)
    app.connect("builder-inited", write_example_pages)
    app.connect("builder-inited", write_api_pages)
    app.connect("autodoc-process-signature", on_signature)
    app.connect("autodoc-process-bases", on_bases)
    app.add_directive("tpm-modules", ModulesDirective)
    app.add_directive("tpm-public", PublicDirective)
    return {"parallel_read_safe": True, "parallel_write_safe": True}
