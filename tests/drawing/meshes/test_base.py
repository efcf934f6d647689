"""The parts both arrangements share (tpm_viz.drawing.meshes.base): sizes follow the parameters, the links sit on
their pivots wherever posed_parts places either mechanism, the parts are stacked in Z, the scene's helpers."""

from __future__ import annotations

import numpy as np
import pytest

from tpm_viz import Params, mechanism_pose
from tpm_viz.drawing import meshes as m
from tpm_viz.paper import arrangement as arr
from tpm_viz.paper.arrangement import Arrangement

P = Params.paper()


def _quat_rotate(wxyz: np.ndarray, v: np.ndarray) -> np.ndarray:
    w, x, y, z = wxyz
    r = np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )
    return r @ v


def test_link_length_is_l_a():
    bounds = m.link(P.replace(l_a=0.3, pivot_spacing=0.05)).bounds
    assert bounds[1, 0] - bounds[0, 0] == pytest.approx(0.3 + m.base.LINK_WIDTH)


def test_link_instances_run_from_slider_pivot_to_platform_pivot():
    pose = mechanism_pose(P, np.array([0.06, -0.04]))
    positions, wxyzs = m.link_instances(pose)
    ends = pose.links.reshape(4, 2, 2)
    for k in range(4):
        tip = positions[k] + _quat_rotate(wxyzs[k], np.array([P.l_a, 0.0, 0.0]))
        np.testing.assert_allclose(positions[k, :2], ends[k, 0], atol=1e-12)
        np.testing.assert_allclose(tip[:2], ends[k, 1], atol=1e-12)


@pytest.mark.parametrize(
    ("arrangement", "p"),
    [
        (Arrangement.PERPENDICULAR, (0.0, 0.0)),
        (Arrangement.PERPENDICULAR, (0.06, -0.04)),
        (Arrangement.PARALLEL, (0.0, 0.1)),
        (Arrangement.PARALLEL, (0.1, 0.2)),
        (Arrangement.PARALLEL, (-0.12, 0.05)),
    ],
)
def test_posed_links_run_between_their_pins(arrangement, p):
    """Each posed link spans its two pivots of the arrangement's pose (eq. 1 / P1), a pin stands on every pivot."""
    parts = m.posed_parts(arrangement, P, p)
    pose = arr.mechanism_pose(arrangement, P, p)
    pins = parts["pins"].vertices
    for k, name in enumerate(m.LINK_NAMES):
        start, end = pose.links.reshape(4, 2, 2)[k]
        axis = (end - start) / np.linalg.norm(end - start)
        rel = parts[name].vertices[:, :2] - start
        along = rel @ axis
        across = rel @ np.array([-axis[1], axis[0]])
        assert along.min() == pytest.approx(-m.base.LINK_WIDTH / 2, abs=1e-9)
        assert along.max() == pytest.approx(P.l_a + m.base.LINK_WIDTH / 2, abs=1e-9)
        assert np.abs(across).max() <= m.base.LINK_WIDTH / 2 + 1e-9
        for pivot in (start, end):  # a pin stands on each pivot
            assert np.min(np.linalg.norm(pins[:, :2] - pivot, axis=1)) <= m.base.PIN_RADIUS + 1e-9
    for i in (0, 1):  # the sliders at A_i, the platform and the tool at P
        np.testing.assert_allclose(
            parts[f"slider{i + 1}"].bounds.mean(axis=0)[:2] - pose.A[i],
            m.parts_of(arrangement).slider(P, i).bounds.mean(axis=0)[:2],
            atol=1e-12,
        )
    np.testing.assert_allclose(parts["tool"].bounds.mean(axis=0)[:2], p, atol=1e-12)


def test_parts_are_stacked_in_z_without_overlap():
    assert m.RAIL_Z[1] <= m.SLIDER_Z[0]
    assert m.SLIDER_Z[1] < min(m.LINK_Z) - m.base.LINK_THICKNESS / 2
    assert abs(m.LINK_Z[1] - m.LINK_Z[0]) > m.base.LINK_THICKNESS
    assert max(m.LINK_Z) + m.base.LINK_THICKNESS / 2 < m.PLATFORM_Z[0]


def test_segments_helpers():
    circle = m.circle_segments(0.2, 0.01, n=16)
    assert circle.shape == (16, 2, 3)
    np.testing.assert_allclose(np.linalg.norm(circle[:, 0, :2], axis=-1), 0.2)
    segs = m.polyline_segments([np.zeros((3, 2)), np.zeros((1, 2))], 0.0)
    assert segs.shape == (2, 2, 3)
    assert m.polyline_segments([], 0.0).shape == (0, 2, 3)


def test_workspace_region_covers_exactly_the_in_stroke_poses():
    """The floor overlay, probed at random points, agrees with eq. (4) and the stroke (not only with the mask)."""
    from tpm_viz import in_stroke, inverse_kinematics, reachable, workspace_map
    from tpm_viz.drawing.meshes import region_mesh

    P = Params.paper()
    ws = workspace_map(P, n=120)
    mesh = region_mesh(ws.in_stroke, ws.xs, ws.ys, 0.0)
    rng = np.random.default_rng(5)
    pts = rng.uniform(-P.l_a, P.l_a, size=(400, 2))
    half_cell = ws.xs[1] - ws.xs[0]
    tri = mesh.triangles[:, :, :2]  # (F, 3, 2), flat at z = 0

    def cross(o, a, b):
        return (a[..., 0] - o[..., 0]) * (b[..., 1] - o[..., 1]) - (a[..., 1] - o[..., 1]) * (b[..., 0] - o[..., 0])

    q = pts[:, None, :]  # (N, 1, 2) against (F, ...)
    s0, s1, s2 = (cross(tri[None, :, k], tri[None, :, (k + 1) % 3], q) for k in range(3))
    inside = np.any(((s0 >= 0) & (s1 >= 0) & (s2 >= 0)) | ((s0 <= 0) & (s1 <= 0) & (s2 <= 0)), axis=1)
    truth = reachable(P, pts)
    truth &= in_stroke(P, inverse_kinematics(P, np.where(truth[:, None], pts, 0.0)))
    # points farther than a cell from the boundary must agree; e.g. (-0.17, -0.17) is in, (0.2, -0.2) is out
    far = np.array([_far_from_boundary(P, p, half_cell) for p in pts])
    assert np.array_equal(np.array(inside)[far], truth[far])
    assert far.sum() > 300


def _far_from_boundary(P, p, r) -> bool:
    from tpm_viz import in_stroke, inverse_kinematics, reachable

    probe = p + r * np.array([[1, 0], [-1, 0], [0, 1], [0, -1], [1, 1], [-1, -1], [1, -1], [-1, 1], [0, 0]])
    ok = reachable(P, probe)
    state = ok & in_stroke(P, inverse_kinematics(P, np.where(ok[:, None], probe, 0.0)))
    return bool(state.all() or (~state).all())
