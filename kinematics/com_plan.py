"""Horizontal CoM plan of the linear inverted pendulum with angular momentum.

Model (world frame, horizontal components):

    c_dd = g / c_z (c - p) + S hdot / (m c_z),   S = [[0, -1], [1, 0]],

with ZMP p [m] and rate of change of centroidal angular momentum hdot [N m]
constant over the horizon. Writing p_eff = p - S hdot / (m g) (the centroidal
moment pivot) it is c_dd = omega^2 (c - p_eff), solved in closed form.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError

GRAVITY = 9.81  # [m/s^2]
ROTATION_90 = np.array([[0.0, -1.0], [1.0, 0.0]])


def lipm_integrate(
    com_position: NDArray[np.float64],
    com_velocity: NDArray[np.float64],
    zmp: NDArray[np.float64],
    angular_momentum_rate: NDArray[np.float64],
    mass: float,
    com_height: float,
    duration: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """CoM position [m] and velocity [m/s] after ``duration`` [s].

    Args:
        com_position: Horizontal CoM c [m], shape (2,).
        com_velocity: Horizontal CoM velocity [m/s], shape (2,).
        zmp: ZMP p [m], shape (2,), constant over ``duration``.
        angular_momentum_rate: hdot [N m], shape (2,), constant over ``duration``.
        mass: Total mass m [kg].
        com_height: CoM height c_z [m].
        duration: Horizon [s], >= 0.
    """
    if not mass > 0.0:
        raise ParameterError("mass", mass, "> 0 kg")
    if not com_height > 0.0:
        raise ParameterError("com_height", com_height, "> 0 m")
    if not duration >= 0.0:
        raise ParameterError("duration", duration, ">= 0 s")
    omega = np.sqrt(GRAVITY / com_height)
    pivot = np.asarray(zmp, float) - ROTATION_90 @ np.asarray(angular_momentum_rate, float) / (
        mass * GRAVITY
    )
    offset = np.asarray(com_position, float) - pivot
    velocity = np.asarray(com_velocity, float)
    cosh, sinh = np.cosh(omega * duration), np.sinh(omega * duration)
    position = pivot + offset * cosh + velocity / omega * sinh
    new_velocity = offset * omega * sinh + velocity * cosh
    return position, new_velocity
