"""The exported URDF: its XML (links, joints, mimic joints, masses, the closure comment) and Pinocchio reading it.

With ``mimic=True`` Pinocchio keeps the four independent coordinates ``(d1, phi1_0, d2, phi2_0)``; adding the
leg closure documented in the file (frames ``link2_0_tip`` and ``platform_B2``) as a point constraint and
projecting ``rnea`` on its null space reproduces the paper's closed-form forces.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pinocchio as pin
import pytest

import tpm_viz as tv
from tests.support.strategies import random_states
from tpm_viz.exchange.topology import joint_motion
from tpm_viz.exchange.urdf import MIMIC, urdf_text
from tpm_viz.multibody.rank import ranked_svd
from tpm_viz.paper.dynamics import inverse_dynamics

P = tv.Params.paper()
OTHER = P.replace(a=0.55, b=0.07, l_a=0.3, m_a=1.7, m_b=0.5, m_p=3.3, pivot_spacing=0.05)
INDEPENDENT = ("d1", "phi1_0", "d2", "phi2_0")
SELECT = [0, 1, 4, 5]  # their places in JOINT_NAMES order


@pytest.mark.parametrize("params", [P, OTHER], ids=["paper", "other"])
def test_urdf_xml_has_the_tree_the_mimic_joints_and_the_masses(params):
    text = urdf_text(params)
    root = ET.fromstring(text)
    links = {el.get("name"): el for el in root.findall("link")}
    joints = {el.get("name"): el for el in root.findall("joint")}
    assert len(links) == 10  # base, 2 sliders, 4 links, platform + the two closure points
    assert len(joints) == 9  # 7 moving + 2 fixed closure points
    kinds = {name: el.get("type") for name, el in joints.items()}
    assert [n for n, k in kinds.items() if k == "prismatic"] == ["d1", "d2"]
    assert sorted(n for n, k in kinds.items() if k == "revolute") == sorted(
        ["phi1_0", "phi_p", "phi1_1", "phi2_0", "phi2_1"]
    )
    mimics = {n: el.find("mimic") for n, el in joints.items() if el.find("mimic") is not None}
    assert {n: (m.get("joint"), float(m.get("multiplier")), float(m.get("offset"))) for n, m in mimics.items()} == {
        n: (driver, k, 0.0) for n, (driver, k) in MIMIC.items()
    }
    moving = sum(
        float(el.find("inertial/mass").get("value"))
        for n, el in links.items()
        if el.find("inertial") is not None and n != "base"
    )
    assert moving == pytest.approx(2 * params.m_a + 2 * params.m_b + params.m_p, rel=1e-12)
    assert float(joints["d1"].find("limit").get("upper")) == pytest.approx(params.stroke)
    comment = text[text.index("<!--") : text.index("-->")]
    assert "LEG CLOSURE NOT IN THE TREE" in comment and "link2_0_tip" in comment and "platform_B2" in comment


class UrdfModel:
    def __init__(self, params, mimic: bool):
        self.params = params
        self.model = pin.buildModelFromXML(urdf_text(params), mimic=mimic)
        self.model.gravity = pin.Motion.Zero()
        self.data = self.model.createData()
        self.mimic = mimic
        names = INDEPENDENT if mimic else ("d1", "phi1_0", "phi_p", "phi1_1", "d2", "phi2_0", "phi2_1")
        self.iq = [self.model.joints[self.model.getJointId(n)].idx_q for n in names]
        self.iv = [self.model.joints[self.model.getJointId(n)].idx_v for n in names]
        self.tip, self.b2 = self.model.getFrameId("link2_0_tip"), self.model.getFrameId("platform_B2")

    def state(self, p, dp=(0.0, 0.0), ddp=(0.0, 0.0)):
        out = []
        for x in joint_motion(self.params, p, dp, ddp):
            y = np.zeros(self.model.nv)
            y[self.iv] = x[SELECT] if self.mimic else x
            out.append(y)
        return out

    def closure(self, q):
        """Gap [m] of the documented leg closure and its Jacobian (3, nv)."""
        m, d, lwa = self.model, self.data, pin.LOCAL_WORLD_ALIGNED
        pin.computeJointJacobians(m, d, q)
        pin.updateFramePlacements(m, d)
        gap = d.oMf[self.tip].translation - d.oMf[self.b2].translation
        jac = pin.getFrameJacobian(m, d, self.tip, lwa)[:3] - pin.getFrameJacobian(m, d, self.b2, lwa)[:3]
        return gap, jac


@pytest.mark.parametrize("mimic", [True, False])
def test_pinocchio_reads_the_urdf_and_the_documented_closure_holds(mimic):
    um = UrdfModel(P, mimic)
    assert (um.model.nq, um.model.nv) == ((4, 4) if mimic else (7, 7))
    mass = sum(um.model.inertias[i].mass for i in range(1, um.model.njoints))
    assert mass == pytest.approx(2 * P.m_a + 2 * P.m_b + P.m_p, rel=1e-12)
    for p, _, _ in random_states(P, 20, seed=5):
        q, _, _ = um.state(p)
        gap, _ = um.closure(q)
        assert np.abs(gap).max() < 1e-12
        platform = um.data.oMi[um.model.getJointId("phi_p")].act(np.array([P.b, 0.0, 0.0]))
        np.testing.assert_allclose(platform[:2], p, atol=1e-12)  # the platform frame is at B_1
        b11 = um.data.oMf[um.model.getFrameId("link1_1")].act(np.array([P.l_a, 0.0, 0.0]))
        np.testing.assert_allclose(b11[:2], p + np.array([-P.b, P.pivot_spacing]), atol=1e-12)  # closed by the mimic


@pytest.mark.parametrize("params", [P, OTHER], ids=["paper", "other"])
def test_mimic_tree_plus_documented_closure_gives_the_closed_form_forces(params):
    um = UrdfModel(params, mimic=True)
    s_t = np.zeros((um.model.nv, 2))
    s_t[[um.iv[0], um.iv[2]], [0, 1]] = 1.0
    worst = 0.0
    for p, dp, ddp in random_states(params, 50, seed=11):
        q, v, a = um.state(p, dp, ddp)
        _, jac = um.closure(q)
        svd = ranked_svd(jac)
        assert svd.rank == 2  # the Z row vanishes
        assert np.abs(jac @ v).max() < 1e-12
        n = svd.null_space
        tau = np.linalg.solve(n.T @ s_t, n.T @ pin.rnea(um.model, um.data, q, v, a))
        ref = inverse_dynamics(params, p, dp, ddp)
        worst = max(worst, float(np.max(np.abs(tau - ref) / (1.0 + np.abs(ref)))))
    print(f"URDF (mimic) + leg closure: max |Δτ|/(1 N + |τ|) = {worst:.2e}")
    assert worst <= 1e-9
