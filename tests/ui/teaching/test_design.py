"""The *Design* tab without a browser (a served app and a protocol client): the heat map's cells hold the indices
:func:`tpm_viz.design.indices.evaluate` gives for those designs (called here directly), infeasible cells are grey and
say so without a number, a click on a cell, its column and row typed, or *Load best design* load that design into
the tab's mechanism, and the parallel mechanism is drawn where the closed-form kinematics of the issue put it."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from tests.support.protocol import wait_for
from tpm_viz import Params
from tpm_viz.core.errors import TpmVizError
from tpm_viz.core.words import Lang, T
from tpm_viz.design.indices import Task, evaluate
from tpm_viz.design.optimum import Search
from tpm_viz.paper.arrangement import Arrangement
from tpm_viz.ui.teaching.design import compare as design_compare
from tpm_viz.ui.teaching.design import text
from tpm_viz.ui.teaching.design.map import INFEASIBLE_COLOUR, Axis, MapSpec, best_cell, colours, prototype_at, ramp

P = Params.paper()
TASK = Task(-0.05, 0.05, -0.05, 0.05)
A_VALUES, L_VALUES = (0.42, 0.48, 0.54), (0.06, 0.18, 0.30)


def _expected(arrangement: Arrangement, a: float, l_a: float, task: Task):
    """The indices of one design, straight from the library (None: not even a valid geometry)."""
    try:
        params = P.replace(a=a, l_a=l_a)
    except TpmVizError:
        return None
    return evaluate(arrangement, params, task)


def _params(view) -> Params:
    with view.hub.lock:
        return view.session.state.params


def _picked(view) -> int | None:
    """The Design tab's picked cell once its description is written (both under the lock: the cell is picked, then
    described)."""
    with view.hub.lock:
        dv = view.teaching.design
        return dv.picked if dv.cell.content else None


def _computed(client, view, ranges: dict[str, str]):
    dv = view.teaching.design
    client.enter(dv.range_box, ranges)
    wait_for(lambda: dv.axes["x"][3] == int(ranges["x_count"]), timeout=30, what="the ranges applied")
    client.click(dv.compute)
    wait_for(lambda: dv.spec is not None and dv.done == dv.spec.size, timeout=60, what="the map computed")
    with view.hub.lock:  # the last chunk is drawn under the lock it was stored under
        return dv


def _click(client, name: str, k: int) -> None:
    owner = wait_for(lambda: next((o for (n, o) in client.nodes if n == name), None), timeout=30, what=f"{name} sent")
    client.send(
        type="SceneNodeClickMessage",
        name=name,
        instance_index=k,
        ray_origin=(0.0, 0.0, 1.0),
        ray_direction=(0.0, 0.0, -1.0),
        screen_pos=(0.5, 0.5),
        modifier=None,
        owner=owner,
    )


RANGES = {"x_from": "420", "x_to": "540", "x_count": "3", "y_from": "60", "y_to": "300", "y_count": "3"}


def test_the_map_is_the_library_at_every_cell_and_a_cell_loads_its_design(connect):
    client, view = connect()
    dv = _computed(client, view, RANGES)
    assert dv.spec.x.name == "a" and dv.spec.y.name == "l_a" and dv.spec.task == TASK
    expected = [_expected(Arrangement.PERPENDICULAR, a, l_a, TASK) for l_a in L_VALUES for a in A_VALUES]
    feasible = [k for k, e in enumerate(expected) if e is not None and e.feasible]
    assert 0 < len(feasible) < len(expected)  # both kinds on this map
    for k, (row, want) in enumerate(zip(dv.rows, expected, strict=True)):
        i, j = dv.spec.cell(k)
        assert math.isclose(row["a"], A_VALUES[i]) and math.isclose(row["l_a"], L_VALUES[j])
        assert bool(row["feasible"]) == (k in feasible)
        if k in feasible:
            for name in ("gci", "cond_max", "dyn_mean", "dyn_max", "peak_force", "cycle_time", "footprint_x"):
                assert row[name] == pytest.approx(getattr(want, name), rel=1e-12), name
    cells = dv.scene.cells
    grey = np.all(np.asarray(cells.batched_colors) == INFEASIBLE_COLOUR, axis=1)
    assert list(np.flatnonzero(~grey)) == feasible  # infeasible cells grey, every feasible one coloured
    gci = [expected[k].gci if k in feasible else -1.0 for k in range(len(expected))]
    assert f"{max(gci):.3f}" in dv.legend.content and "nan" not in dv.legend.content.lower()

    bad = next(k for k in range(len(expected)) if k not in feasible)
    before = _params(view)
    _click(client, "/design/map/cells", bad)  # an infeasible cell: picked, said so, not loaded
    wait_for(lambda: _picked(view) == bad, timeout=30, what="the infeasible cell picked and described")
    assert "infeasible" in dv.cell.content and not re.search(r"cell-\w+'>[\d.]", dv.cell.content)
    assert _params(view) == before

    k = feasible[0]
    _click(client, "/design/map/cells", k)
    i, j = dv.spec.cell(k)
    wait_for(lambda: _params(view).a == pytest.approx(A_VALUES[i]), timeout=30, what="the clicked design loaded")
    assert _params(view).l_a == pytest.approx(L_VALUES[j]) and _params(view).b == P.b
    assert f"{expected[k].gci:.3f}" in dv.cell.content

    k = feasible[-1]
    i, j = dv.spec.cell(k)
    client.enter(dv.pick_box, {"column": str(i + 1), "row": str(j + 1)})  # the keyboard way
    wait_for(lambda: _params(view).l_a == pytest.approx(L_VALUES[j]), timeout=30, what="the typed design loaded")
    assert _params(view).a == pytest.approx(A_VALUES[i])

    best = int(np.argmax(gci))
    client.click(dv.load_best)
    bi, bj = dv.spec.cell(best)
    wait_for(
        lambda: (_params(view).a, _params(view).l_a) == pytest.approx((A_VALUES[bi], L_VALUES[bj])),
        timeout=30,
        what="the best design loaded",
    )


def test_a_parallel_design_is_drawn_by_the_closed_form_kinematics(connect):
    client, view = connect()
    dv = view.teaching.design
    client.set_value(dv.arrangement, "parallel")  # the task keeps its size, centred on the parallel home
    wait_for(lambda: dv.task.y0 > 0, timeout=30, what="the task moved to the parallel home")
    dv = _computed(client, view, {**RANGES, "y_from": "200", "y_count": "2"})
    rows = dv.rows
    k = next(k for k, row in enumerate(rows) if row["feasible"])
    before = _params(view)
    client.enter(dv.pick_box, {"column": str(dv.spec.cell(k)[0] + 1), "row": str(dv.spec.cell(k)[1] + 1)})
    client.click(dv.load_cell)  # the typed column and row may be those shown: the button loads them
    wait_for(lambda: dv.loaded_parallel is not None, timeout=30, what="the parallel design loaded")
    assert _params(view) == before  # the live (perpendicular) mechanism is not changed by a parallel design
    drawing = dv.scene.drawings[Arrangement.PARALLEL]
    wait_for(lambda: drawing.params == dv.loaded_parallel, timeout=30, what="the parallel design drawn")
    a, b, l_a = rows[k]["a"], rows[k]["b"], rows[k]["l_a"]
    p1, p2 = dv.task.centre
    u = math.sqrt(l_a**2 - p2**2)  # the working mode, legs leaning inwards
    d1, d2 = p1 + a - b - u, -p1 + a - b - u
    a_pts, b_pts = (pts - drawing.offset for pts in drawing.joints)
    assert a_pts[:, :2] == pytest.approx(np.array([[d1 - a, 0.0], [a - d2, 0.0]]), abs=1e-12)
    assert b_pts[:, :2] == pytest.approx(np.array([[p1 - b, p2], [p1 + b, p2]]), abs=1e-12)
    perpendicular = dv.scene.drawings[Arrangement.PERPENDICULAR]  # the tab's mechanism beside it
    pa, pb = (pts - perpendicular.offset for pts in perpendicular.joints)
    assert pa[0, 1] == 0.0 and pa[1, 0] == 0.0  # A_1 on the X axis, A_2 on the Y axis
    assert np.linalg.norm(pb - pa, axis=1) == pytest.approx([before.l_a] * 2, rel=1e-12)


def test_the_colours_best_cell_and_prototype_of_a_map():
    spec = MapSpec(Arrangement.PERPENDICULAR, P, TASK, Axis("a", 0.40, 0.56, 5), Axis("l_a", 0.20, 0.30, 3))
    assert spec.overrides(spec.index_of(3, 2)) == {"a": pytest.approx(0.52), "l_a": pytest.approx(0.30)}
    assert prototype_at(spec) == pytest.approx((2.05, 1.2))  # a = 482 mm, l_a = 260 mm
    assert (
        prototype_at(MapSpec(Arrangement.PERPENDICULAR, P, TASK, Axis("a", 0.52, 0.6, 3), spec.y)) is None
    )  # 1.9 cells off
    vals = np.array([0.5, np.nan, 0.9, 0.7])
    cols, span = colours(vals, "gci")
    assert tuple(cols[1]) == INFEASIBLE_COLOUR and span == (0.5, 0.9)
    assert np.array_equal(cols[[0, 2]], ramp(np.array([0.0, 1.0])))  # worst dark, best yellow
    assert best_cell(vals, "gci") == 2 and best_cell(vals, "cycle_time") == 0
    assert best_cell(np.full(3, np.nan), "gci") is None
    for bad in (("a", 0.5, 0.4, 3), ("a", 0.4, 0.5, 16), ("a", -0.1, 0.5, 3), ("m_p", 1.0, 2.0, 2)):
        with pytest.raises(TpmVizError):
            Axis(*bad)
    with pytest.raises(TpmVizError):
        MapSpec(Arrangement.PERPENDICULAR, P, TASK, Axis("a", 0.4, 0.5, 2), Axis("a", 0.4, 0.5, 2))


@pytest.mark.slow  # a small search (the full one's optima are tests/cli/test_design.py's)
def test_the_comparison_table_and_drawings_hold_the_library_numbers(connect, monkeypatch):
    monkeypatch.setattr(design_compare, "SEARCH", Search(population=5, generations=3, polish=10))
    client, view = connect()
    dv = view.teaching.design
    client.click(dv.compare_button)  # hold the link length, the task of 100 x 100 mm
    wait_for(lambda: len(dv.compared) == 4 and dv.table.content, timeout=900, what="the comparison and its table")
    table = dv.table.content
    for n, kind in enumerate(Arrangement):  # the given rows: the task centred on each home pose
        mid = math.sqrt(P.l_a**2 - (P.a - P.b - P.stroke / 2) ** 2)  # parallel home: p1 = 0, sliders at mid-stroke
        home = (0.0, 0.0) if kind is Arrangement.PERPENDICULAR else (0.0, mid)
        want = evaluate(kind, P, TASK.centred_at(*home))
        assert want.feasible
        for key, fmt in (("gci", ".3f"), ("cond_max", ".2f"), ("peak_force", ".0f"), ("cycle_time", ".3f")):
            assert f"data-q='compare-{n}-{key}'>{format(getattr(want, key), fmt)}<" in table, (kind, key)
    assert "nan" not in table.lower() and "inf<" not in table
    drawn = {kind: d for kind, d in dv.scene.drawings.items() if d.node.visible}
    assert set(drawn) == set(Arrangement)
    for kind, drawing in drawn.items():  # each drawn with the given row's task, centred on its home pose
        assert drawing.params == P and drawing.task.width == pytest.approx(TASK.width)
        mid = math.sqrt(P.l_a**2 - (P.a - P.b - P.stroke / 2) ** 2)
        assert drawing.task.centre == pytest.approx([0.0, 0.0 if kind is Arrangement.PERPENDICULAR else mid])
    client.set_value(dv.case, "optimum")
    wait_for(lambda: dv.scene.drawings[Arrangement.PARALLEL].params != P, timeout=30, what="the optima drawn")


def test_a_comparison_leaves_the_fair_worker_to_the_other_tabs_between_its_batches(connect):
    """The comparison's search runs in its own thread and hands each batch of designs to the fair worker: another
    tab's map is computed while the comparison is still searching (before issue 35 the whole comparison was one job,
    and the map waited for it). Leaving the tab stops the search at its next batch."""
    first, first_view = connect()
    second, second_view = connect()
    comparing = first_view.teaching.design
    first.click(comparing.compare_button)
    wait_for(lambda: comparing.compare_note is not None, timeout=30, what="the comparison started")
    small = {**RANGES, "x_count": "2", "y_count": "2"}
    mapped = _computed(second, second_view, small)
    assert mapped.done == 4
    with first_view.hub.lock:
        assert comparing.compared == [] and comparing.compare_note is not None  # still searching


def test_the_texts_of_the_tab_in_korean_hold_the_numbers_and_no_nan():
    spec = MapSpec(Arrangement.PERPENDICULAR, P, TASK, Axis("a", 0.42, 0.54, 3), Axis("stroke", 0.2, 0.3, 2))
    rows = spec.rows(0, spec.size)
    good = next(k for k, r in enumerate(rows) if r["feasible"])
    want = evaluate(Arrangement.PERPENDICULAR, P.replace(**spec.overrides(good)), TASK)
    texts = [
        text.progress_html(3, 6, True, Lang.KO),
        text.legend_html("gci", (0.5, 0.9), 4, 6, Lang.KO),
        text.cell_html(spec, good, rows[good], Lang.KO),
        text.table_html(
            [{**rows[good], "case": "given"}, {"arrangement": "parallel", "feasible": 0.0}], T("footprint"), Lang.KO
        ),
    ]
    assert all(re.search("[\uac00-\ud7a3]", t) and "nan" not in t.lower() for t in texts)
    assert f"{want.gci:.3f}" in texts[2] and "Δd = 200.0 mm" in texts[2]
    assert f"data-q='compare-0-cycle_time'>{want.cycle_time:.3f}<" in texts[3]
    assert "compare-1-gci" not in texts[3]  # an infeasible column: a dash and why, never a number


def test_an_infeasible_cell_says_why_in_the_tabs_language():
    """A design whose task leaves the stroke: its cell and its comparison column give the reason in Korean, with the
    corner's coordinates (the library's grid corner, in mm) and no English words."""
    task = Task(-0.2, 0.2, -0.2, 0.2)
    spec = MapSpec(Arrangement.PERPENDICULAR, P, task, Axis("a", 0.42, 0.54, 2), Axis("stroke", 0.2, 0.3, 2))
    rows = spec.rows(0, spec.size)
    bad = next(k for k, r in enumerate(rows) if not r["feasible"])
    cell = text.cell_html(spec, bad, rows[bad], Lang.KO)
    table = text.table_html([{**rows[bad], "case": "given"}], T("footprint"), Lang.KO)
    for shown in (cell, table):
        reason = re.sub(r"<[^>]+>", " ", shown)
        assert "작업 영역을 덮지 못합니다" in reason and "-200.0" in reason
        assert not re.search(r"\b(task|covered|stroke|unreachable|mm is)\b", reason)
    assert "the task is not covered" in str(rows[bad]["why"])  # the CSV keeps English
