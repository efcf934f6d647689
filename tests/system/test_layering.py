"""Architecture rules: the library never loads viser or pinocchio; each heavy import lives in one place."""

from __future__ import annotations

import pathlib
import re
import subprocess
import sys

ROOT = pathlib.Path(__file__).resolve().parents[2] / "tpm_viz"


def test_importing_the_library_loads_neither_viser_nor_pinocchio():
    code = (
        "import sys, tpm_viz, tpm_viz.cli, tpm_viz.paper.workspace, tpm_viz.paper.trajectories\n"
        "bad = [m for m in ('viser', 'pinocchio', 'matplotlib', 'trimesh') if m in sys.modules]\n"
        "print(','.join(bad))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True).stdout
    assert out.strip() == ""


def _importers(module: str) -> set[str]:
    pattern = re.compile(rf"^\s*(import {module}\b|from {module}\b)", re.MULTILINE)
    return {str(p.relative_to(ROOT)) for p in ROOT.rglob("*.py") if pattern.search(p.read_text())}


def test_pinocchio_is_imported_in_exactly_one_module():
    assert _importers("pinocchio") <= {"multibody/model.py"}


def test_viser_is_imported_only_in_the_ui_package():
    assert all(path.startswith("ui/") for path in _importers("viser"))


def test_pure_math_modules_import_only_numpy():
    allowed = {"numpy", "__future__", "dataclasses", "typing", "math", "collections", "csv", "io", "sys"}
    for name in (
        "params",
        "paper/kinematics",
        "paper/jacobians",
        "paper/dynamics",
        "paper/trajectories",
        "paper/workspace",
        "paper/spline",
        "csvio",
    ):
        text = (ROOT / f"{name}.py").read_text()
        for mod in re.findall(r"^\s*(?:import|from) (\w+)", text, re.MULTILINE):
            assert mod in allowed or mod == "tpm_viz", f"{name}.py imports {mod}"
