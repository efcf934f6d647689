"""Parts of the parallel mechanism (tpm_viz.drawing.meshes.parallel): sliders between the stops, the platform over its
pins, the base under everything."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params
from tpm_viz.drawing import meshes as m
from tpm_viz.drawing.meshes import parallel as mp
from tpm_viz.paper import parallel as par
from tpm_viz.paper.arrangement import Arrangement

P = Params.paper()


@pytest.mark.parametrize("i", [0, 1])
def test_sliders_touch_the_stops_at_both_ends_of_the_stroke(i):
    """Rail 1: d_1 = 0 at the outer (left) stop; rail 2: d_2 = 0 at the outer (right) stop."""
    stops = mp.end_stops(P, i).bounds[:, 0]
    inner_left, inner_right = stops[0] + 0.012, stops[1] - 0.012
    for d_i in (0.0, P.stroke):
        a_x = d_i - P.a if i == 0 else P.a - d_i
        lo, hi = mp.slider(P, i).bounds[:, 0] + a_x
        outer = (d_i == 0.0) == (i == 0)  # leg 1 at d = 0 or leg 2 at d = Δd: at the left stop
        assert (lo if outer else hi) == pytest.approx(inner_left if outer else inner_right, abs=1e-12)
        rail = mp.rail(P, i).bounds[:, 0]
        assert rail[0] < lo and hi < rail[1]


def test_platform_covers_its_pins_and_the_base_covers_everything():
    plate = mp.platform(P).bounds
    offsets = mp.platform_pin_offsets(P)
    assert np.all(offsets[:, :2] > plate[0, :2]) and np.all(offsets[:, :2] < plate[1, :2])
    home = par.home(P)
    lo, hi = mp.base_extent(P)
    for mesh in m.posed_parts(Arrangement.PARALLEL, P, home).values():
        assert np.all(mesh.bounds[0, :2] >= lo - 1e-9) and np.all(mesh.bounds[1, :2] <= hi + 1e-9)
    z = {name: mesh.bounds[:, 2] for name, mesh in m.posed_parts(Arrangement.PARALLEL, P, home).items()}
    assert z["rail1"][1] <= z["slider1"][0] + 1e-12 and z["slider1"][1] < z["link1_0"][0]
    assert z["link2_0"][1] < z["platform"][0]
