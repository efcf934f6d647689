"""Architecture rules, read from the source: folders by layer, each with one import rule; no cycles; viser behind
one door; no module over 400 lines. The layer of a module is its folder under ``tpm_viz/`` (a new module obeys its
folder's rule automatically), and each rule is one test.

Layers, bottom up (a module may import its own layer and the layers its rule lists, never one above):

- ``core/``: errors, parameters, numbers, words, files, CSV: the standard library and numpy;
- ``paper/`` (with ``paper/parallel/``): the paper's maths, numpy only;
- ``drawing/``: trimesh parts, matplotlib figures, the palette, over the paper's maths;
- ``media/``: what leaves the room (clips, 3D frames, videos, the lab report): drawing and the app's runs;
- ``exchange/`` (with ``exchange/c/``): model files and C written from the parameters (no simulator imported);
- ``multibody/``: the only place that imports pinocchio;
- ``app/``: pure app behaviour, no viser, no pinocchio;
- ``design/``: the design studio over the app's planner (the only place that imports Dask: ``design/cluster.py``);
- ``classroom/``: the classroom's shared state, runs, store, identities, links, saving and jobs (no viser);
- ``lti/``: the LTI 1.3 tool (the optional extra ``.[lti]``), an ASGI service over the classroom; never viser (the app
  applies its launches in ``ui/launched.py``);
- ``viserkit/``: the adapter, the only place that touches viser's or websockets' internals;
- ``ui/`` (with ``ui/widgets/`` and ``ui/teaching/``): the per-tab views through viser's public API;
- ``cli/``: may import every layer; nothing imports it but ``__main__``.
"""

from __future__ import annotations

import ast
import functools
import importlib.util
import pathlib
import re
import subprocess
import sys

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"
STDLIB = set(sys.stdlib_module_names) | {"__future__"}
LAYERS = ("core", "paper", "drawing", "media", "exchange", "multibody", "app", "design", "classroom", "lti")
LAYERS += ("viserkit", "ui", "cli")

# layer -> (tpm_viz layers it may import, third-party packages it may import)
RULES: dict[str, tuple[set[str], set[str]]] = {
    "core": ({"core"}, {"numpy"}),
    "paper": ({"core", "paper"}, {"numpy"}),
    "drawing": ({"core", "paper", "drawing"}, {"numpy", "trimesh", "matplotlib"}),
    "media": ({"core", "paper", "drawing", "app", "media"}, {"numpy", "trimesh", "matplotlib", "PIL", "av"}),
    "exchange": ({"core", "paper", "exchange"}, {"numpy"}),
    "multibody": ({"core", "paper", "multibody"}, {"numpy", "pinocchio"}),
    "app": ({"core", "paper", "app"}, {"numpy", "toppra", "scipy"}),
    "design": ({"core", "paper", "app", "design"}, {"numpy", "scipy", "distributed", "dask"}),
    "classroom": ({"core", "paper", "drawing", "app", "classroom"}, {"numpy", "platformdirs"}),
    "lti": ({"core", "app", "classroom", "lti"}, {"jwt", "cryptography", "starlette", "uvicorn", "httpx", "multipart"}),
    "viserkit": ({"core", "app", "classroom", "viserkit"}, {"numpy", "viser", "websockets"}),
    "ui": (set(LAYERS) - {"cli", "lti"}, {"numpy", "trimesh", "viser", "platformdirs", "segno"}),
    "cli": (set(LAYERS), {"numpy"}),
    "api": ({"core", "paper"}, set()),  # tpm_viz/__init__.py: the public API
    "main": ({"cli"}, set()),  # tpm_viz/__main__.py
}


def layer_of(module: str) -> str:
    """The layer of a dotted module name: its folder under tpm_viz (``tpm_viz.paper.parallel.dynamics`` ->
    ``paper``)."""
    parts = module.split(".")[1:]
    if not parts:
        return "api"
    return "main" if parts[0] == "__main__" else parts[0]


@functools.cache
def modules() -> dict[str, pathlib.Path]:
    """Every module of the package, by dotted name (read once: the tests never change the tree)."""
    found = {}
    for path in sorted(PACKAGE.rglob("*.py")):
        parts = path.relative_to(PACKAGE.parent).with_suffix("").parts
        name = ".".join(parts[:-1] if parts[-1] == "__init__" else parts)
        found[name] = path
    return found


@functools.cache
def imports(path: pathlib.Path, module: str) -> list[tuple[str, bool]]:
    """``(imported module, at module level)`` for every import statement of ``path`` (parsed once)."""
    tree = ast.parse(path.read_text())
    top = {id(node) for node in tree.body}
    package = module if path.name == "__init__.py" else module.rsplit(".", 1)[0]
    found = []
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found += [(alias.name, id(node) in top) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                anchor = package.split(".")[: len(package.split(".")) - node.level + 1]
                base = ".".join(anchor + ([base] if base else []))
            names = [f"{base}.{a.name}" for a in node.names]
            known = modules()
            # "from tpm_viz.x import y": y may be a module (counts as one) or a name in x
            found += [(n if n in known else base, id(node) in top) for n in names]
    return found


MODULES = modules()


def test_every_folder_of_the_package_is_a_layer_with_a_rule():
    folders = {p.parent.relative_to(PACKAGE).parts[0] for p in PACKAGE.rglob("*.py") if p.parent != PACKAGE}
    loose = sorted(p.name for p in PACKAGE.glob("*.py"))
    assert folders <= set(RULES), f"folders without an import rule: {sorted(folders - set(RULES))}"
    assert loose == ["__init__.py", "__main__.py"], f"modules loose at the package root: {loose}"


@pytest.mark.parametrize("layer", sorted(RULES))
def test_the_layer_imports_only_what_its_rule_allows(layer):
    allowed_layers, allowed_third = RULES[layer]
    wrong = []
    for module in (m for m in MODULES if layer_of(m) == layer):
        for imported, _ in imports(MODULES[module], module):
            root = imported.split(".")[0]
            if root == "tpm_viz" and layer_of(imported) not in allowed_layers:
                wrong.append(f"{module} imports {imported} ({layer_of(imported)}): points up a layer")
            elif root not in STDLIB and root != "tpm_viz" and root not in allowed_third:
                wrong.append(f"{module} imports {root}: not allowed in {layer}/")
    assert wrong == []


def test_no_import_inside_functions_except_the_cli_deferring_heavy_layers():
    """Lazy imports hide cycles and cost; the command line alone defers the heavy modules (pinocchio, viser,
    matplotlib, toppra) to the subcommand that needs them, so ``tpm-viz kinematics`` starts fast."""
    wrong = []
    for module, path in MODULES.items():
        lazy = [name for name, top in imports(path, module) if not top]
        if layer_of(module) == "cli":
            wrong += [f"{module}: {n} (not tpm-viz's own)" for n in lazy if not n.startswith("tpm_viz")]
        else:
            wrong += [f"{module} imports {n} inside a function" for n in lazy]
    assert wrong == []


def test_no_import_cycle():
    graph = {
        m: {i for i, top in imports(p, m) if top and i in MODULES and i != m and not _is_parent(i, m)}
        for m, p in MODULES.items()
    }
    state: dict[str, int] = {}

    def visit(node: str, stack: list[str]) -> None:
        state[node] = 1
        for nxt in sorted(graph[node]):
            if state.get(nxt) == 1:
                cycle = [*stack[stack.index(nxt) :], nxt] if nxt in stack else [node, nxt]
                raise AssertionError("import cycle: " + " -> ".join(cycle))
            if nxt not in state:
                visit(nxt, [*stack, nxt])
        state[node] = 2

    for m in sorted(graph):
        if m not in state:
            visit(m, [m])


def _is_parent(package: str, module: str) -> bool:
    """``tpm_viz.paper`` is imported implicitly by ``tpm_viz.paper.x``: not an edge of the cycle check."""
    return module.startswith(package + ".")


def test_nothing_imports_the_command_line():
    for module, path in MODULES.items():
        if layer_of(module) not in {"cli", "main"}:
            assert not any(layer_of(i) == "cli" for i, _ in imports(path, module) if i.startswith("tpm_viz")), module


def test_no_module_over_400_lines():
    long = {m: n for m, p in MODULES.items() if (n := len(p.read_text().splitlines())) > 400}
    assert long == {}, f"split these by concept: {long}"


def test_outside_the_classroom_layer_the_hub_is_locked_through_its_one_context():
    """``Hub.locked()`` is how a view takes the hub's lock: no module outside ``classroom/`` reads ``hub.lock``."""
    found = []
    for name, path in MODULES.items():
        if name.startswith("tpm_viz.classroom."):
            continue
        for node in ast.walk(ast.parse(path.read_text())):
            if isinstance(node, ast.Attribute) and node.attr == "lock":
                owner = node.value
                if (isinstance(owner, ast.Attribute) and owner.attr == "hub") or (
                    isinstance(owner, ast.Name) and owner.id == "hub"
                ):
                    found.append(f"{name}:{node.lineno}")
    assert found == [], f"take the lock with hub.locked(): {found}"


PRIVATE_VISER = re.compile(
    r"\._(?:thread_executor|websock_connection|websock_server|handle_gui_updates|handle_file_transfer\w*|"
    r"current_file_upload_states|gui_input_handle_from_uuid|impl_aux|impl|share_tunnel|client_state_from_id|"
    r"live_connections|message_producer|message_consumer|window_loop|broadcast_buffer)\b|"
    r"\bviser(?:\.infra)?\._(?!_)|from viser(?:\.infra)? import _"
)


def test_private_viser_names_are_used_in_the_adapter_only():
    users = {m for m, p in MODULES.items() if PRIVATE_VISER.search(p.read_text())}
    assert users and all(m.startswith("tpm_viz.viserkit.") for m in users), users


def test_tests_and_benchmarks_use_no_private_viser_name():
    """They reach viser's internals through the adapter's public functions (``tpm_viz.viserkit.probe``)."""
    root = PACKAGE.parent
    paths = [p for d in ("tests", "benchmarks") for p in sorted((root / d).rglob("*.py"))]
    users = [str(p.relative_to(root)) for p in paths if PRIVATE_VISER.search(p.read_text())]
    assert paths and users == [], users


def _outside_the_adapter() -> list[pathlib.Path]:
    """The Python files that must reach viser through the adapter: the package outside ``viserkit/``, the tests, the
    benchmarks and the examples."""
    root = PACKAGE.parent
    package = [p for m, p in MODULES.items() if not m.startswith("tpm_viz.viserkit")]
    others = [p for d in ("tests", "benchmarks", "examples") for p in sorted((root / d).rglob("*.py"))]
    return package + others + [p for p in (root / "app.py",) if p.is_file()]


PRIVATE_BY_NAME = re.compile(r"(?<![\w.])(?:getattr|hasattr|setattr|delattr)\(\s*[^,]+,\s*[\"']_(?!_)")
"""A private attribute reached by its name as a string (the built-in functions; ``monkeypatch.setattr`` on tpm-viz's
own modules is a test's business and not matched)."""


def test_no_private_name_is_reached_by_string_outside_the_adapter():
    """The trick that hides a private read from the name check above: ``getattr`` (or ``hasattr``, ``setattr``,
    ``delattr``) with a literal name that starts with one underscore. Inside ``viserkit/`` it is the adapter's job."""
    root = PACKAGE.parent
    found = [
        f"{p.relative_to(root)}:{n}: {line.strip()}"
        for p in _outside_the_adapter()
        for n, line in enumerate(p.read_text().splitlines(), 1)
        if PRIVATE_BY_NAME.search(line)
    ]
    assert found == []


def _defined_private_names(text: str) -> set[str]:
    """Private names a file defines: ``self._x =``, ``_x =`` or ``_x:`` at a line's start, ``def _x``, ``class _X``."""
    found = set(re.findall(r"\b(?:self|cls)\.(_[a-z]\w*)\s*(?::[^=\n]+)?=", text))
    found |= set(re.findall(r"^\s*(_[A-Za-z]\w*)\s*[:=]", text, re.MULTILINE))
    found |= set(re.findall(r"^\s*(?:async\s+)?(?:def|class)\s+(_[A-Za-z]\w*)", text, re.MULTILINE))
    return found


@functools.cache
def _viser_only_private_names() -> frozenset[str]:
    """The private attribute names viser's own source defines that no file of tpm-viz outside the adapter defines too
    (a ``._x`` of such a name outside the adapter can only be viser's)."""
    spec = importlib.util.find_spec("viser")
    assert spec is not None and spec.submodule_search_locations, "viser is not installed"
    viser_root = pathlib.Path(next(iter(spec.submodule_search_locations)))
    viser_names: set[str] = set()
    for path in viser_root.rglob("*.py"):
        viser_names |= _defined_private_names(path.read_text(encoding="utf-8"))
    own: set[str] = set()
    for path in _outside_the_adapter():
        own |= _defined_private_names(path.read_text())
    return frozenset(viser_names - own)


def test_no_private_attribute_of_viser_is_read_outside_the_adapter():
    """Any attribute read outside the adapter whose private name only viser defines (an image node's encoded bytes, a
    recorder's time): :data:`PRIVATE_VISER` lists the ones the adapter uses, this catches the next one
    (:mod:`tpm_viz.viserkit.probe` has public functions for tests, :mod:`tpm_viz.viserkit.core` for the app)."""
    root, names = PACKAGE.parent, _viser_only_private_names()
    assert len(names) > 50, "viser's source was not read"
    found = [
        f"{p.relative_to(root)}:{n}: .{m.group(1)}"
        for p in _outside_the_adapter()
        for n, line in enumerate(p.read_text().splitlines(), 1)
        for m in re.finditer(r"\.(_[a-z]\w*)\b", line)
        if m.group(1) in names
    ]
    assert found == []


def test_the_door_to_viser_refuses_an_untested_version_loudly():
    from tpm_viz.viserkit.core import IncompatibleViserError, check_viser

    check_viser()  # the installed one is the tested one
    with pytest.raises(
        IncompatibleViserError, match=r"viser 1\.2\.0 is installed .* pip install 'viser>=1\.1\.1,<1\.2'"
    ):
        check_viser("1.2.0")
    with pytest.raises(
        IncompatibleViserError, match=r"websockets 17\.0 is installed .* pip install 'websockets>=15,<17'"
    ):
        check_viser(websockets_version="17.0")
    check_viser(websockets_version="15.0.1")  # an older tested major is accepted


def test_importing_the_library_and_the_command_line_loads_neither_viser_nor_pinocchio():
    code = (
        "import sys, tpm_viz, tpm_viz.cli, tpm_viz.paper.workspace, tpm_viz.paper.trajectories, tpm_viz.app.moves\n"
        "bad = [m for m in ('viser', 'pinocchio', 'matplotlib', 'trimesh') if m in sys.modules]\n"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""
