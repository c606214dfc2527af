"""Planner configuration and backend for a full robot in PyBullet."""

from __future__ import annotations

import math
from dataclasses import replace

from planner.parameters import (
    Constraints,
    GaitParameters,
    LipmModel,
    PlannerConfig,
    RsgParameters,
)
from robots import get_robot
from robots.description import RobotDescription

from .backend import InitialCondition
from .overrides import (
    Overrides,
    ParsedOverrides,
    apply_to_description,
    apply_to_rsg,
    check_overrides,
    parse_overrides,
)
from .runner import walking_start
from .setup import DEFAULT_ROBOT

ZMP_MARGIN = 0.005  # [m] kept between the ZMP window and the sole's edges


def planner_config_for(
    description: RobotDescription, mass: float, controller: str = "rsg"
) -> PlannerConfig:
    """The planner's parameters for a robot: its mass, CoM height, sole and gait.

    Args:
        description: The robot.
        mass: Mass measured in the simulator [kg].
        controller: ``rsg``, ``fixed-timing`` or ``no-step``.
    """
    sole = description.sole
    half_width = sole.half_width - ZMP_MARGIN
    return PlannerConfig(
        model=LipmModel(mass=mass, com_height=description.com_height),
        gait=GaitParameters(
            stride_length=description.stride_length,
            step_width=description.step_width,
            double_support_duration=description.double_support_duration,
            single_support_duration=description.single_support_duration,
        ),
        constraints=Constraints(
            zmp_window_min=(sole.x_min + ZMP_MARGIN, -half_width),
            zmp_window_max=(sole.x_max - ZMP_MARGIN, half_width),
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
            dcm_inset=description.dcm_inset,
            push_hold_time=0.0,  # the paper's D_T: no push estimate from the robot's CoM
        ),
        controller=controller,
    )


def robot_with_overrides(
    robot: str | RobotDescription, overrides: Overrides = (), model: str = "pybullet"
) -> tuple[RobotDescription, ParsedOverrides]:
    """The description of ``robot`` (a registry name or a description) with the
    description fields and backend options of ``overrides`` (``--set``; on
    ``model`` ``lipm`` backend options are not allowed).

    Raises:
        ParameterError: Unknown robot, or a bad override.
    """
    description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
    name = robot if isinstance(robot, str) else robot.name
    parsed = parse_overrides(overrides, model, name)
    return apply_to_description(description, parsed), parsed


def build_robot_backend(  # noqa: ANN201
    robot: str | RobotDescription, controller: str, overrides: Overrides = (), paper: bool = False
):
    """PyBullet backend, planner configuration and walking start for ``robot``
    (a registry name or a description), with ``overrides`` (``--set``; RSG
    parameters are applied to the configuration, after the paper's rules when
    ``paper``, :func:`app.setup.paper_rules`). The backend's ``description`` is the
    one with the overrides.

    Raises:
        ParameterError: Unknown robot, or a bad override.
    """
    from kinematics.swing_foot import SwingTiming

    from .pybullet_backend import PyBulletBackend
    from .setup import paper_rules

    check_overrides(overrides, "pybullet", robot, controller, paper)
    description, parsed = robot_with_overrides(robot, overrides)
    config = planner_config_for(description, description.total_mass, controller)
    if paper:
        config = paper_rules(config)
    config = replace(config, rsg=apply_to_rsg(config.rsg, parsed))
    timing = SwingTiming(
        config.gait.double_support_duration,
        config.rsg.swing_preparation_time,
        config.gait.step_duration,
    )
    backend = PyBulletBackend(description, timing)
    config = replace(config, model=replace(config.model, mass=backend.mass))
    initial: InitialCondition = walking_start(config)
    return backend, config, initial


def check_robot_overrides(robot: str | None, overrides: Overrides) -> None:
    """Build ``robot`` once with ``overrides`` (then close it), so that a value out of
    range is reported, as the backend or the planner words it, before a grid or a
    sweep starts its worker processes.

    Raises:
        ParameterError: Unknown robot, or a bad override.
    """
    if not overrides:
        return
    backend, _, _ = build_robot_backend(robot or DEFAULT_ROBOT, "rsg", overrides)
    backend.close()
