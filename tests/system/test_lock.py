"""The lock agrees with ``pyproject.toml``: every requirement that ``pip install -e ".[test]"`` asks for is pinned in
``constraints.txt`` to a version its specifier admits, so a new release cannot change what the README's test command
installs (pytest 9.2 broke a fresh install once). Regenerate with the command in its header."""

from __future__ import annotations

import pathlib
import re
import tomllib

from packaging.requirements import Requirement
from packaging.utils import canonicalize_name
from packaging.version import Version

ROOT = pathlib.Path(__file__).resolve().parents[2]
LOCK = ROOT / "constraints.txt"


def _pins() -> dict[str, Version]:
    pins = {}
    for line in LOCK.read_text().splitlines():
        text = line.split("#", 1)[0].strip()
        if not text:
            continue
        name, _, version = text.partition("==")
        assert version, f"constraints.txt: {line!r} is not a pin (name==version)"
        pins[canonicalize_name(name.split("[")[0])] = Version(version)
    return pins


def _wanted(extra: str = "test") -> list[Requirement]:
    """The requirements of the project and of ``extra``, following the project's own extras it names."""
    project = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]
    extras = project["optional-dependencies"]
    own = canonicalize_name(project["name"])
    wanted = [Requirement(r) for r in project["dependencies"]]
    todo, seen = [extra], set()
    while todo:
        name = todo.pop()
        if name in seen:
            continue
        seen.add(name)
        for text in extras[name]:
            req = Requirement(text)
            if canonicalize_name(req.name) == own:
                todo += sorted(req.extras)
            else:
                wanted.append(req)
    return wanted


def test_every_requirement_of_the_test_install_is_pinned_within_its_specifier():
    pins = _pins()
    for req in _wanted():
        name = canonicalize_name(req.name)
        assert name in pins, f"{req.name} is required by pyproject.toml but not pinned in constraints.txt"
        assert req.specifier.contains(pins[name], prereleases=True), (
            f"constraints.txt pins {req.name}=={pins[name]}, outside pyproject.toml's {req.specifier}"
        )


def test_the_pins_the_code_depends_on_are_bounded_above():
    """viser and websockets internals are replaced at start (viserkit): both carry an upper bound."""
    for name in ("viser", "websockets"):
        specs = [s for r in _wanted() if canonicalize_name(r.name) == name for s in r.specifier]
        assert any(s.operator in ("<", "<=", "==", "~=") for s in specs), f"{name} has no upper bound"


def test_the_readme_ci_and_the_latest_entry_point_use_the_lock_as_documented():
    readme = (ROOT / "README.md").read_text()
    ci = (ROOT / ".ci" / "run").read_text()
    assert re.search(r'pip install -e "\.\[test\]" -c constraints\.txt', readme)
    assert re.search(r'pip install -e "\.\[test\]" -c constraints\.txt', ci)
    latest = (ROOT / ".ci" / "latest").read_text()
    assert "-c constraints.txt" not in latest and "--upgrade" in latest
    assert "uv pip compile" in "".join(LOCK.read_text().splitlines()[:3])
