"""Every file option of the command line against device nodes, FIFOs, a symlink to a device and a folder (issue 35,
item 2): ``export --output /dev/full`` replaced the machine's ``/dev/full`` with a regular file, ``report`` and
``clip`` did the same to a node named ``*.html``/``*.gif``, ``--output FIFO`` and ``--trajectory FIFO`` hung.

The options are enumerated from the parser: every option that takes free text is either a path (attacked here, by
its role) or listed in :data:`NOT_PATHS`, so a new path option cannot be missed. Each attack runs the command in this
process under a timer (a hang is interrupted and fails the test); ``serve`` (which would serve, not return, if it did
not refuse) runs in child processes forked from one driver, each under a deadline. Each
must exit 2 with one line saying the node is not a regular file, and the node must still be what it was, with nothing
left beside it. The device is a copy of ``/dev/null`` (``mknod``, root only) or ``/dev/zero`` (inputs), made in a
temporary folder: the machine's own nodes are never offered to the code under test.
"""

from __future__ import annotations

import argparse
import contextlib
import json
import os
import signal
import stat
import subprocess
import sys
from pathlib import Path

import pytest

from tests.support import cli
from tpm_viz.cli import build_parser, main

NOT_PATHS = {
    "--set", "--fext", "--offset", "--pick-size", "--task", "--vary", "--scheduler", "--footprint", "--size", "--date",
    "--host", "--presenter-token", "--trusted-proxy", "--allowed-host", "--answer", "--seed",
}  # fmt: skip
"""Free-text options that do not name a file."""

PATHS: dict[tuple[str, str], str] = {
    ("kinematics", "--input"): "input",
    ("kinematics", "--output"): "output",
    ("dynamics", "--input"): "input",
    ("dynamics", "--output"): "output",
    ("trajectory", "--input"): "input",
    ("trajectory", "--output"): "output",
    ("replay", "--output"): "output",
    ("figures", "--output-dir"): "folder",
    ("control", "--trajectory"): "input",
    ("control", "--output"): "output",
    ("plan", "--path"): "input",
    ("plan", "--output"): "output",
    ("size", "--input"): "input",
    ("size", "--output"): "output",
    ("export", "--output"): "output",
    ("clip", "--trajectory"): "input",
    ("clip", "--output"): "output",
    ("clip", "--sidecar"): "output",
    ("report", "--trajectory"): "input",
    ("report", "--output"): "output",
    ("design", "--output"): "output",
    ("compare", "--output"): "output",
    ("atlas", "--output"): "output",
    ("serve", "--session"): "serve",
    ("serve", "--lessons"): "serve",
    ("serve", "--lti"): "serve",
    ("lti keygen", "--output"): "folder",
    ("exercise list", "--lessons"): "lessons",
    ("exercise show", "--lessons"): "lessons",
    ("exercise grade", "--lessons"): "lessons",
    ("exercise selftest", "--lessons"): "lessons",
    ("page", "--output"): "output",
    ("page", "--scorm"): "output",
    ("page", "--lessons"): "lessons",
    ("docs", "--output"): "folder",
}
"""Every path option by its role: read, written, a folder written into, or ``serve``'s (run in a subprocess)."""

BASE: dict[str, list[str]] = {
    "kinematics": ["--input", "{csv}"],
    "dynamics": ["--input", "{csv}"],
    "trajectory": ["--kind", "line", "--samples", "5"],
    "replay": ["--trajectory", "line"],
    "figures": ["--samples", "5"],
    "control": ["--trajectory", "line", "--controller", "pd"],
    "plan": ["--path", "line", "--force-limit", "100"],
    "size": ["--input", "{csv}"],
    "export": ["--format", "mjcf"],
    "clip": ["--trajectory", "line", "--samples", "5", "--output", "{out}.gif"],
    "report": ["--trajectory", "line", "--samples", "5", "--output", "{out}.html"],
    "design": ["--task=-0.05,0.05,-0.05,0.05"],
    "compare": ["--task=-0.05,0.05,-0.05,0.05"],
    "atlas": ["--task=-0.05,0.05,-0.05,0.05", "--vary", "l_a=0.25:0.27:2", "--output", "{out}.csv"],
    "serve": ["--host", "127.0.0.1", "--port", "0"],
    "lti keygen": [],
    "exercise list": [],
    "page": ["--lesson", "2"],
    "docs": [],
}
"""Arguments that make each command parse (the attacked option is added, or replaces the same option here)."""

REPLACES = {("trajectory", "--input"): "--kind"}
"""Base options the attacked one cannot go with."""
SUFFIX = {"--sidecar": ".json", "--scorm": ".zip", "clip": ".gif", "report": ".html", "export": ".xml", "page": ".html"}
KINDS = ("fifo", "device", "symlink", "folder")
SECONDS = 120.0
"""Longest an attack may take in this process (a loaded machine imports matplotlib and Pinocchio slowly)."""


def _free_text(action: argparse.Action) -> bool:
    return bool(action.option_strings) and action.nargs != 0 and not action.choices and action.type in (None, str, Path)


def _commands(parser: argparse.ArgumentParser, prefix: str = "") -> dict[str, argparse.ArgumentParser]:
    """Every (sub)command's parser by its words (``"lti keygen"``), nested subcommands included."""
    found = {}
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            for name, child in action.choices.items():
                words = f"{prefix} {name}".strip()
                found[words] = child
                found.update(_commands(child, words))
    return found


def test_every_free_text_option_is_a_known_path_or_known_not_to_be_one():
    commands = _commands(build_parser())
    found = {(name, a.option_strings[-1]) for name, p in commands.items() for a in p._actions if _free_text(a)}
    unknown = {key for key in found if key[1] not in NOT_PATHS and key not in PATHS}
    assert not unknown, f"classify these options in PATHS or NOT_PATHS: {sorted(unknown)}"
    assert set(PATHS) <= found, sorted(set(PATHS) - found)  # the table keeps up with the parser


# -- the nodes --------------------------------------------------------------------------------------------------------
def _device(path: Path, like: str) -> None:
    try:
        os.mknod(path, stat.S_IFCHR | 0o666, os.stat(like).st_rdev)
    except (PermissionError, AttributeError, OSError) as exc:
        pytest.skip(f"mknod needs root ({exc})")


def make(kind: str, path: Path, role: str) -> None:
    """A node of ``kind`` at ``path``: a FIFO, a character device (a copy of /dev/null, or /dev/zero to read), a
    symlink to such a device, or an empty folder."""
    like = "/dev/zero" if role == "input" else "/dev/null"
    if kind == "fifo":
        os.mkfifo(path)
    elif kind == "device":
        _device(path, like)
    elif kind == "symlink":
        target = path.with_name(path.name + ".device")
        _device(target, like)
        path.symlink_to(target)
    else:
        path.mkdir()


def snapshot(folder: Path) -> dict[str, tuple[int, int, str]]:
    """What the folder holds: each entry's type and device number, and a symlink's target (never followed)."""
    out = {}
    for entry in sorted(folder.iterdir()):
        info = entry.lstat()
        out[entry.name] = (stat.S_IFMT(info.st_mode), info.st_rdev, os.readlink(entry) if entry.is_symlink() else "")
    return out


@contextlib.contextmanager
def bounded(seconds: float):
    """Interrupt this (main) thread after ``seconds``: a blocking open() or read() of a FIFO raises here."""

    def expire(signum, frame):
        raise TimeoutError(f"the command hung for {seconds:g} s")

    previous = signal.signal(signal.SIGALRM, expire)
    signal.setitimer(signal.ITIMER_REAL, seconds)
    try:
        yield
    finally:
        signal.setitimer(signal.ITIMER_REAL, 0)
        signal.signal(signal.SIGALRM, previous)


def argv_for(command: str, option: str, value: str, work: Path) -> list[str]:
    """``command``'s base arguments with ``option value`` (replacing the base's own ``option``)."""
    csv = work / "in.csv"
    csv.write_text("p1,p2,dp1,dp2,ddp1,ddp2\n0,0,0,0,0,0\n0.01,0,0,0,0,0\n")
    base = [a.format(csv=csv, out=work / "out") for a in BASE[command]]
    for drop in (option, REPLACES.get((command, option))):
        if drop in base:
            at = base.index(drop)
            del base[at : at + 2]
    return [*command.split(), *base, option, value]


def _one_line_refusal(err: str, what: str) -> None:
    assert err.count("\n") == 1 and err.startswith("tpm-viz: error:"), err
    assert "Traceback" not in err and len(err) <= 320, err
    assert what in err, err


def _attack(command: str, option: str, role: str, kind: str, tmp_path: Path, capsys) -> None:
    work = tmp_path / "work"
    nodes = tmp_path / "nodes"
    work.mkdir()
    nodes.mkdir()
    name = "node" + SUFFIX.get(option, SUFFIX.get(command, ".csv"))
    if role == "folder":  # the folder itself, then a node where its first file goes
        make(kind, nodes / name, role)
        before = snapshot(nodes)
        with bounded(SECONDS):
            assert main(argv_for(command, option, str(nodes / name), work)) == 2
        _one_line_refusal(capsys.readouterr().err, str(nodes / name))
        assert snapshot(nodes) == before
        return
    make(kind, nodes / name, role)
    before = snapshot(nodes)
    with bounded(SECONDS):
        status = main(argv_for(command, option, str(nodes / name), work))
    captured = capsys.readouterr()
    assert status == 2, captured.err
    _one_line_refusal(captured.err, "not a regular file")
    assert str(nodes / name) in captured.err
    assert snapshot(nodes) == before  # the node is what it was, and nothing was put beside it


CASES = [(c, o, r) for (c, o), r in PATHS.items() if r in ("input", "output")]


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize(("command", "option", "role"), CASES, ids=[f"{c}{o}" for c, o, _ in CASES])
def test_a_file_option_refuses_a_node_and_leaves_it_as_it_is(command, option, role, kind, tmp_path, capsys):
    _attack(command, option, role, kind, tmp_path, capsys)


@pytest.mark.parametrize("kind", ("fifo", "device", "symlink"))  # a folder is what it takes
@pytest.mark.parametrize(
    ("command", "option"), [("figures", "--output-dir"), ("lti keygen", "--output"), ("docs", "--output")]
)
def test_an_output_folder_that_is_a_node_is_refused(command, option, kind, tmp_path, capsys):
    _attack(command, option, "folder", kind, tmp_path, capsys)


@pytest.mark.parametrize("kind", ("fifo", "device", "symlink"))
def test_a_lessons_folder_that_is_a_node_or_holds_one_is_refused(kind, tmp_path, capsys):
    """``exercise ... --lessons`` reads a folder of lesson files: a node as the folder, or as a lesson file in it."""
    _attack("exercise list", "--lessons", "folder", kind, tmp_path, capsys)
    folder = tmp_path / "lessons"
    folder.mkdir()
    make(kind, folder / "01-node.toml", "input")
    before = snapshot(folder)
    with bounded(SECONDS):
        assert main(["exercise", "list", "--lessons", str(folder)]) == 2
    _one_line_refusal(capsys.readouterr().err, "01-node.toml")
    assert snapshot(folder) == before


@pytest.mark.parametrize("kind", ("fifo", "device", "symlink"))
@pytest.mark.parametrize(
    ("argv", "first"),
    [
        (["figures", "--samples", "5", "--output-dir"], "fig4_line.png"),
        (["export", "--format", "c", "--output"], "tpm_2ppa.h"),
        (["lti", "keygen", "--output"], "tool-key.pem"),
    ],
    ids=["figures", "export-c", "lti-keygen"],
)
def test_a_node_where_a_folders_file_goes_is_refused(argv, first, kind, tmp_path, capsys):
    folder = tmp_path / "out"
    folder.mkdir()
    make(kind, folder / first, "output")
    before = snapshot(folder)
    with bounded(SECONDS):
        assert main([*argv, str(folder)]) == 2
    err = capsys.readouterr().err
    # the key is never written over anything that exists (a node included): its own line says so
    _one_line_refusal(err, "exists and is not overwritten" if first == "tool-key.pem" else "not a regular file")
    assert snapshot(folder) == before


# -- serve, and the issue's own commands as a user types them ---------------------------------------------------------
_DRIVER = r"""
import json, os, signal, sys, time
import tpm_viz.cli, tpm_viz.ui.app  # the imports every case shares, made once before the forks
cases, deadline = json.loads(sys.argv[1]), float(sys.argv[2])
results = {}
for key, (argv, out, err) in cases.items():
    pid = os.fork()
    if pid == 0:  # the child: the case as a process of its own, its streams in two files, no stdin
        os.dup2(os.open(os.devnull, os.O_RDONLY), 0)
        os.dup2(os.open(out, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), 1)
        os.dup2(os.open(err, os.O_WRONLY | os.O_CREAT | os.O_TRUNC), 2)
        try:
            status = tpm_viz.cli.main(argv)
        finally:
            sys.stdout.flush()
            sys.stderr.flush()
        os._exit(status)
    end = time.monotonic() + deadline
    while time.monotonic() < end:  # bounded: a case that serves instead of refusing is killed at the deadline
        done, code = os.waitpid(pid, os.WNOHANG)
        if done:
            results[key] = os.waitstatus_to_exitcode(code)
            break
        time.sleep(0.05)
    else:
        os.kill(pid, signal.SIGKILL)
        os.waitpid(pid, 0)
        results[key] = "hung"
print(json.dumps(results))
"""

SERVE_CASES = [(o, k) for o in ("--session", "--lessons") for k in KINDS if (o, k) != ("--lessons", "folder")]
"""``serve``'s file options against each node (a folder is what ``--lessons`` takes: its files are read)."""


@pytest.fixture(scope="module")
def serve_refusals(tmp_path_factory) -> dict[tuple[str, str], tuple | str]:
    """Every ``serve`` case, each a child process forked from one driver (``python -c``, the imports made once): per
    case ``(status, stdout, stderr, snapshot before, snapshot after, node)``, or why it was skipped (no ``mknod``)."""
    out: dict[tuple[str, str], tuple | str] = {}
    cases, folders = {}, {}
    for option, kind in SERVE_CASES:
        key, folder = f"{option}-{kind}", tmp_path_factory.mktemp(f"serve{option}-{kind}")
        name = "node.toml" if option == "--lessons" else "node.sqlite3"
        try:
            make(kind, folder / name, "input")
        except pytest.skip.Exception as exc:
            out[option, kind] = str(exc)
            continue
        argv = ["serve", *BASE["serve"], option, str(folder / name)]
        cases[key] = (argv, str(folder / "stdout.txt"), str(folder / "stderr.txt"))
        folders[key] = (option, kind, folder, snapshot(folder))
    if cases:
        done = subprocess.run(
            [sys.executable, "-c", _DRIVER, json.dumps(cases), str(SECONDS / 2)],
            capture_output=True,
            text=True,
            timeout=SECONDS * len(cases),
        )
        assert done.returncode == 0, done.stderr
        statuses = json.loads(done.stdout)
        for key, (option, kind, folder, before) in folders.items():
            streams = [(folder / f).read_text() for f in ("stdout.txt", "stderr.txt")]
            for f in ("stdout.txt", "stderr.txt"):
                (folder / f).unlink()
            out[option, kind] = (statuses[key], *streams, before, snapshot(folder), cases[key][0][-1])
    return out


@pytest.mark.slow
@pytest.mark.parametrize(("option", "kind"), SERVE_CASES)
def test_serve_refuses_a_node_as_its_store_or_lessons_before_serving(option, kind, serve_refusals):
    result = serve_refusals[option, kind]
    if isinstance(result, str):
        pytest.skip(result)
    status, stdout, stderr, before, after, node = result
    assert status == 2 and stdout == "", (status, stdout, stderr)
    _one_line_refusal(stderr, node)
    assert after == before


@pytest.mark.slow
def test_the_issues_commands_exit_2_at_once_and_leave_the_nodes(tmp_path, capsys):
    os.mkfifo(tmp_path / "pipe.csv")
    os.mkfifo(tmp_path / "pipe.html")
    make("device", tmp_path / "full.xml", "output")
    before = snapshot(tmp_path)
    for argv in (
        ["export", "--format", "mjcf", "--output", str(tmp_path / "full.xml")],
        ["trajectory", "--kind", "line", "--output", str(tmp_path / "pipe.csv")],
        ["kinematics", "--input", str(tmp_path / "pipe.csv")],
        ["report", "--trajectory", str(tmp_path / "pipe.csv"), "--output", str(tmp_path / "r.html")],
        ["report", "--trajectory", "line", "--output", str(tmp_path / "pipe.html")],
    ):
        with bounded(SECONDS):
            res = cli.run(capsys, *argv)
        assert res.returncode == 2, (argv, res.stderr)
        _one_line_refusal(res.stderr, "not a regular file")
    assert snapshot(tmp_path) == before


@pytest.mark.end_to_end
def test_stdin_and_stdout_still_work():
    """The installed command in a child process whose stdin and stdout are pipes (not refused as nodes)."""
    res = cli.run_installed("kinematics", "--input", "-", "--output", "-", stdin="p1,p2\n0,0\n", timeout=SECONDS)
    assert res.returncode == 0 and res.stdout.startswith("p1,p2,d1,d2"), res.stderr
