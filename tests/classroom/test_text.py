"""Formatting of the panel (tpm_viz.classroom.text): units, guards against NaN and infinity, banner levels."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.app.moves import Pose
from tpm_viz.app.poses import preset_pose
from tpm_viz.app.readouts import Forces, Load, evaluate
from tpm_viz.app.state import AppState
from tpm_viz.classroom.text import banner_level, dashboard_html, force_scale, legend_html, num

P = Params.paper()


@pytest.mark.parametrize("bad", [None, math.nan, math.inf, -math.inf, "x"])
def test_num_never_prints_nan_or_inf(bad):
    assert num(bad) == "—"


def test_num_scales_and_drops_negative_zero():
    assert num(0.1234, ".1f", 1e3) == "123.4"
    assert num(-1e-9, ".1f") == "0.0"
    assert num(-0.0, ".1e") == "0.0e+00"


def test_force_scale_is_1_2_5():
    assert force_scale([3.0]) == 10.0
    assert force_scale([-56.3, 68.8]) == 100.0
    assert force_scale([180.0, None, math.nan]) == 200.0
    assert force_scale([501.0]) == 1000.0


def _values(html: str) -> dict[str, str]:
    return dict(re.findall(r'data-q="(\w+)"[^>]*>([^<]*)<', html))


def test_dashboard_shows_every_quantity_with_units():
    state = AppState.initial(P).replace(load=Load("static", f_ext=(0.0, -20.0)))
    html = dashboard_html(state, evaluate(P, state.pose, state.load))
    v = _values(html)
    assert v["p1"] == "0.0" and v["d1"] == "130.0" and v["theta1"] == "0.00"
    assert v["det_jx"] == "1.0000" and v["det_jq"] == "1.0000" and v["cond"] == "1.00"
    assert v["tau2"] == "20.00" and v["tau2_ref"] == "—"
    for unit in ("mm", "deg", " N", "eq. 12", "eq. 11", "eq. 10"):
        assert unit in html
    assert "External load" in html or "external load on platform f_ext" in html


def test_dashboard_with_missing_forces_prints_dashes_not_nan():
    state = AppState.initial(P)
    readout = evaluate(P, state.pose)
    broken = type(readout)(**{**readout.__dict__, "forces": Forces(None, None, "eq. 31", "singular"), "cond": None})
    html = dashboard_html(state, broken)
    assert "nan" not in html.lower() and "inf" not in html.lower().replace("info", "")
    assert _values(html)["tau1"] == "—" and _values(html)["cond"] == "—"
    assert "singular" in html


@pytest.mark.parametrize("kind", ["inverse", "direct", "stroke"])
def test_banner_level_follows_the_alerts(kind):
    pose = preset_pose(P, kind).pose
    readout = evaluate(P, pose)
    assert banner_level(readout) == kind
    assert f'data-level="{kind}"' in dashboard_html(AppState(params=P, pose=pose), readout)


def test_banner_shows_the_move_note_and_regular_pose():
    state = AppState(params=P, pose=Pose.working(P, np.zeros(2)), note="stopped: actuator 1 reached the end")
    html = dashboard_html(state, evaluate(P, state.pose))
    assert "Regular pose" in html and "stopped: actuator 1" in html


def test_legend_names_every_colour():
    html = legend_html()
    for word in ("workspace", "inverse singularity", "direct singularity", "stroke end", "assembly mode"):
        assert word in html
