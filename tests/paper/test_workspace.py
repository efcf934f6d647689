"""Workspace maps and singularity loci against the angle formulas (sin θ1 = p2/l_a, sin θ2 = p1/l_a)."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params, inverse_kinematics, workspace_map
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.workspace import direct_singularity_locus, inverse_singularity_loci, stroke_limit_loci

P = Params.paper()


def test_map_values_are_the_formulas_at_grid_points():
    m = workspace_map(P, n=41)
    rng = np.random.default_rng(3)
    for _ in range(50):
        iy, ix = rng.integers(0, 41, size=2)
        p1, p2 = m.xs[ix], m.ys[iy]
        if max(abs(p1), abs(p2)) >= P.l_a:
            assert not m.reachable[iy, ix] and np.isnan(m.det_jx[iy, ix])
            continue
        th1, th2 = np.arcsin(p2 / P.l_a), np.arcsin(p1 / P.l_a)
        assert m.det_jx[iy, ix] == pytest.approx(np.cos(th1 + th2), abs=1e-12)
        assert m.det_jq[iy, ix] == pytest.approx(np.cos(th1) * np.cos(th2), abs=1e-12)
        j = np.array([[1, np.tan(th1)], [np.tan(th2), 1]])
        assert m.cond[iy, ix] == pytest.approx(np.linalg.cond(j), rel=1e-9)
        d = P.a - P.b + np.array([p1, p2]) - P.l_a * np.cos([th1, th2])
        assert m.in_stroke[iy, ix] == bool(np.all((d >= 0) & (d <= P.stroke)))


def test_direct_locus_has_zero_det_jx():
    for arc in direct_singularity_locus(P, n=30):
        inner = arc[1:-1] * (1 - 1e-12)
        assert np.abs(jacobians(P, inner).det_jx) == pytest.approx(np.zeros(28), abs=1e-5)


def test_inverse_loci_bound_the_reachable_square():
    for seg in inverse_singularity_loci(P):
        assert np.all(np.abs(seg).max(axis=1) == pytest.approx(P.l_a))
    p = np.array([0.0, P.l_a * (1 - 1e-9)])
    assert abs(float(jacobians(P, p).det_jq)) < 1e-4


def test_stroke_loci_sit_on_the_stroke_limits():
    curves = stroke_limit_loci(P, n=50)
    assert len(curves) >= 2
    for pts in curves:
        inside = pts[np.all(np.abs(pts) < P.l_a * 0.999, axis=1)]
        d = inverse_kinematics(P, inside)
        at_limit = np.minimum(np.abs(d), np.abs(d - P.stroke)).min(axis=1)
        assert at_limit == pytest.approx(np.zeros(len(inside)), abs=1e-12)
