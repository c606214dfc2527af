"""Build a backend and the matching planner configuration from command-line names."""

from __future__ import annotations

from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig

from .backend import Backend, InitialCondition
from .lipm_backend import LipmBackend
from .runner import walking_start


def build_backend(
    model: str, robot: str, controller: str
) -> tuple[Backend, PlannerConfig, InitialCondition]:
    """The backend for ``model`` and the planner configuration that fits it.

    Raises:
        ParameterError: Unknown model or robot.
    """
    if model == "lipm":
        config = PlannerConfig(controller=controller)
        return LipmBackend(config.model), config, walking_start(config)
    if model == "pybullet":
        from .robot_setup import build_robot_backend

        return build_robot_backend(robot, controller)
    raise ParameterError("--model", model, "lipm or pybullet")
