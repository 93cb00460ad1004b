"""Stage 2: the robot. URDF + robot.yaml spec -> RobotModel (Pinocchio kinematics, convex link
geometry, limits, TCP); `ik/` holds the closed-form and numeric solvers as pure functions."""

from robomax_py.robot.model import (
    DEFAULT_TIME_TO_FULL_ACCEL_S,
    DEFAULT_TIME_TO_FULL_SPEED_S,
    JointLimits,
    RobotModel,
    active_joints,
    checked_ik_params,
    fk_flange,
    fk_tcp,
    kinematic_model,
    load_robot,
    mimic_relation,
    mount_tool,
    passive_joints,
    prismatic_mask,
    reach,
    urdf_model,
)

__all__ = [
    "DEFAULT_TIME_TO_FULL_ACCEL_S", "DEFAULT_TIME_TO_FULL_SPEED_S", "JointLimits", "RobotModel",
    "active_joints", "checked_ik_params", "fk_flange", "fk_tcp", "kinematic_model", "load_robot", "mimic_relation", "mount_tool",
    "passive_joints", "prismatic_mask", "reach", "urdf_model",
]
