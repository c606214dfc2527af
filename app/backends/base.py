"""The interface between the closed loop and a simulation backend.

A backend owns the simulated robot (a point-mass LIPM or a full humanoid). Each
control tick the loop gives it the planner's command and the push force, and it
returns the measured state for the next tick. The same planner runs on every
backend, so the cheap LIPM backend can stand in for the robot in tests.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol

import numpy as np

from planner.types import Foothold, MeasuredState, PlannerOutput, Vector2


@dataclass(frozen=True)
class InitialCondition:
    """Where a run starts.

    Attributes:
        stance: Initial stance foothold (the foot that carries the robot first).
        swing: Initial position of the other foot.
        com_position: Initial horizontal CoM [m].
        com_velocity: Initial horizontal CoM velocity [m/s].
    """

    stance: Foothold
    swing: Foothold
    com_position: Vector2
    com_velocity: Vector2


@dataclass(frozen=True)
class FallStatus:
    """Whether the robot has fallen, and why."""

    fell: bool
    reason: str = ""


class Backend(Protocol):
    """A simulated biped driven by a step planner.

    Attributes:
        name: Backend name written to the results (``"lipm"``, ``"pybullet"``).
        mass: Total mass m [kg] the planner should use.
        com_height: Nominal height of the CoM above the ground [m] (where it is drawn).
        control_period: Duration of one :meth:`step` [s].
    """

    name: str
    mass: float
    com_height: float
    control_period: float

    def reset(self, initial: InitialCondition) -> MeasuredState:
        """Put the robot in its initial state and return the first measurement."""
        ...

    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        """Apply ``command`` and the push force [N] for one control period.

        Returns:
            The measured state at the end of the period.
        """
        ...

    def fall_status(self) -> FallStatus:
        """Whether the robot has fallen."""
        ...

    def close(self) -> None:
        """Release the backend's resources."""
        ...


def zero_push() -> Vector2:
    """A zero push force [N]."""
    return np.zeros(2)
