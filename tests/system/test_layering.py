"""Architecture rules, read from the source: folders by layer, each with one import rule; no cycles; viser behind
one door; no module over 400 lines. The rules are per folder (a new module obeys its folder's rule automatically).

Layers, bottom up (a module may import its own layer and the layers its rule lists, never one above):

- base (``errors``, ``params``, ``csvio``, ``csvdialect``, ``numbers``, ``words``, ``files``): the standard library and
  numpy;
- ``paper/``: the paper's maths, numpy only;
- drawing (``meshes``, ``meshes_parallel``, ``figures``, ``clips``, ``videos``, ``views3d``): trimesh / matplotlib /
  Pillow / PyAV over the paper's maths;
- ``reports/``: documents of a run (the lab report) from the app's runs and the drawing layer;
- ``exchange/``: model files written from the parameters (no simulator imported);
- ``multibody/``: the only place that imports pinocchio;
- ``app/``: pure app behaviour, no viser, no pinocchio;
- ``classroom/``: the classroom's shared state (sessions, drags, snapshot, pacing, access), store, identities, saving
  and jobs: the standard library, base, paper, drawing, app and platformdirs (no viser);
- ``viserkit/``: the adapter, the only place that touches viser's or websockets' internals: base, app, classroom,
  viser and websockets;
- ``cluster`` (``tpm_viz/cluster.py``): the only place that imports Dask (the optional extra ``.[cluster]``);
- ``lti/``: the LTI 1.3 tool (the optional extra ``.[lti]``): base, app, classroom, PyJWT, cryptography, Starlette,
  uvicorn, httpx and python-multipart; never viser (the app applies its launches in ``ui/launched.py``);
- ``ui/``: the per-tab views through viser's public API (its private names only in ``viserkit/``);
- ``cli/``: may import every layer; nothing imports it but ``__main__``.
"""

from __future__ import annotations

import ast
import functools
import pathlib
import re
import subprocess
import sys

import pytest

PACKAGE = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"
STDLIB = set(sys.stdlib_module_names) | {"__future__"}

BASE = {"errors", "params", "csvio", "csvdialect", "numbers", "words", "files"}
DRAWING = {"meshes", "figures", "clips", "videos", "meshes_parallel", "views3d"}

# layer -> (tpm_viz layers it may import, third-party packages it may import)
RULES: dict[str, tuple[set[str], set[str]]] = {
    "base": ({"base"}, {"numpy"}),
    "paper": ({"base", "paper"}, {"numpy"}),
    "drawing": ({"base", "paper", "drawing"}, {"numpy", "trimesh", "matplotlib", "PIL", "av"}),
    "reports": ({"base", "paper", "drawing", "app", "reports"}, {"numpy"}),
    "exchange": ({"base", "paper", "exchange"}, {"numpy"}),
    "multibody": ({"base", "paper", "multibody"}, {"numpy", "pinocchio"}),
    "app": ({"base", "paper", "app"}, {"numpy", "toppra", "scipy"}),
    "classroom": ({"base", "paper", "drawing", "app", "classroom"}, {"numpy", "platformdirs"}),
    "viserkit": ({"base", "app", "classroom", "viserkit"}, {"numpy", "viser", "websockets"}),
    "cluster": ({"base", "paper", "app", "cluster"}, {"numpy", "distributed", "dask"}),  # tpm_viz/cluster.py
    "lti": (
        {"base", "app", "classroom", "lti"},
        {"jwt", "cryptography", "starlette", "uvicorn", "httpx", "multipart"},
    ),
    "ui": (
        {"base", "paper", "drawing", "multibody", "app", "reports", "classroom", "viserkit", "ui"},
        {"numpy", "trimesh", "viser", "platformdirs", "segno"},
    ),
    "cli": (
        {
            "base",
            "paper",
            "drawing",
            "exchange",
            "multibody",
            "app",
            "reports",
            "classroom",
            "viserkit",
            "ui",
            "cluster",
            "lti",
            "cli",
        },
        {"numpy"},
    ),
    "api": ({"base", "paper"}, set()),  # tpm_viz/__init__.py: the public API
    "main": ({"cli"}, set()),  # tpm_viz/__main__.py
}


def layer_of(module: str) -> str:
    """The layer of a dotted module name under tpm_viz (``tpm_viz.paper.kinematics`` -> ``paper``)."""
    parts = module.split(".")[1:]
    if not parts:
        return "api"
    head = parts[0]
    if head in BASE:
        return "base"
    if head in DRAWING:
        return "drawing"
    if head == "__main__":
        return "main"
    return head


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


@pytest.mark.parametrize("module", sorted(MODULES))
def test_each_module_imports_only_what_its_layer_allows(module):
    layer = layer_of(module)
    assert layer in RULES, f"{module}: folder {layer!r} has no import rule; add one to RULES"
    allowed_layers, allowed_third = RULES[layer]
    for imported, _ in imports(MODULES[module], module):
        root = imported.split(".")[0]
        if root == "tpm_viz":
            target = layer_of(imported)
            assert target in allowed_layers, f"{module} ({layer}) imports {imported} ({target}): points up a layer"
        elif root not in STDLIB:
            assert root in allowed_third, f"{module} ({layer}) imports {root}: not allowed in {layer}/"


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_import_inside_functions_except_the_cli_deferring_heavy_layers(module):
    """Lazy imports hide cycles and cost; the command line alone defers the heavy modules (pinocchio, viser,
    matplotlib, toppra) to the subcommand that needs them, so ``tpm-viz kinematics`` starts fast."""
    lazy = [name for name, top in imports(MODULES[module], module) if not top]
    if layer_of(module) == "cli":
        assert all(n.startswith("tpm_viz") for n in lazy), lazy
    else:
        assert lazy == [], f"{module} imports inside a function: {lazy}"


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


@pytest.mark.parametrize("module", sorted(MODULES))
def test_no_module_over_400_lines(module):
    assert len(MODULES[module].read_text().splitlines()) <= 400, f"{module}: split it by concept"


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
