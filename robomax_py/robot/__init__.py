"""Stage 2: the robot. URDF + robot.yaml spec -> RobotModel (Pinocchio kinematics, convex link
geometry, limits, TCP); `ik/` holds the closed-form and numeric solvers as pure functions."""

from robomax_py.robot.ik_params import checked_ik_params
from robomax_py.robot.kinematics import (
    active_joints,
    kinematic_model,
    mimic_relation,
    passive_joints,
    prismatic_mask,
    urdf_model,
)
from robomax_py.robot.model import (
    DEFAULT_TIME_TO_FULL_ACCEL_S,
    DEFAULT_TIME_TO_FULL_SPEED_S,
    JointLimits,
    RobotModel,
    fk_flange,
    fk_tcp,
    load_robot,
    mount_tool,
    reach,
    with_joint_limits,
)

__all__ = [
    "DEFAULT_TIME_TO_FULL_ACCEL_S", "DEFAULT_TIME_TO_FULL_SPEED_S", "JointLimits", "RobotModel",
    "active_joints", "checked_ik_params", "fk_flange", "fk_tcp", "kinematic_model", "load_robot", "mimic_relation", "mount_tool",
    "passive_joints", "prismatic_mask", "reach", "urdf_model", "with_joint_limits",
]
