"""``tpm-viz design | compare | atlas``: the CSV columns, empty cells for an infeasible design, one-line refusals
with status 2, the atlas's prototype and optimum rows; the comparison tables of docs/design.md are the rows stored in
``docs/data/compare-*.csv``, each stored design's indices are its own (evaluated again here), and ``tpm-viz compare``
reproduces the stored files (``heavy``: ``python -m pytest -m heavy``)."""

from __future__ import annotations

import csv
import io
import math
import pathlib
import re

import pytest

from tpm_viz.cli import main
from tpm_viz.core.params import Params
from tpm_viz.design import atlas
from tpm_viz.design.indices import Settings, Task
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

ROOT = pathlib.Path(__file__).resolve().parents[2]
COLUMNS = (
    "arrangement,a,b,l_a,stroke,feasible,gci,cond_max,dyn_mean,dyn_max,peak_force,cycle_time,moving_mass,"
    "footprint_x,footprint_y"
).split(",")


def _rows(path: pathlib.Path) -> list[dict[str, str]]:
    return list(csv.DictReader(io.StringIO(path.read_text())))


def test_design_writes_one_row_of_indices_in_si(tmp_path, capsys):
    out = tmp_path / "d.csv"
    assert main(["design", "--task=-0.1,0.1,-0.05,0.05", "--set", "m_p=3", "--output", str(out)]) == 0
    (row,) = _rows(out)
    assert list(row) == COLUMNS
    assert row["arrangement"] == "perpendicular" and row["feasible"] == "1"
    assert float(row["moving_mass"]) == pytest.approx(2 * 0.95 + 2 * 0.84 + 3.0)  # Table 2 with m_p = 3 kg
    assert 0 < float(row["gci"]) <= 1 <= float(row["cond_max"])
    assert float(row["dyn_mean"]) <= float(row["dyn_max"])
    assert 0.1 < float(row["cycle_time"]) < 10 and float(row["footprint_x"]) > 0.2


def test_an_infeasible_design_is_a_row_of_empty_cells_never_nan(tmp_path, capsys):
    out = tmp_path / "d.csv"
    argv = ["design", "--arrangement", "parallel", "--task=-0.1,0.1,-0.05,0.05", "--output", str(out)]
    assert main(argv) == 0
    (row,) = _rows(out)
    assert row["feasible"] == "0" and row["l_a"] == "0.26000000000000001"
    assert all(row[k] == "" for k in COLUMNS[6:])
    assert "nan" not in out.read_text().lower()
    assert "infeasible" in capsys.readouterr().err


@pytest.mark.parametrize(
    ("argv", "match"),
    [
        (["design", "--task=0.1,-0.1,0,0.1"], "X0 < X1"),
        (["design", "--task=0,1,2"], "four numbers"),
        (["design", "--task=-0.1,0.1,-0.05,0.05", "--set", "l_a=-1"], "l_a"),
        (["design", "--task=-0.1,0.1,-0.05,0.05", "--force-limit", "-5"], "force-limit"),
        (["design", "--arrangement", "diagonal", "--task=0,1,0,1"], "invalid choice"),
        (["atlas", "--vary", "q=1:2:3", "--task=-0.1,0.1,-0.05,0.05", "--output", "x.csv"], "NAME one of"),
        (
            ["atlas", "--vary", "a=1:2:3", "--task=-0.1,0.1,-0.05,0.05", "--output", "x.csv", "--workers", "0"],
            "workers",
        ),
        (["atlas", "--vary", "a=1:2:3", "--task=-0.1,0.1,-0.05,0.05", "--output", "x.csv", "--footprint", "1"], "X,Y"),
        (
            ["atlas", "--vary", "a=0.4:0.5:2", "--task=-0.1,0.1,-0.05,0.05", "--output", "x.csv", "--scheduler", "x"],
            "tcp://",
        ),
        (["compare", "--task=-0.1,0.1,-0.05,0.05", "--hold", "volume"], "invalid choice"),
        (["compare", "--task=-0.1,0.1,-0.05,0.05", "--seed", "-1"], "--seed"),
        (["compare", "--task=-0.1,0.1,-0.05,0.05", "--generations", "0"], "--generations"),
    ],
)
def test_bad_input_is_one_line_and_status_2(argv, match, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("tpm-viz: error:") and re.search(match, err)
    assert not (tmp_path / "x.csv").exists()


def test_atlas_marks_the_front_the_prototype_and_the_optimum(tmp_path, capsys):
    out = tmp_path / "atlas.csv"
    argv = ["atlas", "--vary", "l_a=0.18:0.34:3", "--vary", "stroke=0.2:0.4:3", "--task=-0.1,0.1,-0.05,0.05"]
    argv += ["--grid", "60", "--workers", "1", "--footprint", "0.6,0.6", "--generations", "3", "--output", str(out)]
    assert main(argv) == 0
    rows = _rows(out)
    assert list(rows[0])[: len(COLUMNS)] == COLUMNS and list(rows[0])[-2:] == ["pareto", "tag"]
    grid, prototype, optimum = rows[:9], rows[9], rows[10]
    firsts = [float(r[k]) for r in grid[:4] for k in ("l_a", "stroke")]
    assert firsts == pytest.approx([0.18, 0.2, 0.18, 0.3, 0.18, 0.4, 0.26, 0.2])  # the last --vary fastest
    assert prototype["tag"] == "prototype" and prototype["l_a"] == "0.26000000000000001"
    assert optimum["tag"] == "optimum" and optimum["feasible"] == "1"
    feasible = [r for r in grid if r["feasible"] == "1"]
    assert feasible and len(feasible) < 9
    assert all(all(r[k] == "" for k in COLUMNS[6:]) and r["pareto"] == "0" for r in grid if r["feasible"] == "0")
    allowed = [r for r in feasible if float(r["footprint_x"]) <= 0.6 and float(r["footprint_y"]) <= 0.6]
    assert float(optimum["cycle_time"]) <= min(float(r["cycle_time"]) for r in allowed)
    assert float(optimum["footprint_x"]) <= 0.6 and float(optimum["footprint_y"]) <= 0.6
    assert any(r["pareto"] == "1" for r in feasible)
    err = capsys.readouterr().err
    assert "9/9 designs" in err and f"{len(feasible)} feasible" in err


def test_atlas_starts_no_more_processes_than_chunks_of_designs(tmp_path, monkeypatch, capsys):
    """``--workers 1000`` with 4 designs (one chunk of 8): no process pool at all (issue 35: it forked up to 1,024);
    ``--help`` says so."""

    def no_pool(*args, **kwargs):
        raise AssertionError("a process pool was started for one chunk")

    monkeypatch.setattr(atlas, "ProcessPoolExecutor", no_pool)
    out = tmp_path / "a.csv"
    argv = ["atlas", "--vary", "l_a=0.2:0.3:4", "--task=-0.1,0.1,-0.05,0.05", "--workers", "1000", "--no-optimum"]
    assert main([*argv, "--grid", "60", "--output", str(out)]) == 0
    assert len(_rows(out)) == 5  # four designs and the prototype
    with pytest.raises(SystemExit):
        main(["atlas", "--help"])
    assert "never more than the cores or the chunks of 8 designs" in " ".join(capsys.readouterr().out.split())


def table_lines(rows: list[dict[str, str]], hold: str) -> list[str]:
    """The comparison table as docs/design.md prints it (mm, N, ms; words for no design)."""
    out = []
    for r in rows:
        if r["feasible"] != "1":
            words = "does not cover the task" if r["case"] == "given" else "none found within the hold"
            out.append(f"| {hold} | {r['case']} | {r['arrangement']} | {words} | | | | | | |")
            continue
        f = {k: float(v) for k, v in r.items() if k not in ("case", "arrangement")}
        out.append(
            f"| {hold} | {r['case']} | {r['arrangement']} | {f['a'] * 1e3:.0f} / {f['l_a'] * 1e3:.0f} / "
            f"{f['stroke'] * 1e3:.0f} | {f['gci']:.3f} | {f['cond_max']:.2f} | {f['dyn_max']:.2f} | "
            f"{f['peak_force']:.0f} | {f['cycle_time'] * 1e3:.0f} | {f['footprint_x'] * 1e3:.0f} × "
            f"{f['footprint_y'] * 1e3:.0f} |"
        )
    return out


COMPARISONS = {
    "link": ["--task=-0.1,0.1,-0.05,0.05", "--hold", "link"],
    "footprint": ["--task=-0.1,0.1,-0.05,0.05", "--hold", "footprint"],
    "mass": ["--task=-0.1,0.1,-0.05,0.05", "--hold", "mass"],
    "link, pick y": ["--task=-0.05,0.05,-0.1,0.1", "--pick", "y", "--hold", "link"],
}
"""The comparisons docs/design.md prints (label: the command's options)."""
STORED = {
    label: ROOT / "docs" / "data" / f"compare-{label.replace(', ', '-').replace(' ', '-')}.csv" for label in COMPARISONS
}
"""What each comparison printed (``tpm-viz compare OPTIONS --output FILE``), the rows its docs table shows."""
INDICES = "gci,cond_max,dyn_mean,dyn_max,peak_force,cycle_time,moving_mass,footprint_x,footprint_y".split(",")
CASES = [("given", "perpendicular"), ("given", "parallel"), ("optimum", "perpendicular"), ("optimum", "parallel")]


@pytest.mark.parametrize("label", list(COMPARISONS))
def test_every_stored_comparison_row_is_its_designs_indices(label):
    """Each stored design, evaluated again here (its parameters over the paper's, its task where the row says, or,
    for a given design that covers no task, centred on its home pose), has the stored indices; a row without a
    design has no number at all."""
    pick = "y" if "--pick" in COMPARISONS[label] else "x"
    rows = _rows(STORED[label])
    assert [(r["case"], r["arrangement"]) for r in rows] == CASES
    for row in rows:
        if row["a"] == "":  # no design found: every cell but its names empty
            assert row["feasible"] == "0" and row["case"] == "optimum"
            assert all(v == "" for k, v in row.items() if k not in ("case", "arrangement", "feasible"))
            continue
        values = {**atlas.values_of(Params.paper()), **{k: float(row[k]) for k in ("a", "b", "l_a", "stroke", "m_b")}}
        if row["task_x0"] != "":
            box = tuple(float(row[k]) for k in ("task_x0", "task_x1", "task_y0", "task_y1"))
        else:
            assert row["case"] == "given"
            task = Task.parse(COMPARISONS[label][0].removeprefix("--task="))
            centre = arr.home(Arrangement.parse(row["arrangement"]), Params(**values))
            placed = task.centred_at(float(centre[0]), float(centre[1]))
            box = (placed.x0, placed.x1, placed.y0, placed.y1)
        again = atlas.design_row(row["arrangement"], values, {}, box, Settings(pick=pick))
        assert int(again["feasible"]) == int(row["feasible"]), row
        for key in INDICES:
            if row["feasible"] == "1":
                assert float(again[key]) == pytest.approx(float(row[key]), rel=1e-9), (row["case"], key)
            else:
                assert row[key] == "" and math.isnan(float(again[key]))


@pytest.mark.parametrize("label", list(COMPARISONS))
def test_the_comparison_tables_in_the_docs_are_the_stored_rows(label):
    """Every run of the label's lines in docs/design.md (its overview table and the comparison's) is the stored
    rows, formatted as the docs show them, in order."""
    lines = table_lines(_rows(STORED[label]), label)
    runs: list[list[str]] = []
    after = False
    for line in (ROOT / "docs" / "design.md").read_text().splitlines():
        ours = line.startswith(f"| {label} |")
        if ours and not after:
            runs.append([])
        if ours:
            runs[-1].append(line)
        after = ours
    assert runs and all(run == lines for run in runs), runs


@pytest.mark.heavy  # minutes each: two global searches
@pytest.mark.parametrize("label", list(COMPARISONS))
def test_compare_reproduces_the_stored_comparisons(label, tmp_path):
    out = tmp_path / "compare.csv"
    assert main(["compare", *COMPARISONS[label], "--output", str(out)]) == 0
    fresh, stored = _rows(out), _rows(STORED[label])
    assert list(fresh[0]) == list(stored[0])
    for new, old in zip(fresh, stored, strict=True):
        for key, value in old.items():
            if key in ("case", "arrangement", "feasible") or value == "":
                assert new[key] == value, (new["case"], new["arrangement"], key)
            else:
                assert float(new[key]) == pytest.approx(float(value), rel=1e-6), (new["case"], key)
