"""``tpm-viz compare`` for people (issue 40, item 7): a terminal gets a table in mm, N, kg, s; a pipe or ``--output``
gets the CSV (SI, unchanged); the searches' progress goes to stderr. The terminal is a real pseudo-terminal
(:func:`os.openpty`) around the installed entry point; the table's numbers are checked against the CSV converted
here; docs/cli.md shows what the terminal printed."""

from __future__ import annotations

import csv
import io
import os
import pathlib
import re
import subprocess

import pytest

from tests.support.cli import installed, run

ROOT = pathlib.Path(__file__).resolve().parents[2]
QUICK = ["compare", "--task=-0.1,0.1,-0.05,0.05", "--hold", "footprint", "--generations", "1", "--grid", "60"]
"""A comparison in seconds (one generation, a coarse planner grid) whose parallel search finds nothing feasible."""
UNITS = {
    # heading: (CSV column, factor from SI, decimals shown), written here from docs/conventions.md
    "a": ("a", 1000.0, 1),
    "b": ("b", 1000.0, 1),
    "l_a": ("l_a", 1000.0, 1),
    "Δd": ("stroke", 1000.0, 1),
    "m_b": ("m_b", 1.0, 3),
    "task x0": ("task_x0", 1000.0, 1),
    "task x1": ("task_x1", 1000.0, 1),
    "task y0": ("task_y0", 1000.0, 1),
    "task y1": ("task_y1", 1000.0, 1),
    "GCI": ("gci", 1.0, 3),
    "cond J": ("cond_max", 1.0, 2),
    "dyn mean": ("dyn_mean", 1.0, 2),
    "dyn max": ("dyn_max", 1.0, 2),
    "peak force": ("peak_force", 1.0, 0),
    "cycle": ("cycle_time", 1.0, 3),
    "moving mass": ("moving_mass", 1.0, 2),
    "footprint x": ("footprint_x", 1000.0, 1),
    "footprint y": ("footprint_y", 1000.0, 1),
}


def on_terminal(
    argv: list[str], cwd: pathlib.Path, timeout: float = 300, stderr_too: bool = False
) -> tuple[int, str, str]:
    """``tpm-viz ARGV`` with its stdout on a pseudo-terminal and its stderr on a pipe (``stderr_too``: on the
    terminal as well): status, what the terminal showed (newlines as written), stderr."""
    leader, follower = os.openpty()
    try:
        child = subprocess.Popen(
            [*installed(), *argv],
            stdout=follower,
            stderr=follower if stderr_too else subprocess.PIPE,
            stdin=subprocess.DEVNULL,
            cwd=cwd,
        )
    finally:
        os.close(follower)
    shown = bytearray()
    while True:  # read until the child's side closes (EIO on Linux), so the terminal never fills up
        try:
            chunk = os.read(leader, 65536)
        except OSError:
            break
        if not chunk:
            break
        shown += chunk
    os.close(leader)
    err = child.stderr.read().decode() if child.stderr else ""
    status = child.wait(timeout=timeout)
    return status, shown.decode().replace("\r\n", "\n"), err


@pytest.fixture(scope="module")
def terminal(tmp_path_factory) -> tuple[str, str, str]:
    """The quick comparison on a terminal, with ``--output``: (what the terminal showed, stderr, the CSV file)."""
    folder = tmp_path_factory.mktemp("compare")
    status, shown, err = on_terminal([*QUICK, "--output", "c.csv"], folder)
    assert status == 0, err
    return shown, err, (folder / "c.csv").read_text()


def _tables(shown: str) -> dict[str, tuple[list[str], list[str]]]:
    """``{title: (header line, body lines)}`` of the terminal's tables (a title line, names, units, dashes, rows)."""
    lines = shown.splitlines()
    out = {}
    for title in ("Designs", "Indices"):
        k = lines.index(title)
        end = next((j for j in range(k + 4, len(lines)) if not lines[j].strip()), len(lines))
        out[title] = (lines[k + 1], lines[k + 4 : end])
    return out


def _cells(header: str, line: str) -> dict[str, str]:
    """A body line's cells by heading: each column is right-aligned under the end of its heading."""
    names = [m for m in re.finditer(r"\S+(?: \S+)*", header)]
    cells = {}
    for m in names[2:]:
        cell = line[: m.end()].split("  ")[-1].strip()
        cells[m.group()] = cell
    return cells


@pytest.mark.end_to_end
def test_a_terminal_gets_the_table_in_mm_n_kg_s_equal_to_the_csv(terminal):
    shown, _, text = terminal
    rows = list(csv.DictReader(io.StringIO(text)))
    assert [(r["arrangement"], r["case"]) for r in rows] == [
        ("perpendicular", "given"),
        ("parallel", "given"),
        ("perpendicular", "optimum"),
        ("parallel", "optimum"),
    ]
    assert "designs/s" not in shown and "case,arrangement" not in shown  # progress and CSV stay off the table
    assert "nan" not in shown.lower()
    checked = 0
    for title, (header, body) in _tables(shown).items():
        assert len(body) == len(rows)
        for line, row in zip(body, rows, strict=True):
            assert line.split()[:2] == [row["arrangement"], row["case"]]
            if row[UNITS["a"][0]] == "" or (title == "Indices" and row["feasible"] != "1"):
                # no design (or no indices): why, never a number
                rest = line.split(None, 2)[2]
                assert not re.search(r"\d", rest), line
                assert rest.startswith("infeasible: " if title == "Indices" else "no design")
                continue
            for heading, cell in _cells(header, line).items():
                key, factor, decimals = UNITS[heading]
                assert float(cell) == pytest.approx(float(row[key]) * factor, abs=0.5 * 10**-decimals + 1e-9), heading
                assert len(cell.partition(".")[2]) == decimals, (heading, cell)
                checked += 1
    assert checked == 3 * 9 + 3 * 9  # three designs with dimensions, three with indices
    assert rows[3]["feasible"] == "0" and "infeasible: no design found within the limits" in shown


def test_a_pipe_gets_the_csv_that_output_writes_and_progress_goes_to_stderr(terminal, capsys):
    _, terminal_err, written = terminal
    piped = run(capsys, *QUICK)
    assert piped.returncode == 0
    assert piped.stdout == written  # the same CSV, byte for byte
    assert [r["case"] for r in csv.DictReader(io.StringIO(piped.stdout))] == ["given", "given", "optimum", "optimum"]
    assert "designs" not in piped.stdout
    for err in (piped.stderr, terminal_err):
        counts = [tuple(map(int, m)) for m in re.findall(r"\] (\d+)/(\d+) designs", err)]
        assert len(counts) >= 3 and counts[0][0] == 0
        done, total = counts[-1]
        assert done == total and all(d <= t for d, t in counts)
        assert [d for d, _ in counts] == sorted(d for d, _ in counts)
    # one generation: (1 + 1) populations of 75 (five free variables) per search, a polish of at most 120 designs
    # after the perpendicular one, none after the parallel one (nothing feasible)
    assert 2 * 2 * 75 < done <= 2 * 2 * 75 + 120


def test_docs_cli_shows_what_the_terminal_printed(terminal):
    shown = terminal[0]
    docs = (ROOT / "docs" / "cli.md").read_text()
    command = "tpm-viz " + " ".join(QUICK)
    assert command in docs
    block = docs.split(command, 1)[1].split("```", 1)[0]  # the lines after the command in its code block
    assert block.strip("\n") == shown.strip("\n")


def test_on_a_terminal_an_error_after_the_progress_bar_is_a_line_of_its_own(tmp_path):
    """The bar is drawn in place on a terminal; a refusal after it (here: the perpendicular design at ``a = 200 mm``
    covers no task, so there is no footprint to hold) starts a new line, and nothing is written."""
    argv = ["compare", "--task=-0.1,0.1,-0.05,0.05", "--hold", "footprint", "--set", "a=0.2", "--output", "c.csv"]
    status, shown, _ = on_terminal(argv, tmp_path, stderr_too=True)
    assert status == 2
    bar, error = shown.strip("\n").split("\n")
    assert bar.startswith("\r[") and "0/" in bar
    assert error.startswith("tpm-viz: error: --hold footprint needs the perpendicular design")
    assert not (tmp_path / "c.csv").exists()
