"""The robot's low-level interface: what the controller sends and what it reads.

Modelled on the Unitree G1's own low level (``LowCmd`` / ``LowState`` of unitree_sdk2):
per joint, a target angle and velocity, a stiffness and damping and a feed-forward
torque, evaluated by the motor at its own rate as

    tau = kp (q* - q) + kd (qd* - qd) + tau_ff,    clipped at the joint's effort limit;

and back, per tick, the joint encoders, the IMU and (on robots that have them) foot
force sensors. The simulator's truth that a real robot does not measure is kept in
separate fields, so the controller's use of it is visible.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray


@dataclass(frozen=True)
class JointCommand:
    """One control tick's command to every actuated joint (arrays in joint order).

    Attributes:
        position: Target angles q* [rad].
        velocity: Target velocities qd* [rad/s].
        stiffness: kp [N m/rad].
        damping: kd [N m s/rad].
        torque: Feed-forward torques tau_ff [N m].
    """

    position: NDArray[np.float64]
    velocity: NDArray[np.float64]
    stiffness: NDArray[np.float64]
    damping: NDArray[np.float64]
    torque: NDArray[np.float64]


@dataclass(frozen=True)
class FootForce:
    """A foot's ground reaction, from a foot force sensor.

    Attributes:
        normal_force: Vertical force [N] (>= 0).
        cop: Centre of pressure on the ground [m], shape (2,).
    """

    normal_force: float
    cop: NDArray[np.float64]


@dataclass(frozen=True)
class RobotMeasurement:
    """What the controller reads at the start of a tick.

    On a real G1: ``joint_positions`` and ``joint_velocities`` (motor encoders),
    ``base_orientation`` and ``base_angular_velocity`` (the pelvis IMU). Foot force
    sensors are an option of some G1 versions; here they are simulated from the
    contact forces (``foot_forces``). ``base_position`` and ``base_linear_velocity``
    are the simulator's truth: a real robot estimates them (leg odometry,
    :mod:`app.stabilizer.estimator`).

    Attributes:
        time: Time [s].
        joint_positions: Joint angles [rad], in the robot's joint order.
        joint_velocities: Joint velocities [rad/s].
        base_orientation: Pelvis orientation, quaternion (x, y, z, w).
        base_angular_velocity: Pelvis angular velocity in the pelvis frame [rad/s].
        foot_forces: Foot -> its ground reaction (feet without contact absent).
        base_position: Pelvis position in the world [m] (simulator truth).
        base_linear_velocity: Pelvis velocity in the world [m/s] (simulator truth).
    """

    time: float
    joint_positions: NDArray[np.float64]
    joint_velocities: NDArray[np.float64]
    base_orientation: NDArray[np.float64]
    base_angular_velocity: NDArray[np.float64]
    foot_forces: dict[str, FootForce]
    base_position: NDArray[np.float64]
    base_linear_velocity: NDArray[np.float64]

    def normal_force(self, foot: str) -> float:
        """Vertical ground force on ``foot`` [N] (0 without contact)."""
        reading = self.foot_forces.get(foot)
        return 0.0 if reading is None else reading.normal_force
