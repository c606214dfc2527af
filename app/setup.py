"""Build a backend and the matching planner configuration from command-line names."""

from __future__ import annotations

import math
from dataclasses import replace

from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig

from .backend import Backend, InitialCondition
from .lipm_backend import LipmBackend
from .overrides import Overrides, apply_to_rsg, check_overrides, parse_overrides
from .runner import walking_start

DEFAULT_ROBOT = "g1"


def resolve_robot(model: str, robot: str | None) -> str | None:
    """The robot a run uses: on ``pybullet`` ``robot`` or :data:`DEFAULT_ROBOT`; on
    ``lipm`` ``robot`` (``None``: the paper's point mass; a name: that robot's
    planner configuration, mass, sole, gait and timing, on the point mass)."""
    if model == "pybullet" and robot is None:
        return DEFAULT_ROBOT
    return robot


def paper_rules(config: PlannerConfig) -> PlannerConfig:
    """``config`` without the documented extensions: the paper's D_T and (27) as printed
    (no push hold, ``push_hold_time = 0``; no step reaction time,
    ``step_reaction_time = 0``; no leg reach in the QP, ``com_reach = inf``; no DCM
    row (27c'), ``dcm_inset = None``)."""
    return replace(
        config,
        rsg=replace(config.rsg, push_hold_time=0.0, step_reaction_time=0.0, dcm_inset=None),
        constraints=replace(config.constraints, com_reach=math.inf),
    )


def build_backend(
    model: str,
    robot: str | None,
    controller: str,
    paper: bool = False,
    overrides: Overrides = (),
) -> tuple[Backend, PlannerConfig, InitialCondition]:
    """The backend for ``model`` and the planner configuration that fits it.

    Args:
        model, robot, controller: Names as on the command line. ``robot`` ``None``
            is G1 on ``pybullet`` and the paper's point mass on ``lipm``; a robot on
            ``lipm`` is its planner configuration (mass, sole, gait, timing) on the
            point mass, what the RSG could do if the robot realised the LIPM exactly.
        paper: The paper's rules only (:func:`paper_rules`).
        overrides: ``--set`` pairs (:mod:`app.overrides`); RSG parameters among
            them are applied after ``paper``.

    Raises:
        ParameterError: Unknown model or robot, or a bad override.
    """
    if model not in ("lipm", "pybullet"):
        raise ParameterError("--model", model, "lipm or pybullet")
    check_overrides(overrides, model, robot, controller, paper)
    if model == "lipm":
        if robot is None:
            parsed = parse_overrides(overrides, "lipm")
            config = PlannerConfig(controller=controller)
        else:
            from .robot_setup import planner_config_for, robot_with_overrides

            description, parsed = robot_with_overrides(robot, overrides, "lipm")
            config = planner_config_for(description, description.total_mass, controller)
        if paper:
            config = paper_rules(config)
        config = replace(config, rsg=apply_to_rsg(config.rsg, parsed))
        return LipmBackend(config.model), config, walking_start(config)
    if model == "pybullet":
        from .robot_setup import build_robot_backend

        return build_robot_backend(robot or DEFAULT_ROBOT, controller, overrides, paper)
    raise ParameterError("--model", model, "lipm or pybullet")
