"""The parallel 2-PPa (Liu & Wang's arrangement, both rails on the X axis), in the paper's conventions.

The one import for the parallel arrangement: kinematics, Jacobians, singularities, statics and status from
:mod:`tpm_viz.paper.parallel.kinematics`, the closed-form inverse dynamics from
:mod:`tpm_viz.paper.parallel.dynamics`. Names, shapes, units and returned types mirror the perpendicular
arrangement's (:mod:`tpm_viz.paper.kinematics`, :mod:`tpm_viz.paper.jacobians`, :mod:`tpm_viz.paper.dynamics`),
whose code it shares where the equations share their shape (:mod:`tpm_viz.paper.legs`,
:func:`~tpm_viz.paper.jacobians.jacobians_of`); equations P1-P15 are derived in ``docs/parallel.md``.
"""

from __future__ import annotations

from tpm_viz.paper.parallel.dynamics import (
    coordinate_mass_matrix,
    inverse_dynamics,
    inverse_dynamics_detail,
    kinetic_energy,
    mass_matrix,
)
from tpm_viz.paper.parallel.kinematics import (
    PARALLEL,
    actuator_acceleration,
    actuator_forces_from_platform_force,
    actuator_velocity,
    classify,
    condition_number,
    forward_kinematics,
    forward_kinematics_both,
    forward_kinematics_nearest,
    geometry_problem,
    home,
    in_stroke,
    inverse_kinematics,
    jacobians,
    leg_angles,
    leg_components,
    mechanism_pose,
    platform_force_from_actuator_forces,
    platform_velocity,
    reachable,
    validate,
)

__all__ = [
    "PARALLEL",
    "actuator_acceleration",
    "actuator_forces_from_platform_force",
    "actuator_velocity",
    "classify",
    "condition_number",
    "coordinate_mass_matrix",
    "forward_kinematics",
    "forward_kinematics_both",
    "forward_kinematics_nearest",
    "geometry_problem",
    "home",
    "in_stroke",
    "inverse_dynamics",
    "inverse_dynamics_detail",
    "inverse_kinematics",
    "jacobians",
    "kinetic_energy",
    "leg_angles",
    "leg_components",
    "mass_matrix",
    "mechanism_pose",
    "platform_force_from_actuator_forces",
    "platform_velocity",
    "reachable",
    "validate",
]
