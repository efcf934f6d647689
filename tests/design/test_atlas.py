"""The atlas (tpm_viz/design/atlas.py): the grid, the process pool against one process and its size (never more
processes than chunks or cores), the Pareto front against a plain double loop, the local and the global optimiser
within their bounds and limits and never worse than their start."""

from __future__ import annotations

import math
from typing import ClassVar

import numpy as np
import pytest

from tpm_viz.core.params import Params
from tpm_viz.design import atlas
from tpm_viz.design.atlas import (
    Limits,
    Vary,
    best,
    columns_for,
    design_row,
    designs,
    pareto,
    pool_size,
    sweep,
    values_of,
)
from tpm_viz.design.indices import INDEX_COLUMNS, Settings, Task
from tpm_viz.design.optimum import Search, optimise, search
from tpm_viz.paper.arrangement import Arrangement

TASK = Task(-0.1, 0.1, -0.05, 0.05)
FAST = Settings(planner_grid=60)


def test_vary_gives_count_values_with_both_ends_and_the_grid_is_row_major():
    assert Vary.parse("l_a=0.2:0.3:3").values.tolist() == pytest.approx([0.2, 0.25, 0.3])
    grid = designs([Vary.parse("a=0.4:0.5:2"), Vary.parse("l_a=0.2:0.3:3")])
    pairs = np.array([(g["a"], g["l_a"]) for g in grid])
    expected = np.array([(0.4, 0.2), (0.4, 0.25), (0.4, 0.3), (0.5, 0.2), (0.5, 0.25), (0.5, 0.3)])
    np.testing.assert_allclose(pairs, expected, rtol=1e-12)
    assert columns_for(["m_b", "a"])[:6] == ["arrangement", "a", "b", "l_a", "stroke", "m_b"]
    assert columns_for([])[5:] == list(INDEX_COLUMNS)


@pytest.mark.parametrize(
    ("text", "match"),
    [
        ("x=1:2:3", "NAME one of"),
        ("a=1:2", "START:STOP:COUNT"),
        ("a=1:2:0", "COUNT from 1"),
        ("a=nan:2:3", "finite"),
        ("a", "NAME=START"),
    ],
)
def test_a_bad_vary_is_refused_in_one_line(text, match):
    with pytest.raises(ValueError, match=match):
        Vary.parse(text)


def test_a_grid_too_large_or_repeated_is_refused():
    with pytest.raises(ValueError, match="too many"):
        designs([Vary.parse("a=0.4:0.5:10000"), Vary.parse("b=0.05:0.1:10000"), Vary.parse("l_a=0.2:0.3:20")])
    with pytest.raises(ValueError, match="varied once"):
        designs([Vary.parse("a=0.4:0.5:2"), Vary.parse("a=0.4:0.5:2")])


def test_the_process_pool_gives_the_rows_of_one_process_in_order():
    grid = designs([Vary.parse("l_a=0.15:0.35:3"), Vary.parse("stroke=0.2:0.4:2")])
    seen: list[tuple[int, int]] = []
    one = sweep(Arrangement.PERPENDICULAR, Params.paper(), grid, TASK, FAST, workers=1)
    two = sweep(
        Arrangement.PERPENDICULAR,
        Params.paper(),
        grid,
        TASK,
        FAST,
        workers=2,
        progress=lambda d, t: seen.append((d, t)),
    )
    assert seen[-1] == (len(grid), len(grid))
    assert [r["l_a"] for r in two] == [g["l_a"] for g in grid]
    for a, b in zip(one, two, strict=True):
        assert a.keys() == b.keys()
        for key in a:
            assert (a[key] == b[key]) or (isinstance(a[key], float) and math.isnan(a[key]) and math.isnan(b[key]))
    assert any(r["feasible"] for r in one) and not all(r["feasible"] for r in one)


def test_an_invalid_parameter_set_is_an_infeasible_row():
    row = design_row("perpendicular", values_of(Params.paper()), {"l_a": -1.0}, (-0.1, 0.1, -0.05, 0.05), FAST)
    assert row["feasible"] == 0.0 and "positive" in str(row["why"])
    assert all(math.isnan(float(row[k])) for k in INDEX_COLUMNS if k != "feasible")


def test_the_pareto_front_matches_a_double_loop():
    rng = np.random.default_rng(3)
    rows = [
        {
            "feasible": bool(rng.random() < 0.8),
            "gci": float(rng.integers(0, 5)),
            "cycle_time": float(rng.integers(0, 5)),
            "footprint_x": float(rng.integers(1, 4)),
            "footprint_y": 1.0,
        }
        for _ in range(300)
    ]

    def key(r):
        return (-r["gci"], r["cycle_time"], r["footprint_x"] * r["footprint_y"])

    expected = []
    for r in rows:
        dominated = any(
            o["feasible"] and all(x <= y for x, y in zip(key(o), key(r), strict=True)) and key(o) != key(r)
            for o in rows
        )
        expected.append(r["feasible"] and not dominated)
    assert pareto(rows).tolist() == expected


def test_the_optimum_is_within_bounds_and_limits_and_no_slower_than_the_best_grid_point():
    grid = designs([Vary.parse("l_a=0.2:0.32:3"), Vary.parse("stroke=0.25:0.4:3")])
    rows = sweep(Arrangement.PERPENDICULAR, Params.paper(), grid, TASK, FAST, workers=1)
    limits = Limits(footprint_x=0.6, footprint_y=0.6)
    k = best(rows, limits)
    assert k is not None
    bounds = {"l_a": (0.2, 0.32), "stroke": (0.25, 0.4)}
    found = optimise(
        Arrangement.PERPENDICULAR,
        values_of(Params.paper()),
        {"l_a": rows[k]["l_a"], "stroke": rows[k]["stroke"]},
        bounds,
        TASK,
        FAST,
        limits,
        max_evaluations=30,
    )
    assert found["feasible"] and limits.allows(found)
    assert found["cycle_time"] <= rows[k]["cycle_time"]
    assert all(lo <= found[name] <= hi for name, (lo, hi) in bounds.items())
    allowed = [r for r in rows if limits.allows(r)]
    assert rows[k]["cycle_time"] == min(r["cycle_time"] for r in allowed)


def test_the_global_search_from_the_best_grid_point_is_no_slower_and_within_bounds_and_limits():
    grid = designs([Vary.parse("l_a=0.2:0.32:3"), Vary.parse("stroke=0.25:0.4:3")])
    rows = sweep(Arrangement.PERPENDICULAR, Params.paper(), grid, TASK, FAST, workers=1)
    limits = Limits(footprint_x=0.6, footprint_y=0.6)
    k = best(rows, limits)
    assert k is not None
    bounds = {"l_a": (0.2, 0.32), "stroke": (0.25, 0.4)}
    start = {"l_a": rows[k]["l_a"], "stroke": rows[k]["stroke"]}
    how = Search(population=5, generations=5, polish=20)
    found = search(
        Arrangement.PERPENDICULAR, values_of(Params.paper()), bounds, TASK, FAST, limits, how=how, starts=[start]
    )
    assert found is not None and found["feasible"] and limits.allows(found)
    assert found["cycle_time"] <= rows[k]["cycle_time"]
    assert all(lo <= found[name] <= hi for name, (lo, hi) in bounds.items())


class _Pool:
    """A stand-in for ProcessPoolExecutor that records its size and maps in this process."""

    sizes: ClassVar[list[int]] = []

    def __init__(self, max_workers: int) -> None:
        _Pool.sizes.append(max_workers)

    def __enter__(self):
        return self

    def __exit__(self, *exc) -> None:
        return None

    def map(self, fn, jobs):
        return map(fn, jobs)


@pytest.mark.parametrize(
    ("asked", "designs_n", "cores", "expected"), [(1000, 4, 2, 1), (1000, 20, 2, 2), (None, 20, 64, 3), (2, 40, 64, 2)]
)
def test_the_pool_has_no_more_processes_than_chunks_or_cores(monkeypatch, asked, designs_n, cores, expected):
    """``--workers 1000`` with 4 designs forked up to 1,024 processes (issue 35): the pool is one per chunk of 8
    designs and per core at most (one process: no pool at all)."""
    monkeypatch.setattr(atlas, "cores", lambda: cores)
    monkeypatch.setattr(atlas, "ProcessPoolExecutor", _Pool)
    monkeypatch.setattr(atlas, "run_chunk", lambda job: [{"n": len(job[2])}] * len(job[2]))
    _Pool.sizes = []
    assert pool_size(asked, -(-designs_n // 8)) == expected
    grid = [{"l_a": 0.26}] * designs_n
    rows = sweep(Arrangement.PERPENDICULAR, Params.paper(), grid, TASK, FAST, workers=asked)
    assert len(rows) == designs_n
    assert _Pool.sizes == ([] if expected == 1 else [expected])
