"""Inverse kinematics as pure functions of SI parameters (no robot model, no files): the OPW and
UR closed forms, the numeric solver, turn variants and the configuration indicators.
`robomax_py.robot.solve` applies them to a RobotModel; `robomax_py.io.ik_params` reads robot.yaml's
`ik.params` into these parameter types."""

from robomax_py.robot.ik.config import ConfigIndicator, brand_text, same_config
from robomax_py.robot.ik.numeric import NumericIkParams, numeric_ik
from robomax_py.robot.ik.opw import OpwParams, opw_fk, opw_ik
from robomax_py.robot.ik.ur import UrParams, ur_fk, ur_ik

__all__ = [
    "ConfigIndicator", "NumericIkParams", "OpwParams", "UrParams", "brand_text", "numeric_ik", "opw_fk",
    "opw_ik", "same_config", "ur_fk", "ur_ik",
]
