"""Whole-body kinematics of the biped: what turns the planner's targets into joint angles.

- :mod:`kinematics.whole_body_ik`: placo's whole-body IK (CoM, soles, trunk, posture);
- :mod:`kinematics.swing_foot`: the swing foot's trajectory, re-targeted every tick;
- :mod:`kinematics.upper_body`: the upper body as a bounded flywheel for hdot;
- :mod:`kinematics.robot_model`: the pinocchio model for inverse dynamics;
- :mod:`kinematics.reach`: the legs' lateral reach (the planner's outward step bound).
"""

from kinematics.robot_model import RobotModel
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming
from kinematics.upper_body import UpperBodyFlywheel
from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK

__all__ = [
    "IkInfeasibleError",
    "RobotModel",
    "SwingFootTrajectory",
    "SwingTiming",
    "UpperBodyFlywheel",
    "WholeBodyIK",
]
