"""The Pinocchio pieces both arrangements' closed-loop models are built from (:mod:`.model`, :mod:`.parallel`).

Placements in the plane, the inertias of the mass model (docs/conventions.md: sliders and platform as point masses,
each link a uniform slender rod), and :func:`closed_tree`: a depth-first tree of joints and bodies, one frame per
part and the loop closures at the link tips. Each arrangement gives only its own tree and attachment points. SI
units: metres, kilograms, radians.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import pinocchio as pin
from numpy.typing import ArrayLike

from tpm_viz.core.params import Params

__all__ = ["Built", "TreeRow", "closed_tree", "point_mass", "rod", "se3"]

TreeRow = tuple[str, str, Any, Any, Any]
"""``(name, parent, joint model, placement in the parent, body inertia)`` (Pinocchio ships no types)."""

Built = tuple[Any, list[Any], dict[str, int]]
"""``(pinocchio.Model, its RigidConstraintModel closures, the frame id of each part)``."""


def se3(xyz: ArrayLike, angle: float = 0.0) -> pin.SE3:
    """The placement at ``xyz`` [m], turned by ``angle`` [rad] about z."""
    c, s = np.cos(angle), np.sin(angle)
    return pin.SE3(np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]]), np.asarray(xyz, dtype=float))


def rod(mass: float, length: float) -> pin.Inertia:
    """Uniform slender rod along local x from the origin: COM at ``l/2``, ``I = m l²/12`` (y, z)."""
    i_t = mass * length**2 / 12.0
    return pin.Inertia(mass, np.array([length / 2.0, 0.0, 0.0]), np.diag([0.0, i_t, i_t]))


def point_mass(mass: float, xyz: ArrayLike = (0.0, 0.0, 0.0)) -> pin.Inertia:
    """A point mass [kg] at ``xyz`` [m] of its joint's frame (no rotational inertia)."""
    return pin.Inertia(mass, np.asarray(xyz, dtype=float), np.zeros((3, 3)))


def closed_tree(params: Params, tree: list[TreeRow], on_platform: dict[str, list[float]]) -> Built:
    """The gravity-free model of ``tree`` (depth-first: Pinocchio's ``crba`` needs every subtree contiguous in
    ``v``), a frame per part (the platform's at ``P = B_1 + b e_1``) and one ``CONTACT_3D`` closure
    (``LOCAL_WORLD_ALIGNED``) per entry of ``on_platform``: the tip of that link (``l_a`` along its x axis) on the
    platform point given [m, from ``B_1``]."""
    model = pin.Model()
    model.gravity = pin.Motion.Zero()  # horizontal mechanism, U = 0
    joints = {"universe": 0}
    for name, parent, joint, placement, inertia in tree:
        joints[name] = model.addJoint(joints[parent], joint, placement, name)
        model.appendBodyToJoint(joints[name], inertia, pin.SE3.Identity())
    del joints["universe"]
    frames = {}
    for name, jid in joints.items():
        origin = [params.b, 0, 0] if name == "platform" else [0, 0, 0]  # platform frame at P = B_1 + b e_1
        frames[name] = model.addFrame(pin.Frame(name, jid, se3(origin), pin.FrameType.OP_FRAME), False)
    tip = se3([params.l_a, 0, 0])
    closures = [
        pin.RigidConstraintModel(
            pin.ContactType.CONTACT_3D,
            model,
            joints[link],
            tip,
            joints["platform"],
            se3(xyz),
            pin.ReferenceFrame.LOCAL_WORLD_ALIGNED,
        )
        for link, xyz in on_platform.items()
    ]
    return model, closures, frames
