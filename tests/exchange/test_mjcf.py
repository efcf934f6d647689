"""The exported MJCF read back by Pinocchio 4.1 (``buildModelsAndConstraintsFromMJCF``) against the closed form.

Independent of :mod:`tpm_viz.multibody.model`: the tree, the inertias and the loop closures come from the file
only. Joint states come from the closed-form kinematics (:func:`tpm_viz.exchange.topology.joint_motion`);
the actuator forces from ``rnea`` projected on the null space ``N`` of the constraint Jacobian of the
file's constraints: ``(Nᵀ Sᵀ) τ = Nᵀ rnea(q, v, a)`` (λ eliminated, the method of the multibody model).
"""

from __future__ import annotations

import numpy as np
import pinocchio as pin
import pytest

import tpm_viz as tv
from tests.support.strategies import random_states
from tpm_viz.exchange.mjcf import mjcf_text
from tpm_viz.exchange.topology import JOINT_NAMES, joint_motion, joint_positions
from tpm_viz.multibody.rank import ranked_svd
from tpm_viz.paper.dynamics import inverse_dynamics

P = tv.Params.paper()
OTHER = P.replace(a=0.55, b=0.07, l_a=0.3, m_a=1.7, m_b=0.5, m_p=3.3, pivot_spacing=0.05)


class FromFile:
    """The model and constraints Pinocchio reads from the exported MJCF."""

    def __init__(self, path):
        self.model, found, self.collision, self.visual = pin.buildModelsAndConstraintsFromMJCF(
            str(path), constraints=True
        )
        self.constraints = list(found["point_anchor_constraint_models"])
        self.frame_constraints = list(found["frame_anchor_constraint_models"])
        self.data = self.model.createData()
        self.cdatas = [c.createData() for c in self.constraints]
        self.idx = [self.model.joints[self.model.getJointId(n)].idx_v for n in JOINT_NAMES]
        self.s_t = np.zeros((self.model.nv, 2))
        self.s_t[[self.idx[0], self.idx[4]], [0, 1]] = 1.0  # d1, d2: the actuated sliders

    def to_pin(self, x: np.ndarray) -> np.ndarray:
        """A vector in :data:`JOINT_NAMES` order rearranged into Pinocchio's ``v`` order."""
        out = np.empty(self.model.nv)
        out[self.idx] = x
        return out

    def closure(self, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Closure gaps (3 per constraint) [m] and the stacked constraint Jacobian (9, 7)."""
        m, d = self.model, self.data
        pin.computeJointJacobians(m, d, q)  # forward kinematics too; then calc, then the Jacobian
        gaps, rows = [], []
        for c, cd in zip(self.constraints, self.cdatas, strict=True):
            c.calc(m, d, cd)
            gaps.append(cd.oMc1.translation - cd.oMc2.translation)
            rows.append(pin.getConstraintJacobian(m, d, c, cd))
        return np.concatenate(gaps), np.vstack(rows)

    def closure_acceleration(self, q, v, a) -> np.ndarray:
        """Relative classical acceleration of each closure's two points (world) [m/s²]."""
        m, d = self.model, self.data
        pin.forwardKinematics(m, d, q, v, a)
        lwa = pin.LOCAL_WORLD_ALIGNED
        return np.concatenate(
            [
                pin.getFrameClassicalAcceleration(m, d, c.joint1_id, c.joint1_placement, lwa).linear
                - pin.getFrameClassicalAcceleration(m, d, c.joint2_id, c.joint2_placement, lwa).linear
                for c in self.constraints
            ]
        )

    def inverse_dynamics(self, params, p, dp, ddp) -> np.ndarray:
        q, v, a = (self.to_pin(x) for x in joint_motion(params, p, dp, ddp))
        _, jc = self.closure(q)
        svd = ranked_svd(jc)
        assert svd.rank == 5, svd.s  # 9 rows: 3 out of plane vanish, 1 in-plane row is redundant
        n = svd.null_space
        rhs = pin.rnea(self.model, self.data, q, v, a)
        return np.linalg.solve(n.T @ self.s_t, n.T @ rhs)


@pytest.fixture(scope="module")
def read_back(tmp_path_factory):
    models = {}
    for name, params in (("paper", P), ("other", OTHER)):
        path = tmp_path_factory.mktemp("mjcf") / f"{name}.xml"
        path.write_text(mjcf_text(params))
        models[name] = FromFile(path)
    return models


def test_pinocchio_reads_the_topology_masses_and_closures(read_back):
    fm = read_back["paper"]
    m = fm.model
    assert (m.nq, m.nv, m.njoints) == (7, 7, 8)
    assert [m.names[i] for i in range(1, m.njoints)] == list(JOINT_NAMES)  # depth-first, as in the model
    assert [type(j.extract()).__name__ for j in m.joints[1:]] == ["JointModelPX"] + ["JointModelRZ"] * 3 + [
        "JointModelPY"
    ] + ["JointModelRZ"] * 2
    moving = sum(m.inertias[i].mass for i in range(1, m.njoints))
    assert moving == pytest.approx(2 * P.m_a + 2 * P.m_b + P.m_p, rel=1e-12)
    rod = m.inertias[m.getJointId("phi1_0")]
    assert rod.mass == pytest.approx(P.m_b / 2)
    np.testing.assert_allclose(rod.lever, [P.l_a / 2, 0, 0], atol=1e-15)
    assert rod.inertia[2, 2] == pytest.approx(P.m_b / 2 * P.l_a**2 / 12, rel=1e-12)  # about its centre, Z
    platform = m.inertias[m.getJointId("phi_p")]
    np.testing.assert_allclose(platform.lever, [P.b, 0, 0], atol=1e-15)  # P is b from the hinge at B_1
    assert len(fm.constraints) == 3 and not fm.frame_constraints
    assert fm.visual.ngeoms == 2 + 2 + 4 + 1  # rails, sliders, links, platform (visual boxes)
    assert all(type(c).__name__ == "PointAnchorConstraintModel" for c in fm.constraints)
    # the sliders' ref (qpos0 is the assembled home pose, issue 27): Pinocchio 4.1's MJCF reader honours it in the
    # kinematics (the tests below) but shifts the range by -ref; the stroke is the range's width
    d_home = joint_positions(P, (0.0, 0.0))["d1"]
    assert m.upperPositionLimit[fm.idx[0]] == pytest.approx(P.stroke - d_home)
    assert m.upperPositionLimit[fm.idx[0]] - m.lowerPositionLimit[fm.idx[0]] == pytest.approx(P.stroke)


@pytest.mark.parametrize("which", ["paper", "other"])
def test_closures_hold_at_closed_form_states(read_back, which):
    fm, params = read_back[which], (P if which == "paper" else OTHER)
    worst = [0.0, 0.0, 0.0]
    for p, dp, ddp in random_states(params, 20, seed=1):
        q, v, a = (fm.to_pin(x) for x in joint_motion(params, p, dp, ddp))
        gaps, jc = fm.closure(q)
        worst[0] = max(worst[0], np.abs(gaps).max())
        worst[1] = max(worst[1], np.abs(jc @ v).max())
        worst[2] = max(worst[2], np.abs(fm.closure_acceleration(q, v, a)).max())
        platform = fm.data.oMi[fm.model.getJointId("phi_p")].act(np.array([params.b, 0.0, 0.0]))
        np.testing.assert_allclose(platform[:2], p, atol=1e-12)
    assert worst[0] < 1e-12 and worst[1] < 1e-12 and worst[2] < 1e-9, worst


@pytest.mark.parametrize(("which", "count"), [("paper", 100), ("other", 30)])
def test_constrained_inverse_dynamics_matches_the_closed_form(read_back, which, count):
    fm, params = read_back[which], (P if which == "paper" else OTHER)
    worst = 0.0
    for p, dp, ddp in random_states(params, count, seed=7):
        tau = fm.inverse_dynamics(params, p, dp, ddp)
        ref = inverse_dynamics(params, p, dp, ddp)
        worst = max(worst, float(np.max(np.abs(tau - ref) / (1.0 + np.abs(ref)))))
    print(f"{which}: max |Δτ|/(1 N + |τ|) = {worst:.2e} over {count} states")
    assert worst <= 1e-9
