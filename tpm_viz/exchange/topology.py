"""The real topology of the 2-PPa TPM as plain data: the one description the MJCF and URDF writers read.

Units: SI (m, kg, kg m², rad). Frame: the paper's OXY with Z up; the mechanism lies in the plane ``z = 0``
(visual boxes are stacked in Z only). Quaternions are ``(w, x, y, z)``.

Tree (depth-first, the order of ``qpos`` in MuJoCo and of ``q`` in Pinocchio, the same as
:mod:`tpm_viz.multibody.model`)::

    base (fixed) ─slide x "d1"─ slider1 (origin A_1 = (d_1 - a) e_1) ─hinge z "phi1_0"─ link1_0 (pivot A_1)
                 │                                                    │   └hinge z "phi_p"─ platform (origin P)
                 │                                                    └hinge z "phi1_1"─ link1_1 (pivot A_1 + s e_2)
                 └slide y "d2"─ slider2 (origin A_2 = (d_2 - a) e_2) ─hinge z "phi2_0"─ link2_0 (pivot A_2)
                                                                      └hinge z "phi2_1"─ link2_1 (pivot A_2 + s e_1)

``s`` is the pivot spacing. Each link frame has its x axis along the link (leg 2's link frames are turned
+90° about Z), so ``phi1_k = θ_1``, ``phi2_k = -θ_2`` and ``phi_p = -θ_1`` (the platform translates). The
platform frame is at ``P`` with its hinge at ``B_1 = P - b e_1``. Loop closures (:attr:`Topology.closures`):
the tips of link1_1, link2_0 and link2_1 coincide with ``B_1 + s e_2``, ``B_2 = P - b e_2`` and
``B_2 + s e_1`` on the platform (three point constraints, nine rows, rank five in the plane).

Mass model (``docs/conventions.md``): sliders ``m_a`` and the platform ``m_p`` are point masses; each link is a
uniform slender rod of mass ``m_b / 2`` and length ``l_a``: centre at ``l_a / 2`` on its x axis, principal
moments ``(0, m l_a² / 12, m l_a² / 12)`` about it. MuJoCo needs every moment of a
moving body positive: the zero moments become ``m r²`` with ``r`` = :data:`POINT_GYRATION` (1 mm), which
never enters the dynamics (sliders do not rotate, the platform translates, the motion is planar). The base is
fixed; it carries a nominal :data:`BASE_INERTIAL` only because Pinocchio's MJCF reader needs an inertial on
every body (it never enters the dynamics either).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import Params
from tpm_viz.paper.kinematics import as_xy, inverse_kinematics, leg_components

__all__ = [
    "BASE_INERTIAL",
    "JOINT_NAMES",
    "POINT_GYRATION",
    "Body",
    "Box",
    "Closure",
    "Inertial",
    "Joint",
    "Site",
    "Topology",
    "joint_motion",
    "joint_positions",
    "topology",
]

Vec3 = tuple[float, float, float]

JOINT_NAMES = ("d1", "phi1_0", "phi_p", "phi1_1", "d2", "phi2_0", "phi2_1")
"""Joint names in tree (``qpos``) order."""

_QUARTER_TURN = (math.cos(math.pi / 4), 0.0, 0.0, math.sin(math.pi / 4))  # +90° about Z (w, x, y, z)
_IDENTITY = (1.0, 0.0, 0.0, 0.0)

POINT_GYRATION = 1e-3
"""Radius of gyration [m] where the mass model has no moment: ``I = m r²`` about every axis of the point
masses (sliders, platform) and about the axis of each rod.

MuJoCo refuses moving bodies without rotational inertia. The sliders never rotate, the platform only
translates while the closures hold and no link turns about its own axis (planar motion), so this value does
not enter the dynamics of the mechanism."""


@dataclass(frozen=True)
class Inertial:
    """Mass ``mass`` [kg] with its centre ``com`` [m] in the body frame and principal moments ``diag``
    [kg m²] about the centre, along the body axes."""

    mass: float
    com: Vec3
    diag: Vec3


@dataclass(frozen=True)
class Joint:
    """A one-DOF joint: ``kind`` ``"slide"`` [m] or ``"hinge"`` [rad], ``axis`` in the body frame, ``pos`` [m]
    in the body frame (the hinge point); ``limits`` ``(lower, upper)`` or None for unlimited."""

    name: str
    kind: str
    axis: Vec3
    pos: Vec3 = (0.0, 0.0, 0.0)
    limits: tuple[float, float] | None = None


@dataclass(frozen=True)
class Site:
    """A named point ``pos`` [m] of a body frame (a loop-closure anchor)."""

    name: str
    pos: Vec3


@dataclass(frozen=True)
class Box:
    """A visual box: half sizes ``half`` [m] centred at ``pos`` [m] in the body frame; ``rgba`` colour."""

    half: Vec3
    pos: Vec3
    rgba: tuple[float, float, float, float]


@dataclass(frozen=True)
class Body:
    """One rigid body: placement ``pos`` [m], ``quat`` (w, x, y, z) in its parent's frame at zero joint values."""

    name: str
    parent: str
    pos: Vec3
    quat: tuple[float, float, float, float]
    joint: Joint | None
    inertial: Inertial | None
    sites: tuple[Site, ...] = ()
    boxes: tuple[Box, ...] = ()


@dataclass(frozen=True)
class Closure:
    """Loop closure: the point ``site1`` of ``body1`` coincides with ``site2`` of ``body2``."""

    name: str
    body1: str
    site1: str
    body2: str
    site2: str


@dataclass(frozen=True)
class Topology:
    """Bodies in depth-first order (parents first), the loop closures and the source parameters."""

    params: Params
    bodies: tuple[Body, ...]
    closures: tuple[Closure, ...]

    @property
    def moving_mass(self) -> float:
        """Total mass [kg] of the bodies with a joint: ``2 m_a + 2 m_b + m_p``."""
        return sum(b.inertial.mass for b in self.bodies if b.joint is not None and b.inertial is not None)

    def body(self, name: str) -> Body:
        """The body called ``name``."""
        for b in self.bodies:
            if b.name == name:
                return b
        raise InputError(f"no body called {name!r}")


_GREY, _BLUE, _ORANGE, _GREEN = (0.6, 0.6, 0.6, 1.0), (0.2, 0.4, 0.8, 1.0), (0.9, 0.5, 0.1, 1.0), (0.2, 0.7, 0.3, 1.0)


BASE_INERTIAL = Inertial(1.0, (0.0, 0.0, 0.0), (0.01, 0.01, 0.01))
"""Nominal inertial of the fixed base [kg, m, kg m²] (not part of the mechanism's mass model)."""


def _point(mass: float) -> Inertial:
    i = mass * POINT_GYRATION**2
    return Inertial(mass, (0.0, 0.0, 0.0), (i, i, i))


def topology(params: Params) -> Topology:
    """The bodies, joints, inertias and loop closures of ``params`` (see the module docstring)."""
    if not isinstance(params, Params):
        raise InputError(f"topology needs a tpm_viz.Params, got {type(params).__name__}")
    a, b, la, sp, stroke = params.a, params.b, params.l_a, params.pivot_spacing, params.stroke
    m_link = params.m_b / 2.0
    i_rod = m_link * la**2 / 12.0
    rod = Inertial(m_link, (la / 2.0, 0.0, 0.0), (m_link * POINT_GYRATION**2, i_rod, i_rod))
    w = 0.1 * sp  # visual thickness [m]

    def link(name: str, parent: str, pos: Vec3, quat, z: float) -> Body:
        return Body(
            name,
            parent,
            pos,
            quat,
            Joint(f"phi{name[4:]}", "hinge", (0.0, 0.0, 1.0)),
            rod,
            (Site(f"{name}_tip", (la, 0.0, 0.0)),),
            (Box((la / 2.0, w / 2.0, w / 2.0), (la / 2.0, 0.0, z), _ORANGE),),
        )

    def slider(i: int) -> Body:
        axis = (1.0, 0.0, 0.0) if i == 1 else (0.0, 1.0, 0.0)
        half = (2 * w, sp / 2 + w, w / 2) if i == 1 else (sp / 2 + w, 2 * w, w / 2)
        centre = (0.0, sp / 2, -2 * w) if i == 1 else (sp / 2, 0.0, -2 * w)
        return Body(
            f"slider{i}",
            "base",
            (-a, 0.0, 0.0) if i == 1 else (0.0, -a, 0.0),
            _IDENTITY,
            Joint(f"d{i}", "slide", axis, limits=(0.0, stroke)),
            _point(params.m_a),
            (),
            (Box(half, centre, _BLUE),),
        )

    rail = stroke / 2.0
    base = Body(
        "base",
        "world",
        (0.0, 0.0, 0.0),
        _IDENTITY,
        None,
        BASE_INERTIAL,
        (),
        (
            Box((rail, w / 2, w / 2), (rail - a, 0.0, -4 * w), _GREY),
            Box((w / 2, rail, w / 2), (0.0, rail - a, -4 * w), _GREY),
        ),
    )
    platform = Body(
        "platform",
        "link1_0",
        (la + b, 0.0, 0.0),
        _IDENTITY,
        Joint("phi_p", "hinge", (0.0, 0.0, 1.0), pos=(-b, 0.0, 0.0)),
        _point(params.m_p),
        (
            Site("platform_B1_1", (-b, sp, 0.0)),
            Site("platform_B2_0", (0.0, -b, 0.0)),
            Site("platform_B2_1", (sp, -b, 0.0)),
        ),
        (Box((b + w, b + w, w / 2), (sp / 2, sp / 2, 2 * w), _GREEN),),
    )
    bodies = (
        base,
        slider(1),
        link("link1_0", "slider1", (0.0, 0.0, 0.0), _IDENTITY, w),
        platform,
        link("link1_1", "slider1", (0.0, sp, 0.0), _IDENTITY, w),
        slider(2),
        link("link2_0", "slider2", (0.0, 0.0, 0.0), _QUARTER_TURN, -w),
        link("link2_1", "slider2", (sp, 0.0, 0.0), _QUARTER_TURN, -w),
    )
    closures = (
        Closure("close_link1_1", "link1_1", "link1_1_tip", "platform", "platform_B1_1"),
        Closure("close_link2_0", "link2_0", "link2_0_tip", "platform", "platform_B2_0"),
        Closure("close_link2_1", "link2_1", "link2_1_tip", "platform", "platform_B2_1"),
    )
    return Topology(params, bodies, closures)


def joint_motion(params: Params, p, dp=(0.0, 0.0), ddp=(0.0, 0.0)) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Joint positions, velocities and accelerations ``(q, v, a)``, shape ``(7,)`` each in
    :data:`JOINT_NAMES` order [m, rad, /s, /s²], for one platform state ``p, ṗ, p̈`` [m, m/s, m/s²].

    Closed form, working mode (eq. 4): ``d`` from :func:`~tpm_viz.paper.kinematics.inverse_kinematics`,
    ``c_i = l_a cos θ_i`` and ``p_j = l_a sin θ_i``, so ``θ̇_i = ṗ_j / c_i``, ``θ̈_i = (p̈_j + p_j θ̇_i²) / c_i``
    and ``ḋ_i = ṗ_i - ċ_i``, ``d̈_i = p̈_i - c̈_i`` with ``ċ_i = -p_j θ̇_i``, ``c̈_i = -ṗ_j θ̇_i - p_j θ̈_i``.
    """
    p, dp, ddp = as_xy(p), as_xy(dp, "dp"), as_xy(ddp, "ddp")
    if p.shape != (2,) or dp.shape != (2,) or ddp.shape != (2,):
        raise InputError("joint_motion takes one platform state: p, dp and ddp of shape (2,)")
    d = inverse_kinematics(params, p)
    c, s = leg_components(params, p, d)  # c_i = l_a cos θ_i > 0, s_i = p_j
    theta = np.arctan2(s, c)
    ds, dds = dp[::-1], ddp[::-1]
    dtheta = ds / c
    ddtheta = (dds + s * dtheta**2) / c
    dc = -s * dtheta
    ddc = -ds * dtheta - s * ddtheta

    def pack(lin, ang):  # (d1, θ1, -θ1, θ1, d2, -θ2, -θ2)
        return np.array([lin[0], ang[0], -ang[0], ang[0], lin[1], -ang[1], -ang[1]])

    return pack(d, theta), pack(dp - dc, dtheta), pack(ddp - ddc, ddtheta)


def joint_positions(params: Params, p) -> dict[str, float]:
    """``{joint name: value}`` [m, rad] of the working-mode configuration of platform position ``p`` (2,) [m]."""
    q = joint_motion(params, p)[0]
    return dict(zip(JOINT_NAMES, q.tolist(), strict=True))
