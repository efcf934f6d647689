"""Counting a comparison's designs for its progress line (tpm_viz/design/tally.py): the count is every design the
searches evaluate (counted here by a second wrapper), the total the budget still open (worked out here by hand for a
scripted run), and the rows are the same with or without the tally."""

from __future__ import annotations

import numpy as np

from tpm_viz.core.params import Params
from tpm_viz.design.compare import Hold, compare, populations
from tpm_viz.design.indices import Settings, Task
from tpm_viz.design.optimum import Search
from tpm_viz.design.tally import Tally


class _Problem:
    """A stand-in for a search's problem: only its bound ``cost`` matters to the tally."""

    def cost(self, x: np.ndarray) -> float:
        return float(np.sum(x))


def test_the_total_is_the_count_plus_the_budget_still_open():
    how = Search(generations=4, polish=3)  # a search of population 5: at most 5 * 5 DE designs, then 3
    seen: list[tuple[int, int]] = []
    tally = Tally([5, 5], how, lambda done, total: seen.append((done, total)))
    assert tally.total == 2 * (25 + 3)
    one, two = _Problem(), _Problem()
    batch = [np.zeros(2)] * 5
    for _ in range(3):  # the first search's members agree after two generations
        assert tally(one.cost, batch) == [0.0] * 5
    tally(one.cost, [np.ones(2)])  # its polish: two designs of three
    tally(one.cost, [np.ones(2)])
    for _ in range(2):  # the second finds nothing feasible: no polish
        tally(two.cost, batch)
    tally.finish()
    assert seen == [
        (5, 5 + 20 + 3 + 28),
        (10, 10 + 15 + 3 + 28),
        (15, 15 + 10 + 3 + 28),
        (16, 16 + 2 + 28),  # the rest of the first population's budget is gone
        (17, 17 + 1 + 28),
        (22, 22 + 20 + 3),  # so is the rest of its polish
        (27, 27 + 15 + 3),
        (27, 27),
    ]


def test_a_tallied_comparison_counts_every_design_and_gives_the_same_rows():
    params, task, hold = Params.paper(), Task(-0.1, 0.1, -0.05, 0.05), Hold.LINK
    settings, how = Settings(planner_grid=60), Search(generations=1)
    counted: list[int] = []

    def inner(cost, points):
        counted.append(len(points))
        return [cost(x) for x in points]

    seen: list[tuple[int, int]] = []
    tally = Tally(populations(params, hold, how), how, lambda d, t: seen.append((d, t)), inner)
    assert tally.total == 2 * ((1 + 1) * 15 * 4 + 120)  # a, the stroke and where the task stands: 4 variables
    tallied = compare(params, task, hold, settings, how, evaluate=tally)
    tally.finish()
    plain = compare(params, task, hold, settings, how)
    assert [{k: v for k, v in r.items() if k != "why"} for r in tallied] == [
        {k: v for k, v in r.items() if k != "why"} for r in plain
    ]
    assert seen[-1] == (sum(counted), sum(counted))
    assert all(d <= t for d, t in seen) and [d for d, _ in seen] == sorted(d for d, _ in seen)
    assert counted.count(60) == 4  # two populations of 60 per search
