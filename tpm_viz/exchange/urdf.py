"""URDF text of the 2-PPa TPM: the tree of :mod:`tpm_viz.exchange.topology`, the inner loops as mimic joints.

URDF describes trees only. What the file holds (see :func:`urdf_text`):

- the same links, joints, masses and inertias as the MJCF (the fixed ``base`` is the root link);
- the parallelogram of each leg as mimic joints: ``phi1_1`` and ``phi2_1`` copy ``phi1_0`` and ``phi2_0``
  (multiplier 1) and the platform joint ``phi_p`` is ``-phi1_0`` (leg 1's parallelogram keeps the platform
  translating), so that the independent coordinates are ``(d1, phi1_0, d2, phi2_0)``;
- the one closure left, between leg 2 and the platform, in an XML comment: the point ``tip`` of ``link2_0``
  must coincide with the point ``B2`` of the platform (two in-plane equations; ``link2_1`` then closes by the
  mimic). Both points are also fixed, massless links (``link2_0_tip``, ``platform_B2``) so that a reader
  can impose the constraint between two frames.

A URDF child frame sits on its joint axis: the platform's link frame is at ``B_1 = P - b e_1`` (its centre of
mass at ``(b, 0, 0)``), not at ``P`` as in the MJCF. Units: SI, radians; ``rpy`` about fixed X, Y, Z.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.exchange.topology import Body, topology

__all__ = ["MIMIC", "urdf_text"]

MIMIC = {"phi_p": ("phi1_0", -1.0), "phi1_1": ("phi1_0", 1.0), "phi2_1": ("phi2_0", 1.0)}
"""``{mimic joint: (driving joint, multiplier)}`` (offset 0): the parallelograms' inner loops."""

_REVOLUTE_LIMIT = 0.5 * math.pi  # rad: the working mode keeps cos θ_i > 0 (eq. 4)
_EFFORT, _VELOCITY = 1e4, 10.0  # N (N m), m/s (rad/s): nominal limits, URDF requires them


def _fmt(*values: float) -> str:
    return " ".join(repr(float(v) + 0.0) for v in values)  # + 0.0: no "-0.0"


def _rotation(quat) -> np.ndarray:
    w, x, y, z = quat
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)],
            [2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)],
            [2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)],
        ]
    )


def _rpy(quat) -> tuple[float, float, float]:
    """Roll, pitch, yaw [rad] of a unit quaternion (w, x, y, z): ``R = Rz(yaw) Ry(pitch) Rx(roll)``."""
    r = _rotation(quat)
    pitch = math.asin(max(-1.0, min(1.0, -r[2, 0])))
    return math.atan2(r[2, 1], r[2, 2]), pitch, math.atan2(r[1, 0], r[0, 0])


def _offset(body: Body | None) -> np.ndarray:
    """Where a body's URDF frame is in its MJCF frame: on its joint axis (the joint's ``pos``)."""
    return np.zeros(3) if body is None or body.joint is None else np.asarray(body.joint.pos)


def _origin(parent: ET.Element, xyz, rpy=(0.0, 0.0, 0.0)) -> None:
    ET.SubElement(parent, "origin", xyz=_fmt(*xyz), rpy=_fmt(*rpy))


def _link(root: ET.Element, body: Body) -> None:
    el = ET.SubElement(root, "link", name=body.name)
    shift = _offset(body)
    if body.inertial is not None:
        i = body.inertial
        inertial = ET.SubElement(el, "inertial")
        _origin(inertial, np.asarray(i.com) - shift)
        ET.SubElement(inertial, "mass", value=_fmt(i.mass))
        ixx, iyy, izz = i.diag
        ET.SubElement(inertial, "inertia", ixx=_fmt(ixx), ixy="0", ixz="0", iyy=_fmt(iyy), iyz="0", izz=_fmt(izz))
    for box in body.boxes:
        visual = ET.SubElement(el, "visual")
        _origin(visual, np.asarray(box.pos) - shift)
        ET.SubElement(ET.SubElement(visual, "geometry"), "box", size=_fmt(*(2 * np.asarray(box.half))))
        ET.SubElement(ET.SubElement(visual, "material", name=f"{body.name}_colour"), "color", rgba=_fmt(*box.rgba))


def _joint(root: ET.Element, body: Body, parent: Body | None, stroke: float) -> None:
    j = body.joint
    assert j is not None, f"{body.name} is fixed to its parent: no joint to write"
    # Joint origin in the parent's URDF frame: the body's MJCF placement, moved onto the joint axis.
    xyz = np.asarray(body.pos) + _rotation(body.quat) @ _offset(body) - _offset(parent)
    kind = "prismatic" if j.kind == "slide" else "revolute"
    el = ET.SubElement(root, "joint", name=j.name, type=kind)
    _origin(el, xyz, _rpy(body.quat))
    ET.SubElement(el, "parent", link=body.parent)
    ET.SubElement(el, "child", link=body.name)
    ET.SubElement(el, "axis", xyz=_fmt(*j.axis))
    lower, upper = j.limits if j.limits is not None else (-_REVOLUTE_LIMIT, _REVOLUTE_LIMIT)
    ET.SubElement(el, "limit", lower=_fmt(lower), upper=_fmt(upper), effort=_fmt(_EFFORT), velocity=_fmt(_VELOCITY))
    if j.name in MIMIC:
        driver, multiplier = MIMIC[j.name]
        ET.SubElement(el, "mimic", joint=driver, multiplier=_fmt(multiplier), offset="0.0")


def _fixed_point(root: ET.Element, name: str, parent: Body, xyz) -> None:
    """A massless link ``name`` fixed at ``xyz`` [m] (MJCF body coordinates) of ``parent``."""
    ET.SubElement(root, "link", name=name)
    el = ET.SubElement(root, "joint", name=f"{name}_fixed", type="fixed")
    _origin(el, np.asarray(xyz) - _offset(parent))
    ET.SubElement(el, "parent", link=parent.name)
    ET.SubElement(el, "child", link=name)


def _closure_comment(params: Params, topo) -> str:
    link, platform = topo.body("link2_0"), topo.body("platform")
    tip = np.asarray(next(s.pos for s in link.sites if s.name == "link2_0_tip")) - _offset(link)
    b2 = np.asarray(next(s.pos for s in platform.sites if s.name == "platform_B2_0")) - _offset(platform)
    lines = [
        "2-PPa planar translational parallel manipulator (Pham & Kim 2013), written by tpm-viz (tpm-viz export).",
        "Parameters [SI]: " + ", ".join(f"{k}={getattr(params, k):g}" for k in PARAM_INFO) + ".",
        "URDF is a tree. Inner loops of the parallelograms as mimic joints (offset 0):",
        "  phi1_1 = phi1_0, phi2_1 = phi2_0 and phi_p = -phi1_0 (the platform translates);",
        "  phi1_k = theta_1, phi2_k = -theta_2; independent coordinates (d1, phi1_0, d2, phi2_0).",
        "LEG CLOSURE NOT IN THE TREE (impose it as a constraint, e.g. a point contact between frames):",
        f"  point {_fmt(*tip)} of link 'link2_0' (its tip, frame 'link2_0_tip')",
        f"  == point {_fmt(*b2)} of link 'platform' (B_2 = P - b e_2, frame 'platform_B2').",
        "  Two in-plane equations (the Z row vanishes); link2_1's tip then closes by the mimic.",
        "The platform link frame is at B_1 = P - b e_1 (on the joint axis); P is at (b, 0, 0) in it.",
        "Masses: sliders m_a and platform m_p point masses, links uniform rods m_b/2 with m l_a^2/12;",
        "zero moments written as m (1 mm)^2. Effort and velocity limits are nominal.",
    ]
    return "\n" + "\n".join(f"  {line}" for line in lines) + "\n"


def urdf_text(params: Params) -> str:
    """The URDF document of ``params`` (see the module docstring)."""
    if not isinstance(params, Params):
        raise InputError(f"urdf_text needs a tpm_viz.Params, got {type(params).__name__}")
    topo = topology(params)
    root = ET.Element("robot", name="tpm_2ppa")
    root.append(ET.Comment(_closure_comment(params, topo)))
    by_name = {b.name: b for b in topo.bodies}
    for body in topo.bodies:
        _link(root, body)
        if body.joint is not None:
            _joint(root, body, by_name.get(body.parent), params.stroke)
    link, platform = by_name["link2_0"], by_name["platform"]
    _fixed_point(root, "link2_0_tip", link, next(s.pos for s in link.sites if s.name == "link2_0_tip"))
    _fixed_point(root, "platform_B2", platform, next(s.pos for s in platform.sites if s.name == "platform_B2_0"))
    ET.indent(root, space="  ")
    return '<?xml version="1.0"?>\n' + ET.tostring(root, encoding="unicode") + "\n"
