"""The maps are true: every cross-reference in a docstring of ``tpm_viz`` names something that exists.

Checked: Sphinx roles (``:mod:``, ``:class:``, ``:func:``, ``:meth:``, ``:attr:``, ``:data:``, ``:exc:``, ``:obj:``,
``~`` and leading dots as Sphinx reads them) and backticked dotted names that start with ``tpm_viz.`` or with one of
its packages (``paper.kinematics.inverse_kinematics``). A name is resolved the way a reader would look it up: from the
module (or class) that holds the docstring, its package and parents, then from ``tpm_viz``.
"""

from __future__ import annotations

import ast
import builtins
import functools
import importlib
import inspect
import pathlib
import re
from collections.abc import Iterator
from typing import Any

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"
ROLE = re.compile(r":(?:mod|class|func|meth|attr|data|exc|obj):`~?([^`<>]+?)`")
DOTTED = re.compile(r"``?([A-Za-z_][A-Za-z0-9_]*(?:\.[A-Za-z_][A-Za-z0-9_]*)+)``?")
SUBPACKAGES = {p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()}
MISSING = object()


def _modules() -> Iterator[tuple[str, pathlib.Path]]:
    for path in sorted(PACKAGE.rglob("*.py")):
        if path.name == "__main__.py":  # importing it runs the command line
            continue
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        yield ".".join(parts[:-1] if parts[-1] == "__init__" else parts), path


def _docstrings(tree: ast.Module) -> Iterator[tuple[str | None, int, str]]:
    """(enclosing class name or None, line, docstring) of the module, its classes and functions."""
    doc = ast.get_docstring(tree, clean=False)
    if doc:
        yield None, 1, doc

    def walk(node: ast.AST, cls: str | None) -> Iterator[tuple[str | None, int, str]]:
        for child in ast.iter_child_nodes(node):
            if isinstance(child, ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
                inner = child.name if isinstance(child, ast.ClassDef) else cls
                text = ast.get_docstring(child, clean=False)
                if text:
                    yield inner, child.lineno, text
                yield from walk(child, inner)

    yield from walk(tree, None)


@functools.cache
def _lookup(dotted: str) -> Any:
    """The object named by an absolute dotted path (modules imported as needed), or MISSING."""
    parts = dotted.split(".")
    for cut in range(len(parts), 0, -1):
        try:
            obj: Any = importlib.import_module(".".join(parts[:cut]))
        except ImportError:
            continue
        for attr in parts[cut:]:
            obj = getattr(obj, attr, MISSING)
            if obj is MISSING:
                # a dataclass field or an annotated attribute without a class-level value
                return MISSING
        return obj
    return MISSING


def _has_annotation(owner: Any, name: str) -> bool:
    for klass in getattr(owner, "__mro__", ()):
        if name in getattr(klass, "__annotations__", {}) or name in getattr(klass, "__slots__", ()):
            return True
    return False


def _resolves(name: str, module: str, cls: str | None) -> bool:
    package = module.rsplit(".", 1)[0] if not _is_package(module) else module
    if name.startswith("."):  # Sphinx: the current module first, then any object whose name ends with it
        suffix = name.lstrip(".")
        return (
            _found(f"{module}.{suffix}")
            or any(
                _found(f"{other}.{rest}" if rest else other)
                for other in MODULES
                for head, _, rest in [suffix.partition(".")]
                if other == f"tpm_viz.{head}" or other.endswith(f".{head}")
            )
            or any(_found(f"{other}.{suffix}") for other in MODULES)
        )
    if hasattr(builtins, name):
        return True
    if "." not in name and any(_has_member(klass, name) for klass in _classes(module)):
        return True  # :meth:`update` in a module docstring: a method of one of its classes
    if cls is not None and "." not in name and _assigned(_lookup(f"{module}.{cls}"), name):
        return True
    candidates = []
    if cls is not None:
        candidates.append(f"{module}.{cls}.{name}")
    candidates.append(f"{module}.{name}")
    parts = package.split(".")
    for cut in range(len(parts), 0, -1):
        candidates.append(".".join([*parts[:cut], name]))
    candidates.append(name)
    return any(_found(c) for c in candidates)


def _found(dotted: str) -> bool:
    if _lookup(dotted) is not MISSING:
        return True
    owner_path, _, attr = dotted.rpartition(".")
    owner = _lookup(owner_path) if owner_path else MISSING
    return owner is not MISSING and _has_annotation(owner, attr)


def _classes(module: str) -> list[Any]:
    obj = _lookup(module)
    return [v for v in vars(obj).values() if isinstance(v, type)] if obj is not MISSING else []


def _has_member(klass: Any, name: str) -> bool:
    return hasattr(klass, name) or _has_annotation(klass, name) or _assigned(klass, name)


def _assigned(klass: Any, name: str) -> bool:
    """Whether a method of ``klass`` (or a base) assigns ``self.<name>``: an instance attribute."""
    pattern = re.compile(rf"\bself\.{re.escape(name)}\s*(?::[^=]+)?=[^=]")
    return any(pattern.search(_source(base)) for base in getattr(klass, "__mro__", ()))


@functools.cache
def _source(klass: Any) -> str:
    try:
        return inspect.getsource(klass)
    except (OSError, TypeError):
        return ""


def _is_package(module: str) -> bool:
    return (PACKAGE.parent / module.replace(".", "/") / "__init__.py").exists()


def references() -> list[tuple[str, int, str, str | None]]:
    """(module, line, name, enclosing class) of every cross-reference in the package's docstrings."""
    found = []
    for module, path in _modules():
        for cls, line, doc in _docstrings(ast.parse(path.read_text())):
            names = {re.sub(r"\s+", "", m.group(1)) for m in ROLE.finditer(doc)}  # a role may wrap a line
            for m in DOTTED.finditer(doc):
                head = m.group(1).split(".")[0]
                if head == "tpm_viz" or head in SUBPACKAGES:
                    names.add(m.group(1))
            found.extend((module, line, name, cls) for name in sorted(names))
    return found


MODULES = [name for name, _ in _modules()]


def test_the_scan_finds_references_and_catches_a_wrong_one():
    refs = references()
    assert len(refs) > 200
    assert _resolves("inverse_kinematics", "tpm_viz.paper.dynamics", None)
    assert _resolves(".kinematics.inverse_kinematics", "tpm_viz.paper.dynamics", None)
    assert not _resolves(".kinematics.no_such_function", "tpm_viz.paper.dynamics", None)
    assert _resolves(".text.num", "tpm_viz.ui.teaching.player.text", None)  # Sphinx's suffix search
    assert not _resolves(".no_such_module", "tpm_viz.ui.app", None)
    assert not _resolves("paper.no_such_module", "tpm_viz.app.state", None)


def test_every_docstring_reference_names_something_that_exists():
    wrong = [
        f"{module}:{line}: {name}"
        for module, line, name, cls in references()
        if not _resolves(name, module, cls) and not _resolves(f"tpm_viz.{name}", module, cls)
    ]
    assert not wrong, "docstring references to names that do not exist:\n" + "\n".join(wrong)


@pytest.mark.parametrize("package", sorted(SUBPACKAGES | {"ui.teaching"}))
def test_a_package_docstring_lists_only_modules_that_are_there(package):
    """A package's docstring names its modules as ``:mod:`.name``` (or ``name``): each is there."""
    folder = PACKAGE / package.replace(".", "/")
    doc = ast.get_docstring(ast.parse((folder / "__init__.py").read_text())) or ""
    named = {m.group(1).lstrip(".").split(".")[0] for m in re.finditer(r":mod:`~?(\.[A-Za-z_]\w*(?:\.\w+)*)`", doc)}
    there = {p.stem for p in folder.glob("*.py")} | {p.name for p in folder.iterdir() if (p / "__init__.py").exists()}
    assert named <= there, f"tpm_viz.{package} lists modules that are not there: {sorted(named - there)}"


def test_docstrings_state_contracts_not_issue_numbers():
    """A reader of the code needs the contract, not the tracker's history: no "issue N" in the package's text."""
    cited = [
        f"{path.relative_to(PACKAGE.parent)}:{n}"
        for _, path in _modules()
        for n, line in enumerate(path.read_text().splitlines(), 1)
        if re.search(r"\bissues? \d+", line, re.IGNORECASE)
    ]
    assert not cited, "issue numbers in the package's docstrings or comments: " + ", ".join(cited)
