"""MJCF text of the 2-PPa TPM: every body of the real topology, the mass model, the loop closures.

The file (see :func:`mjcf_text`) is read by MuJoCo (``mujoco.MjModel.from_xml_string``) and by
Pinocchio's MJCF reader (``pinocchio.buildModelsAndConstraintsFromMJCF``, which needs the single
top-level body ``base``). Bodies, joints and inertias come from :mod:`tpm_viz.exchange.topology`.

- Loop closures: one ``<equality><connect site1 site2>`` per closure (between sites, so that the constraint
  does not depend on the placement of the bodies).
- ``qpos0`` is the assembled working-mode configuration of ``P = (0, 0)`` (closure residual ~1e-16 m, as
  closed-chain models in MuJoCo Menagerie): every body is placed where its joint at that value puts it, and the
  joint's ``ref`` is that value, so ``qpos`` keeps its meaning (``d_i`` the actuator positions [m], the angles
  of :mod:`.topology`) and a model opened in MuJoCo's viewer starts at rest, assembled. Pinocchio 4.1's MJCF reader
  honours ``ref`` in its kinematics but reports the sliders' range shifted by ``-ref`` (its width is the stroke).
- Solver: with MuJoCo's default soft constraints (``solref 0.02 1``, ``solimp 0.9 0.95 0.001``, 2 ms,
  Euler) the closures drift by ~1.6 mm over 1 s of the paper's circle driven by the closed-form forces.
  :class:`MjcfSettings` holds stiff values and the recommended time step (drift ~1e-8 m); they are written
  in ``<option>``, on every ``<connect>`` and in a comment at the top of the file.
- Actuators: a ``<motor>`` per slider (``ctrl`` = force [N] along ``e_i``, unlimited).
- Keyframe ``home``: the same configuration as ``qpos0`` (kept for scripts that reset to it).
- Gravity ``-9.81 e_z`` (Z up): the mechanism lies in a horizontal plane, so gravity does no work (the
  paper's ``U = 0``); no contacts (visual geoms only, ``contype = conaffinity = 0``, contacts disabled).

Units: SI; ``<compiler angle="radian">``; inertias are given explicitly (``inertiafromgeom="false"``).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass

from tpm_viz.core.errors import InputError
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.exchange.topology import Body, Topology, joint_positions, topology

__all__ = ["DEFAULT_SETTINGS", "MUJOCO_DEFAULTS", "MjcfSettings", "mjcf_text"]


@dataclass(frozen=True)
class MjcfSettings:
    """MuJoCo solver settings written into the file.

    ``timestep`` [s]; ``solref`` ``(timeconst [s], dampratio)`` and ``solimp``
    ``(dmin, dmax, width [m], midpoint, power)`` of every loop closure; ``integrator`` and the constraint
    solver's ``iterations`` and ``tolerance``. MuJoCo clamps ``timeconst`` to at least ``2 timestep``.
    """

    timestep: float = 2e-4
    solref: tuple[float, float] = (4e-4, 1.0)
    solimp: tuple[float, float, float, float, float] = (0.9999, 0.9999, 1e-6, 0.5, 2.0)
    integrator: str = "RK4"
    iterations: int = 100
    tolerance: float = 1e-10

    def __post_init__(self) -> None:
        numbers = (self.timestep, *self.solref, *self.solimp, self.tolerance)
        if not all(isinstance(x, (int, float)) and math.isfinite(x) for x in numbers):
            raise InputError("MJCF settings must be finite numbers")
        if self.timestep <= 0 or self.solref[0] <= 0 or self.tolerance < 0 or self.iterations < 1:
            raise InputError("MJCF settings: timestep, timeconst and iterations must be positive")
        if not 0 < self.solimp[0] <= self.solimp[1] < 1:
            raise InputError("MJCF settings: solimp needs 0 < dmin <= dmax < 1")
        if self.integrator not in ("Euler", "RK4", "implicit", "implicitfast"):
            raise InputError(f"unknown MuJoCo integrator {self.integrator!r}")


DEFAULT_SETTINGS = MjcfSettings()
"""The recommended settings (the tests measure the closure drift they give)."""

MUJOCO_DEFAULTS = MjcfSettings(
    timestep=2e-3, solref=(0.02, 1.0), solimp=(0.9, 0.95, 1e-3, 0.5, 2.0), integrator="Euler", tolerance=1e-8
)
"""MuJoCo's own defaults, for comparison (the closures drift by ~1.6 mm over 1 s of the circle)."""


def _fmt(*values: float) -> str:
    return " ".join(repr(float(v) + 0.0) for v in values)  # + 0.0: no "-0.0"


def _at(body: Body, value: float) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``(pos, quat)`` of ``body`` in its parent with its joint at ``value`` [m or rad]: the body frame moved
    rigidly by the joint (a slide along its axis, a hinge about Z through its point). Every rotation of the
    topology is about Z."""
    yaw = 2.0 * math.atan2(body.quat[3], body.quat[0])
    j = body.joint
    assert j is not None and (j.kind == "slide" or j.axis == (0.0, 0.0, 1.0)), body.name

    def turn(v, angle):
        c, s = math.cos(angle), math.sin(angle)
        return (c * v[0] - s * v[1], s * v[0] + c * v[1])

    if j.kind == "slide":
        shift = turn((j.axis[0] * value, j.axis[1] * value), yaw)
    else:
        turned = turn(j.pos, value)
        shift = turn((j.pos[0] - turned[0], j.pos[1] - turned[1]), yaw)
        yaw += value
    pos = (body.pos[0] + shift[0], body.pos[1] + shift[1], body.pos[2])
    return pos, (math.cos(yaw / 2.0), 0.0, 0.0, math.sin(yaw / 2.0))


def _add_body(parent: ET.Element, body: Body, children: dict[str, list[Body]], home: dict[str, float]) -> None:
    pos, quat = (body.pos, body.quat) if body.joint is None else _at(body, home[body.joint.name])
    el = ET.SubElement(parent, "body", name=body.name, pos=_fmt(*pos), quat=_fmt(*quat))
    if body.inertial is not None:
        i = body.inertial
        ET.SubElement(el, "inertial", pos=_fmt(*i.com), mass=_fmt(i.mass), diaginertia=_fmt(*i.diag))
    if body.joint is not None:
        j = body.joint
        attrs = {"name": j.name, "type": j.kind, "axis": _fmt(*j.axis), "pos": _fmt(*j.pos), "ref": _fmt(home[j.name])}
        if j.limits is not None:
            attrs |= {"limited": "true", "range": _fmt(*j.limits)}
        else:
            attrs["limited"] = "false"
        ET.SubElement(el, "joint", attrs)
    for box in body.boxes:
        ET.SubElement(
            el,
            "geom",
            type="box",
            size=_fmt(*box.half),
            pos=_fmt(*box.pos),
            rgba=_fmt(*box.rgba),
            contype="0",
            conaffinity="0",
            group="1",
            mass="0",
        )
    for site in body.sites:
        ET.SubElement(el, "site", name=site.name, pos=_fmt(*site.pos), size="0.004")
    for child in children.get(body.name, []):
        _add_body(el, child, children, home)


def _header(params: Params, s: MjcfSettings) -> str:
    r = DEFAULT_SETTINGS
    lines = [
        "2-PPa planar translational parallel manipulator (Pham & Kim 2013), written by tpm-viz (tpm-viz export).",
        "Parameters [SI]: " + ", ".join(f"{k}={getattr(params, k):g}" for k in PARAM_INFO) + ".",
        "Joints (qpos order): d1, phi1_0, phi_p, phi1_1, d2, phi2_0, phi2_1; phi1_k = theta_1,",
        "phi_p = -theta_1, phi2_k = -theta_2. qpos0 (each joint's ref) is the assembled pose P = (0, 0),",
        "the same as keyframe 'home' (Pinocchio 4.1 reads d1, d2's range shifted by -ref; its width is the stroke).",
        "Loop closures: three <connect> between sites, 9 rows of rank 5 (planar: 3 rows vanish, 1 is redundant).",
        f"Solver settings in this file: timestep {s.timestep:g} s, integrator {s.integrator}, connect solref",
        f"'{_fmt(*s.solref)}', solimp '{_fmt(*s.solimp)}', solver tolerance {s.tolerance:g}.",
        f"RECOMMENDED (tpm-viz default): timestep {r.timestep:g} s, {r.integrator}, solref '{_fmt(*r.solref)}',",
        f"solimp '{_fmt(*r.solimp)}', tolerance {r.tolerance:g}. Over 1 s of the paper's circle (T = 0.5 s, twice)",
        "driven by the closed-form forces, the closures then drift ~1e-8 m (paper's parameters, MuJoCo 4.0);",
        "with MuJoCo's defaults (2 ms, Euler, solref '0.02 1', solimp '0.9 0.95 0.001') they drift ~1.6 mm.",
        "Keep solref's time constant >= 2 timesteps (MuJoCo clamps it).",
        "Actuators: motor on d1 and d2, ctrl = slider force [N] along e_i. Gravity is along -Z (Z up): no work.",
    ]
    return "\n".join(f"  {line}" for line in lines)


def mjcf_text(params: Params, settings: MjcfSettings = DEFAULT_SETTINGS) -> str:
    """The MJCF document of ``params`` with the solver ``settings`` (see the module docstring)."""
    if not isinstance(settings, MjcfSettings):
        raise InputError(f"settings must be an MjcfSettings, got {type(settings).__name__}")
    topo: Topology = topology(params)
    root = ET.Element("mujoco", model="tpm_2ppa")
    root.append(ET.Comment("\n" + _header(params, settings) + "\n"))
    ET.SubElement(root, "compiler", angle="radian", inertiafromgeom="false", autolimits="true")
    option = ET.SubElement(
        root,
        "option",
        timestep=_fmt(settings.timestep),
        integrator=settings.integrator,
        gravity="0 0 -9.81",
        iterations=str(settings.iterations),
        tolerance=_fmt(settings.tolerance),
        solver="Newton",
    )
    ET.SubElement(option, "flag", contact="disable")
    ET.SubElement(root, "size", memory="1M")
    world = ET.SubElement(root, "worldbody")
    children: dict[str, list[Body]] = {}
    for body in topo.bodies:
        children.setdefault(body.parent, []).append(body)
    home = joint_positions(params, (0.0, 0.0))
    for top in children["world"]:
        _add_body(world, top, children, home)
    equality = ET.SubElement(root, "equality")
    for c in topo.closures:
        ET.SubElement(
            equality,
            "connect",
            name=c.name,
            site1=c.site1,
            site2=c.site2,
            solref=_fmt(*settings.solref),
            solimp=_fmt(*settings.solimp),
        )
    actuator = ET.SubElement(root, "actuator")
    for i in (1, 2):
        ET.SubElement(actuator, "motor", name=f"force{i}", joint=f"d{i}", gear="1", ctrllimited="false")
    keyframe = ET.SubElement(root, "keyframe")
    ET.SubElement(keyframe, "key", name="home", qpos=_fmt(*home.values()))
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode", xml_declaration=False) + "\n"
