"""Every code block of the docs site and the README is run or checked (``tests/support/docs.py`` finds them):

- ``python``: run, a page's blocks in order in one fresh interpreter in an empty folder (servers a block starts, it
  stops: the interpreter is gone at the end anyway); a fragment says why above it (``<!-- not run: ... -->``) and is
  compiled instead;
- shell (``bash``, ``sh``, ``console``, or a block without a language): each ``tpm-viz ...`` / ``python -m tpm_viz
  ...`` / ``python app.py ...`` command is parsed by the command line's own parser (a synopsis with ``[...]``, ``a|b``
  or ``...`` has its subcommand and option names checked); ``python -m pytest`` and ``python benchmarks|examples/...``
  name files that exist; ``uv pip compile`` is the command in the lock's header. The command-line page's blocks
  also run (``test_doc_commands.py``);
- ``toml``: parses; ``bibtex``: the README's and the site's citation are the same entry.

Output blocks (the ``tpm-viz crosscheck`` table) are pinned by ``test_doc_figures.py``; the nginx and Caddy snippets
of ``docs/classroom.md`` are configuration of other programs and are not checked.
"""

from __future__ import annotations

import os
import pathlib
import re
import shlex
import subprocess
import sys
import tomllib

import pytest

from tests.support.docs import ROOT, Block, all_blocks
from tpm_viz.cli import build_parser

SHELL = {"bash", "sh", "shell", "console", ""}
SEPARATORS = {"&&", "||", ";", "|", "&"}
RUNNER = """
import pathlib, sys
for path in sys.argv[1:]:
    text = pathlib.Path(path).read_text()
    print(f"--- {path}", flush=True)
    exec(compile(text, path, "exec"), globals())
"""


def _python_pages() -> dict[pathlib.Path, list[Block]]:
    found: dict[pathlib.Path, list[Block]] = {}
    for block in all_blocks():
        if block.lang == "python" and block.not_run is None:
            found.setdefault(block.page, []).append(block)
    return found


def _python_params() -> list:
    params = []
    for page, blocks in _python_pages().items():
        slow = any("tpm_viz.ui" in b.text or "tpm_viz.multibody" in b.text for b in blocks)
        marks = [pytest.mark.slow] if slow else []
        params.append(pytest.param(page, id=page.relative_to(ROOT).as_posix(), marks=marks))
    return params


def test_the_pages_have_python_blocks_to_run_and_few_fragments():
    pythons = [b for b in all_blocks() if b.lang == "python"]
    run = [b for b in pythons if b.not_run is None]
    assert len(run) >= 4 and any(b.page.name == "README.md" for b in run)
    fragments = [b.where for b in pythons if b.not_run is not None]
    assert len(fragments) <= 2, f"too many Python blocks are not run: {fragments}"


@pytest.mark.parametrize("block", [b for b in all_blocks() if b.lang == "python"], ids=lambda b: b.where)
def test_every_python_block_compiles(block):
    compile(block.text, block.where, "exec")


@pytest.mark.parametrize("page", _python_params())
def test_the_python_blocks_of_a_page_run_in_order(page, tmp_path):
    files = []
    for n, block in enumerate(_python_pages()[page]):
        path = tmp_path / f"block{n}_{block.line}.py"
        path.write_text(block.text)
        files.append(str(path))
    work = tmp_path / "work"
    work.mkdir()
    env = {**os.environ, "MPLBACKEND": "Agg", "PYTHONPATH": str(ROOT)}
    done = subprocess.run(
        [sys.executable, "-c", RUNNER, *files], cwd=work, env=env, capture_output=True, text=True, timeout=600
    )
    assert done.returncode == 0, f"{page.relative_to(ROOT)}: {done.stdout[-800:]}\n{done.stderr[-2000:]}"


# --------------------------------------------------------------------------------------------------------------------
# shell blocks


def _commands(text: str) -> list[list[str]]:
    """The simple commands of a shell block: lines joined at ``\\`` and inside quotes, comments dropped, split at
    ``&&``, ``;``, ``|``."""
    logical, current, quote, comment = [], [], None, False
    text = text.replace("\\\n", " ")
    for ch in text:
        if comment and ch != "\n":
            continue
        if quote:
            quote = None if ch == quote else quote
        elif ch in "'\"":
            quote = ch
        elif ch == "#" and (not current or current[-1].isspace()):
            comment = True
            continue
        elif ch == "\n":
            logical.append("".join(current))
            current, comment = [], False
            continue
        current.append(ch)
    logical.append("".join(current))
    found = []
    for line in logical:
        line = re.sub(r"^\s*\$ ", "", line)
        lexer = shlex.shlex(line, posix=True, punctuation_chars=True)
        lexer.whitespace_split, lexer.commenters = True, "#"
        try:
            tokens = list(lexer)
        except ValueError:
            tokens = line.split()
        command: list[str] = []
        for token in tokens:
            if token in SEPARATORS:
                found.append(command)
                command = []
            else:
                command.append(token)
        found.append(command)
    return [c for c in found if c]


def _subparsers():
    parser = build_parser()
    action = next(a for a in parser._actions if a.__class__.__name__ == "_SubParsersAction")
    return parser, action.choices


def _tpm_args(command: list[str]) -> list[str] | None:
    """The arguments of a ``tpm-viz`` command (``python -m tpm_viz``, ``python app.py`` too), else None."""
    if command[0] == "tpm-viz":
        return command[1:]
    if command[:3] in (["python", "-m", "tpm_viz"], ["python3", "-m", "tpm_viz"]):
        return command[3:]
    if command[:2] in (["python", "app.py"], ["python3", "app.py"]):
        return ["serve", *command[2:]]
    return None


def _is_synopsis(args: list[str]) -> bool:
    return any(re.search(r"[\[\]|]|\.\.\.", a) for a in args)


def _check_tpm(args: list[str], block: Block, strict: bool) -> str | None:
    """None if the command line accepts ``args`` (a problem otherwise)."""
    parser, subs = _subparsers()
    if not args or (args[0] not in subs and not args[0].startswith("-")):
        return f"unknown subcommand {args[:1]}" if strict else None
    if args[0].startswith("-"):
        return None if set(args) <= {"-h", "--help"} else f"tpm-viz {args}"
    sub, name = subs[args[0]], args[0]
    nested = next((a for a in sub._actions if a.__class__.__name__ == "_SubParsersAction"), None)
    if nested is not None and len(args) > 1 and args[1] in nested.choices:  # tpm-viz exercise list, lti keygen
        sub, name = nested.choices[args[1]], f"{args[0]} {args[1]}"
    if _is_synopsis(args) or "-h" in args or "--help" in args:
        words = [w for a in args for w in re.split(r"[\[\]|]", a)]
        options = {w.split("=")[0] for w in words if w.startswith("--")}
        unknown = sorted(o for o in options if o not in sub._option_string_actions)
        return f"tpm-viz {name}: no option {unknown}" if unknown else None
    try:
        parser.parse_args(args)
    except Exception as exc:
        return f"tpm-viz {' '.join(args)}: {exc}"
    except SystemExit as exc:  # argparse's own exit (the Parser raises InputError instead)
        return f"tpm-viz {' '.join(args)}: exit {exc.code}"
    return None


def _check_paths(command: list[str]) -> str | None:
    if command[:3] == ["python", "-m", "pytest"]:
        paths = [a.split("::")[0] for a in command[3:] if not a.startswith("-") and a.startswith("tests")]
        missing = [p for p in paths if not (ROOT / p).exists()]
        return f"no such test file {missing}" if missing else None
    if command[0] == "python" and len(command) > 1 and re.match(r"(benchmarks|examples)/", command[1]):
        return None if (ROOT / command[1]).is_file() else f"no such script {command[1]}"
    if command[0] == "cc":
        sources = [a for a in command if a.startswith("examples/")]
        missing = [s for s in sources if not (ROOT / s).is_file()]
        return f"no such source {missing}" if missing else None
    if command[:3] == ["uv", "pip", "compile"]:
        header = (ROOT / "constraints.txt").read_text().splitlines()[1].lstrip("# ").strip()
        return None if " ".join(command) == header else f"not the lock's command: {header}"
    return None


SHELL_BLOCKS = [b for b in all_blocks() if b.lang in SHELL]


def test_the_scan_reads_shell_blocks_as_a_shell_does():
    text = 'a --x 1 \\\n  --y 2  # note\ntpm-viz serve && python -c "\nprint(1)\n" | cat\n'
    assert _commands(text) == [
        ["a", "--x", "1", "--y", "2"],
        ["tpm-viz", "serve"],
        ["python", "-c", "\nprint(1)\n"],
        ["cat"],
    ]
    block = Block(ROOT / "README.md", 1, "bash", "", None)
    assert _check_tpm(["kinematics", "--input", "p.csv"], block, True) is None
    assert _check_tpm(["kinematics", "--no-such-option"], block, True) is not None
    assert _check_tpm(["compare", "--hold", "link|footprint", "[--nope", "FILE]"], block, True) is not None
    assert _check_tpm(["serving", "at", "http://127.0.0.1:8080"], block, False) is None  # output, not a command
    assert _check_paths(["python", "-m", "pytest", "tests/no_such_test.py"]) is not None


def test_the_shell_blocks_name_tpm_viz_commands():
    commands = [c for b in SHELL_BLOCKS for c in _commands(b.text) if _tpm_args(c) is not None]
    assert len(commands) >= 30


@pytest.mark.parametrize("block", SHELL_BLOCKS, ids=lambda b: b.where)
def test_every_command_of_a_shell_block_is_accepted(block):
    strict = block.lang != ""  # a block without a language may show a command's output
    problems = []
    for command in _commands(block.text):
        args = _tpm_args(command)
        problem = _check_tpm(args, block, strict) if args is not None else _check_paths(command)
        if problem:
            problems.append(problem)
    assert not problems, f"{block.where}: " + "; ".join(problems)


@pytest.mark.parametrize("block", [b for b in all_blocks() if b.lang == "toml"], ids=lambda b: b.where)
def test_every_toml_block_parses(block):
    tomllib.loads(block.text)


def test_the_citation_is_the_same_in_the_readme_and_on_the_site():
    entries = {b.page.name: b.text for b in all_blocks() if b.lang == "bibtex"}
    assert set(entries) == {"README.md", "index.md"}
    assert entries["README.md"] == entries["index.md"]
    assert "Korean Society for Precision Engineering" in entries["README.md"]
