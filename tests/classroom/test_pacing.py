"""The pacing of own copies under load (tpm_viz.classroom.pacing), against a simulated class: N students dragging their
own copies at the browser's 20 Hz, each commit costing c seconds of the one core. The load the pacer settles on is
checked against the budget it was given, and the interval against the closed form N c / budget."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from tests.support.hypo import examples
from tpm_viz.classroom.pacing import WATCH_INTERVAL, WATCH_TABS, Pacer, watch_phase, watch_slot


def _simulate(pacer: Pacer, students: int, cost: float, seconds: float, rate: float = 20.0) -> list[float]:
    """Commits happen at most every pacer.interval() per student and at most at the input rate; returns the load
    (fraction of one core) measured in each second."""
    dt = 1.0 / rate
    next_at = [k * dt / students for k in range(students)]  # staggered
    loads, busy, t = [], 0.0, 0.0
    second_end = 1.0
    while t < seconds:
        t += dt / 4
        for k in range(students):
            if t >= next_at[k]:
                pacer.spent(cost, t)
                busy += cost
                next_at[k] = t + max(dt, pacer.interval(t))
        if t >= second_end:
            loads.append(busy)
            busy, second_end = 0.0, second_end + 1.0
    return loads


def test_a_light_class_is_never_paced():
    pacer = Pacer(budget=0.4)
    loads = _simulate(pacer, students=5, cost=0.002, seconds=5)  # 5 x 20 Hz x 2 ms = 0.2 of a core
    assert pacer.interval(5.0) == 0.0
    assert loads[-1] == pytest.approx(5 * 20 * 0.002, rel=0.1)


@settings(max_examples=examples(25), deadline=None)
@given(students=st.integers(10, 60), cost=st.floats(0.001, 0.004))
def test_an_overloaded_class_settles_at_the_budget(students, cost):
    demand = students * 20 * cost
    pacer = Pacer(budget=0.4)
    loads = _simulate(pacer, students, cost, seconds=12)
    if demand <= 0.4:
        assert pacer.interval(12.0) == 0.0
        return
    settled = sum(loads[-4:]) / 4
    if demand < 1.5 * 0.4:  # near the budget the 20 Hz input itself caps the rate: only the load is defined
        assert settled <= 1.3 * 0.4
        return
    expected_interval = min(pacer.ceiling, students * cost / 0.4)  # N c / budget
    assert settled == pytest.approx(students * cost / expected_interval, rel=0.3)  # the budget, unless at the ceiling
    assert pacer.interval(12.0) == pytest.approx(expected_interval, rel=0.3)


def test_the_pacing_ends_when_the_class_stops_dragging():
    pacer = Pacer(budget=0.4)
    _simulate(pacer, students=40, cost=0.003, seconds=5)
    assert pacer.interval(5.0) > 0.1
    for k in range(6):  # nobody drags: windows with no commit at all
        pacer.spent(0.0, 5.0 + 0.6 * (k + 1))
    assert pacer.interval(9.0) == 0.0
    assert math.isclose(pacer.load(9.0), 0.0, abs_tol=1e-12)


def _watch(tabs: int, seconds: float = 8.0, rate: float = 20.0) -> tuple[list[int], list[int]]:
    """A drag committed at ``rate`` Hz, watched by ``tabs`` tabs (phases of tabs numbered 0..tabs-1, as they joined):
    returns how many tabs draw at each commit and how many times each tab drew."""
    phases = [watch_phase(k) for k in range(tabs)]
    slots: list[int | None] = [None] * tabs
    per_commit, per_tab = [], [0] * tabs
    for n in range(int(seconds * rate)):
        now = 1000.0 + (n + 0.5) / rate  # commits mid-way between slot edges of phase 0 (no rounding luck)
        drawn = 0
        for k in range(tabs):
            slot = watch_slot(now, tabs, phases[k])
            if slot != slots[k]:
                slots[k], drawn, per_tab[k] = slot, drawn + 1, per_tab[k] + (n > 0)
        per_commit.append(drawn)
    return per_commit[1:], per_tab  # not the first commit: it draws everybody (nobody has a slot yet)


@pytest.mark.parametrize("tabs", [1, 10, 30, 60, 150])
def test_watching_tabs_draw_in_turn_at_the_rate_their_number_allows(tabs):
    per_commit, per_tab = _watch(tabs)
    interval = WATCH_INTERVAL * max(1.0, (tabs / WATCH_TABS) ** 2)  # the documented rule, written out
    expected = 8.0 / interval  # draws per tab over 8 s
    assert all(abs(count - expected) <= 1.5 for count in per_tab)
    fair_share = tabs * (1 / 20.0) / interval  # tabs per commit if spread evenly
    assert max(per_commit) <= math.ceil(fair_share) + 2  # never the whole hall at one commit
    if tabs >= 60:
        assert max(per_commit) <= tabs // 3  # (all at once before: each commit drew none or all of them)


def test_phases_of_consecutive_tabs_are_spread_evenly():
    for tabs in (2, 7, 30, 150):
        phases = sorted(watch_phase(k) for k in range(tabs))
        gaps = [b - a for a, b in zip(phases, [*phases[1:], phases[0] + 1.0], strict=True)]
        assert max(gaps) < 3.0 / tabs  # the three-gap theorem: no gap above ~2.6 / tabs
