"""Build a backend and the matching planner configuration from command-line names."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace

from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig, RsgParameters

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


@dataclass(frozen=True)
class Extension:
    """A documented extension of the paper, and its value under the paper's rules.

    Attributes:
        name: What it is, in words.
        field: Its parameter, in :class:`planner.parameters.RsgParameters` or
            :class:`planner.parameters.Constraints`.
        paper_value: The value that turns it off.
    """

    name: str
    field: str
    paper_value: object


# What --paper-rules turns off: the one list the CLI help and the README refer to.
PAPER_RULES: tuple[Extension, ...] = (
    Extension("the push hold", "push_hold_time", 0.0),
    Extension("the step reaction time", "step_reaction_time", 0.0),
    Extension("the QP's location for a timing jump below gamma_v", "qp_at_timing_jump", False),
    Extension("the leg reach in the step QP", "com_reach", math.inf),
    Extension("the DCM row (27c')", "dcm_inset", None),
)
# What it keeps (README, "Implementation notes"): the misprint fixes, and two departures
# without which the paper's own nominal walk fails with these limits.
PAPER_RULES_KEPT = (
    "the misprints fixed, and two documented departures: the double-support compensation "
    "added after the saturation of K_u e_u, and D_S gated by s~ >= T_DSP + T_SP"
)
PAPER_RULES_HELP = (
    "the paper's algorithm: turns off "
    + ", ".join(f"{e.name} ({e.field}={e.paper_value})" for e in PAPER_RULES)
    + "; keeps "
    + PAPER_RULES_KEPT
    + " (app/setup.py)"
)


def paper_rules(config: PlannerConfig) -> PlannerConfig:
    """``config`` under the paper's rules: every extension of :data:`PAPER_RULES` off."""
    rsg_fields = {f.name for f in fields(RsgParameters)}
    rsg = {e.field: e.paper_value for e in PAPER_RULES if e.field in rsg_fields}
    constraints = {e.field: e.paper_value for e in PAPER_RULES if e.field not in rsg_fields}
    return replace(
        config,
        rsg=replace(config.rsg, **rsg),  # type: ignore[arg-type]
        constraints=replace(config.constraints, **constraints),  # type: ignore[arg-type]
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
        paper: The paper's rules (:data:`PAPER_RULES` off, :func:`paper_rules`).
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
