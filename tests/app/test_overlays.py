"""The explorer's overlays (tpm_viz.app.overlays, workspace_area) against the formulas: map pixels against eqs.
(4), (10), (12) at their grid points, orientation, transparency where nothing exists, no NaN in any image, the
ellipses against J. No viser."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import InputError, Params
from tpm_viz.app.overlays import (
    _DIVERGING,
    _SEQUENTIAL,
    ALPHA,
    COND_MAX,
    MAP_KINDS,
    cached_map,
    colour_scale,
    ellipse_polylines,
    map_rgba,
)
from tpm_viz.paper.jacobians import jacobians
from tpm_viz.paper.workspace import workspace_area, workspace_map

P = Params.paper()


def _colour(value, stops) -> np.ndarray:
    xs = [s[0] for s in stops]
    cs = np.array([s[1] for s in stops], dtype=float)
    v = float(np.clip(value, xs[0], xs[-1]))
    return np.array([np.interp(v, xs, cs[:, k]) for k in range(3)])


@pytest.mark.parametrize("kind", [k for k in MAP_KINDS if k != "off"])
def test_images_are_uint8_rgba_with_unreachable_cells_transparent(kind):
    ws = workspace_map(P, n=41)
    img = map_rgba(ws, kind)
    assert img.shape == (41, 41, 4) and img.dtype == np.uint8 and img.flags.c_contiguous
    assert np.all(img[..., 3][~ws.reachable] == 0)
    assert np.all(img[..., 3][ws.in_stroke] == ALPHA)
    faint = ws.reachable & ~ws.in_stroke
    assert np.all((img[..., 3][faint] > 0) & (img[..., 3][faint] < ALPHA))


def test_pixel_k_i_is_the_grid_point_xs_i_ys_k_with_the_formula_colour():
    ws = workspace_map(P, n=61)
    det, cond = map_rgba(ws, "det_jx"), map_rgba(ws, "cond")
    rng = np.random.default_rng(7)
    checked = 0
    for _ in range(300):
        k, i = rng.integers(0, 61, size=2)
        p1, p2 = ws.xs[i], ws.ys[k]
        if max(abs(p1), abs(p2)) >= P.l_a:
            continue
        th1, th2 = np.arcsin(p2 / P.l_a), np.arcsin(p1 / P.l_a)  # sin θ1 = p2 / l_a, sin θ2 = p1 / l_a
        assert det[k, i, :3] == pytest.approx(_colour(np.cos(th1 + th2), _DIVERGING), abs=0.51)
        j = np.array([[1, np.tan(th1)], [np.tan(th2), 1]])
        assert cond[k, i, :3] == pytest.approx(_colour(np.log10(np.linalg.cond(j)), _SEQUENTIAL), abs=0.51)
        checked += 1
    assert checked > 150


def test_the_workspace_map_is_green_exactly_inside_the_stroke_and_not_mirrored():
    ws = workspace_map(P, n=81)
    img = map_rgba(ws, "workspace")
    green = (img[..., 1] > 150) & (img[..., 0] < 100) & (img[..., 3] > 0)
    np.testing.assert_array_equal(green, ws.in_stroke)
    # The in-stroke region reaches into the third quadrant's corner (d_i ~ 70 mm there), not the second's.
    k3, i3 = np.searchsorted(ws.ys, -0.24), np.searchsorted(ws.xs, -0.24)
    k2 = np.searchsorted(ws.ys, 0.24)
    assert green[k3, i3] and not green[k2, i3]


def test_det_map_is_white_on_the_direct_singularity_arcs_and_cond_saturates_there():
    ws = workspace_map(P, n=201)
    det, cond = map_rgba(ws, "det_jx"), map_rgba(ws, "cond")
    near = np.abs(ws.det_jx) < 0.02
    assert near.any()
    assert np.all(det[near][:, :3].astype(int).min(axis=-1) > 230)  # white band
    assert np.all(np.abs(cond[near][:, :3].astype(int) - _SEQUENTIAL[-1][1]).max(axis=-1) <= 40)
    assert np.isfinite(ws.cond).sum() < ws.cond.size and COND_MAX == 100.0


def test_off_is_fully_transparent_and_unknown_kinds_are_refused():
    assert not map_rgba(workspace_map(P, n=11), "off")[..., 3].any()
    with pytest.raises(InputError):
        map_rgba(workspace_map(P, n=11), "temperature")
    for kind in MAP_KINDS:
        scale = colour_scale(kind)
        assert all(c.startswith("#") and len(c) == 7 for _, c in scale.stops)


def test_cached_map_is_computed_once_and_read_only():
    a, b = cached_map(P), cached_map(P)
    assert a is b and a.det_jx.shape == (200, 200)
    with pytest.raises(ValueError):
        a.det_jx[0, 0] = 1.0


def test_workspace_area_of_the_reachable_square_and_the_stroke():
    ws = workspace_map(P, n=301)
    assert workspace_area(ws, "reachable") == pytest.approx((2 * P.l_a) ** 2, rel=0.02)
    fine = workspace_area(workspace_map(P, n=601))
    assert workspace_area(ws) == pytest.approx(fine, rel=0.01)
    small = P.replace(l_a=0.2)
    assert workspace_area(workspace_map(small, n=301)) < 0.85 * fine
    with pytest.raises(InputError):
        workspace_area(ws, "everything")


@pytest.mark.parametrize("p", [(0.0, 0.0), (0.05, -0.08), (-0.12, 0.1), (-0.17, -0.17)])
def test_ellipse_outlines_satisfy_their_definitions_with_j(p):
    scale = 0.1
    drawing = ellipse_polylines(P, p, scale=scale, cap=1e9)
    j = jacobians(P, np.array(p)).j
    vel = drawing.velocity[:-1] / scale
    assert np.linalg.norm(vel @ j.T, axis=1) == pytest.approx(np.ones(len(vel)), rel=1e-9)  # |J ṗ| = 1
    force = drawing.force[:-1] / scale
    tau = np.linalg.solve(j.T, force.T).T
    assert np.linalg.norm(tau, axis=1) == pytest.approx(np.ones(len(tau)), rel=1e-9)  # f = Jᵀτ, |τ| = 1
    sv = np.linalg.svd(j, compute_uv=False)
    assert sorted(drawing.force_radii) == pytest.approx(sorted(sv))
    assert sorted(drawing.velocity_radii) == pytest.approx(sorted(1 / sv))
    assert not drawing.clipped


def test_ellipses_are_clipped_for_drawing_and_hidden_at_singular_poses():
    drawing = ellipse_polylines(P, (-0.2252, -0.2582), scale=0.1, cap=3.0)
    assert drawing.clipped and max(drawing.force_radii) > 3.0
    assert np.max(np.linalg.norm(drawing.force, axis=1)) <= 0.3 + 1e-12
    arc = P.l_a * np.array([np.cos(-2.2), np.sin(-2.2)])  # on the quadrant-III arc: det J_x = 0
    assert ellipse_polylines(P, arc, scale=0.1) is None
    assert ellipse_polylines(P, (0.0, P.l_a), scale=0.1) is None  # cos θ1 = 0
