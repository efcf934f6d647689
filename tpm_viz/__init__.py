"""tpm-viz: kinematics, singularities and closed-form dynamics of the 2-PPa planar translational
parallel manipulator (Pham & Kim, 2013), with an independent Pinocchio model and a browser app.

The top level is pure numpy: importing :mod:`tpm_viz` loads neither viser nor pinocchio.
Shapes: positions, velocities, accelerations and forces are arrays of shape ``(..., 2)`` in SI units.
"""

from tpm_viz.core.errors import (
    InputError,
    InvalidParametersError,
    SingularConfigurationError,
    TpmVizError,
    UnreachablePoseError,
)
from tpm_viz.core.params import PARAM_INFO, Params
from tpm_viz.paper.dynamics import DynamicsResult, inverse_dynamics, inverse_dynamics_detail, kinetic_energy
from tpm_viz.paper.jacobians import (
    Jacobians,
    actuator_acceleration,
    actuator_forces_from_platform_force,
    actuator_velocity,
    classify,
    condition_number,
    jacobians,
    platform_force_from_actuator_forces,
    platform_velocity,
    theta_dot,
)
from tpm_viz.paper.kinematics import (
    FkSolutions,
    MechanismPose,
    forward_kinematics,
    forward_kinematics_both,
    forward_kinematics_nearest,
    in_stroke,
    inverse_kinematics,
    leg_angles,
    mechanism_pose,
    reachable,
)
from tpm_viz.paper.status import FK_STATUS, STATUS_LABELS, FkStatus, PoseStatus, SingularityThresholds
from tpm_viz.paper.trajectories import (
    DEFAULT_DURATIONS,
    Trajectory,
    circle_state,
    line_state,
    paper_trajectory,
    parse_trajectory_csv,
    trajectory_from_samples,
)
from tpm_viz.paper.workspace import WorkspaceMap, direct_singularity_locus, workspace_map

__version__ = "0.1.0"

__all__ = [
    "DEFAULT_DURATIONS",
    "FK_STATUS",
    "PARAM_INFO",
    "STATUS_LABELS",
    "DynamicsResult",
    "FkSolutions",
    "FkStatus",
    "InputError",
    "InvalidParametersError",
    "Jacobians",
    "MechanismPose",
    "Params",
    "PoseStatus",
    "SingularConfigurationError",
    "SingularityThresholds",
    "TpmVizError",
    "Trajectory",
    "UnreachablePoseError",
    "WorkspaceMap",
    "actuator_acceleration",
    "actuator_forces_from_platform_force",
    "actuator_velocity",
    "circle_state",
    "classify",
    "condition_number",
    "direct_singularity_locus",
    "forward_kinematics",
    "forward_kinematics_both",
    "forward_kinematics_nearest",
    "in_stroke",
    "inverse_dynamics",
    "inverse_dynamics_detail",
    "inverse_kinematics",
    "jacobians",
    "kinetic_energy",
    "leg_angles",
    "line_state",
    "mechanism_pose",
    "paper_trajectory",
    "parse_trajectory_csv",
    "platform_force_from_actuator_forces",
    "platform_velocity",
    "reachable",
    "theta_dot",
    "trajectory_from_samples",
    "workspace_map",
]
