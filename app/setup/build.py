"""Build a backend and the matching planner configuration from command-line names."""

from __future__ import annotations

from dataclasses import replace

from app.backends.base import Backend, InitialCondition
from app.backends.lipm import LipmBackend
from app.backends.physics_log import PhysicsLog
from app.reality import DEFAULT_PROFILE, RealityDraw, check_profile, robot_reality
from app.runner import walking_start
from app.setup.overrides import (
    MODELS,
    ROBOT_MODELS,
    Overrides,
    ParsedOverrides,
    apply_to_description,
    apply_to_rsg,
    check_overrides,
    parse_overrides,
)
from app.setup.paper_rules import paper_rules
from app.setup.robot_config import planner_config_for
from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig
from robots import DEFAULT_ROBOT, get_robot
from robots.description import RobotDescription


def resolve_robot(model: str, robot: str | None) -> str | None:
    """The robot a run uses: on ``pybullet`` or ``mujoco`` ``robot`` or
    :data:`DEFAULT_ROBOT`; on ``lipm`` ``robot`` (``None``: the paper's point mass; a name:
    that robot's planner configuration, mass, sole, gait and timing, on the point mass)."""
    if model in ROBOT_MODELS and robot is None:
        return DEFAULT_ROBOT
    return robot


def build_backend(
    model: str,
    robot: str | None,
    controller: str,
    paper: bool = False,
    overrides: Overrides = (),
    physics_log: PhysicsLog | None = None,
    reality: str = DEFAULT_PROFILE,
    seed: int = 0,
) -> tuple[Backend, PlannerConfig, InitialCondition]:
    """The backend for ``model`` and the planner configuration that fits it.

    Args:
        model, robot, controller: Names as on the command line. ``robot`` ``None``
            is G1 on ``pybullet`` or ``mujoco`` and the paper's point mass on ``lipm``; a robot on
            ``lipm`` is its planner configuration (mass, sole, gait, timing) on the
            point mass, what the RSG could do if the robot realised the LIPM exactly.
        paper: The paper's rules (:data:`PAPER_RULES` off, :func:`paper_rules`).
        overrides: ``--set`` pairs (:mod:`app.setup.overrides`); RSG parameters among
            them are applied after ``paper``.
        physics_log: Records every physics step of a full-robot run (None: nothing).
        reality: Profile of :mod:`app.reality` (``--reality``); on ``lipm`` checked and
            ignored (the LIPM stays ideal).
        seed: Seed of the reality's draw (:func:`robot_reality`).

    Raises:
        ParameterError: Unknown model, robot or reality profile, or a bad override.
    """
    if model not in MODELS:
        raise ParameterError("--model", model, f"one of {', '.join(MODELS)}")
    check_profile(reality)
    check_overrides(overrides, model, robot, controller, paper)
    if model == "lipm":
        if robot is None:
            parsed = parse_overrides(overrides, "lipm")
            config = PlannerConfig(controller=controller)
        else:
            description, parsed = robot_with_overrides(robot, overrides, "lipm")
            config = planner_config_for(description, description.total_mass, controller)
        if paper:
            config = paper_rules(config)
        config = replace(config, rsg=apply_to_rsg(config.rsg, parsed))
        return LipmBackend(config.model), config, walking_start(config)
    return build_robot_backend(
        robot or DEFAULT_ROBOT, controller, overrides, paper, physics_log, reality, seed, model
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
    robot: str | RobotDescription,
    controller: str,
    overrides: Overrides = (),
    paper: bool = False,
    physics_log: PhysicsLog | None = None,
    reality: str = DEFAULT_PROFILE,
    seed: int = 0,
    engine: str = "pybullet",
):
    """Full-robot backend on ``engine`` (``pybullet`` or ``mujoco``), planner
    configuration and walking start for ``robot``
    (a registry name or a description), with ``overrides`` (``--set``; RSG
    parameters are applied to the configuration, after the paper's rules when
    ``paper``, :func:`app.setup.paper_rules.paper_rules`). The backend's ``description``
    is the one with the overrides; ``physics_log`` records every physics step; the
    backend applies the reality ``reality`` drawn from ``seed`` (:func:`robot_reality`).

    Raises:
        ParameterError: Unknown robot or reality profile, or a bad override.
    """
    # PyBullet, MuJoCo and placo load only for full-robot runs.
    from app.backends.pybullet import PyBulletBackend
    from kinematics.swing_foot import SwingTiming

    if engine not in ROBOT_MODELS:
        raise ParameterError("engine", engine, f"one of {', '.join(ROBOT_MODELS)}")
    backend_type = PyBulletBackend
    if engine == "mujoco":
        from app.backends.mujoco import MujocoBackend

        backend_type = MujocoBackend

    check_profile(reality)
    check_overrides(overrides, engine, robot, controller, paper)
    description, parsed = robot_with_overrides(robot, overrides, engine)
    config = planner_config_for(description, description.total_mass, controller)
    if paper:
        config = paper_rules(config)
    config = replace(config, rsg=apply_to_rsg(config.rsg, parsed))
    timing = SwingTiming(
        config.gait.double_support_duration,
        config.rsg.swing_preparation_time,
        config.gait.step_duration,
    )
    draw = robot_reality(description, reality, seed)
    backend = backend_type(description, timing, physics_log, reality=draw)
    config = replace(config, model=replace(config.model, mass=backend.mass))
    initial: InitialCondition = walking_start(config)
    return backend, config, initial


def backend_reality(backend: object, profile: str, seed: int) -> RealityDraw | None:
    """The reality a backend built with ``profile`` and ``seed`` applies: its own
    ``reality`` when it has one, else drawn again from its description
    (:func:`robot_reality`, the same draw); None for a backend without a description
    (the LIPM, which ignores the profile)."""
    own = getattr(backend, "reality", None)
    if isinstance(own, RealityDraw):
        return own
    description = getattr(backend, "description", None)
    if isinstance(description, RobotDescription):
        return robot_reality(description, profile, seed)
    return None


def check_robot_overrides(
    robot: str | None, overrides: Overrides, engine: str = "pybullet"
) -> None:
    """Build ``robot`` once on ``engine`` with ``overrides`` (then close it), so that a
    value out of range is reported, as the backend or the planner words it, before a
    grid or a sweep starts its worker processes.

    Raises:
        ParameterError: Unknown robot, or a bad override.
    """
    if not overrides:
        return
    backend, _, _ = build_robot_backend(robot or DEFAULT_ROBOT, "rsg", overrides, engine=engine)
    backend.close()
