"""Registry of the bipeds the full-robot backend can simulate.

Adding a robot: write one module with a :class:`RobotDescription` and add it to
``_REGISTRY``.
"""

from __future__ import annotations

from planner.exceptions import ParameterError
from robots.description import JointImpedance, RobotDescription, SoleRectangle
from robots.g1 import G1
from robots.talos import TALOS

_REGISTRY: dict[str, RobotDescription] = {robot.name: robot for robot in (G1, TALOS)}
DEFAULT_ROBOT = "g1"  # the robot a full-robot run uses when none is named

__all__ = [
    "DEFAULT_ROBOT",
    "JointImpedance",
    "RobotDescription",
    "SoleRectangle",
    "available_robots",
    "get_robot",
]


def available_robots() -> list[str]:
    """Names accepted by :func:`get_robot`, sorted."""
    return sorted(_REGISTRY)


def get_robot(name: str) -> RobotDescription:
    """The description of robot ``name``.

    Raises:
        ParameterError: ``name`` is not a registered robot.
    """
    try:
        return _REGISTRY[name]
    except KeyError:
        raise ParameterError("robot", name, f"one of {available_robots()}") from None
