"""The planner's configuration for a robot: its mass, CoM height, sole and gait."""

from __future__ import annotations

import math

from kinematics.robot_model import RobotModel
from planner.parameters import (
    GRAVITY,
    Constraints,
    GaitParameters,
    LipmModel,
    PlannerConfig,
    RsgParameters,
)
from robots.description import RobotDescription

ZMP_MARGIN = 0.005  # [m] kept between the ZMP window and the edges of what holds the CoP


def ankle_reach(description: RobotDescription, mass: float) -> tuple[float, float]:
    """How far from the ankle [m] its joints hold the CoP under the robot's weight, along
    x (pitch) and y (roll): each ankle's effort limit over m g."""
    roll, pitch = RobotModel(description).ankle_effort_limits()
    weight = mass * GRAVITY
    return pitch / weight, roll / weight


def planner_config_for(
    description: RobotDescription, mass: float, controller: str = "rsg"
) -> PlannerConfig:
    """The planner's parameters for a robot: its mass, CoM height, sole and gait.

    The ZMP window is the part of the sole where the ankles hold the CoP under the robot's
    weight (:func:`ankle_reach`), ``ZMP_MARGIN`` inside its edges: the stabilizer never
    plans a CoP beyond the ankles' reach, so the planner does not count on one.

    Args:
        description: The robot.
        mass: Mass measured in the simulator [kg].
        controller: ``rsg``, ``fixed-timing`` or ``no-step``.
    """
    sole = description.sole
    reach_x, reach_y = ankle_reach(description, mass)
    half_width = min(sole.half_width, reach_y) - ZMP_MARGIN
    return PlannerConfig(
        model=LipmModel(mass=mass, com_height=description.pendulum_height),
        gait=GaitParameters(
            stride_length=description.stride_length,
            step_width=description.step_width,
            double_support_duration=description.double_support_duration,
            single_support_duration=description.single_support_duration,
        ),
        constraints=Constraints(
            zmp_window_min=(max(sole.x_min, -reach_x) + ZMP_MARGIN, -half_width),
            zmp_window_max=(min(sole.x_max, reach_x) - ZMP_MARGIN, half_width),
            angular_momentum_rate_max=description.angular_momentum_rate_max,
            step_min=description.step_min,
            step_max=description.step_max,
            com_reach=math.inf,  # the LIPM extensions are validated on the LIPM only
        ),
        rsg=RsgParameters(
            lqr_dcm_error_scale=description.lqr_dcm_error_scale,
            lqr_zmp_scale=half_width,
            lqr_angular_momentum_scale=description.angular_momentum_rate_max,
            swing_preparation_time=description.swing_preparation_time,
            filter_time_constant=description.filter_time_constant,
            step_reaction_time=description.step_reaction_time,
            reanchor_time=description.reanchor_time,
            touchdown_window=description.touchdown_window,
            dcm_inset=description.dcm_inset,
            push_hold_time=0.0,  # the paper's D_T: no push estimate from the robot's CoM
        ),
        controller=controller,
    )
