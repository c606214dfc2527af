"""The robot's low-level interface: what the controller sends and what it reads.

Modelled on the Unitree G1's own low level (``LowCmd`` / ``LowState`` of unitree_sdk2,
``unitree_hg``): per joint, a target angle and velocity, a stiffness and damping and a
feed-forward torque, evaluated by the motor at its own rate as

    tau = kp (q* - q) + kd (qd* - qd) + tau_ff,    clipped at the motor's limit;

and back, per tick, what the robot senses: per motor the encoder's angle and velocity and
the estimated torque, the pelvis IMU (attitude, gyroscope, accelerometer) and, on robots
that have them (Talos, not G1), the ankles' force-torque sensors. The simulator's truth
is a separate record (:class:`SimulatorTruth`) for judging and logging only: the
controller's interface takes a :class:`RobotMeasurement`, which has no field of it.
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
    """A foot's ground reaction.

    Attributes:
        normal_force: Vertical force [N] (>= 0).
        cop: Centre of pressure on the ground [m], shape (2,).
    """

    normal_force: float
    cop: NDArray[np.float64]


@dataclass(frozen=True)
class ImuReading:
    """The pelvis IMU (its frame is the pelvis's, at ``RobotDescription.imu_position``).

    Attributes:
        orientation: Attitude, quaternion (x, y, z, w): roll and pitch referenced to
            gravity, yaw integrated from the gyroscope (it drifts).
        angular_velocity: Gyroscope [rad/s], IMU frame, shape (3,).
        linear_acceleration: Accelerometer [m/s^2], IMU frame, shape (3,): the specific
            force, acceleration minus gravity (+9.81 up at rest), averaged over the tick.
    """

    orientation: NDArray[np.float64]
    angular_velocity: NDArray[np.float64]
    linear_acceleration: NDArray[np.float64]


@dataclass(frozen=True)
class RobotMeasurement:
    """What the robot senses, read by the controller at the start of a tick.

    Attributes:
        time: Time [s].
        joint_positions: Encoder angles [rad], in the robot model's joint order.
        joint_velocities: Encoder velocities [rad/s].
        joint_torques: The motors' estimated torques [N m] (from their current).
        imu: The pelvis IMU.
        foot_forces: Foot -> its force-torque sensor's reading (feet in the air read
            zero), or None on a robot without foot sensors.
    """

    time: float
    joint_positions: NDArray[np.float64]
    joint_velocities: NDArray[np.float64]
    joint_torques: NDArray[np.float64]
    imu: ImuReading
    foot_forces: dict[str, FootForce] | None


@dataclass(frozen=True)
class SimulatorTruth:
    """The simulated robot's true state, for judging and logging only.

    Attributes:
        time: Time [s].
        base_position: Pelvis (URDF base frame) position in the world [m].
        base_orientation: Pelvis orientation, quaternion (x, y, z, w).
        base_linear_velocity: Pelvis origin velocity in the world [m/s].
        base_angular_velocity: Pelvis angular velocity in the pelvis frame [rad/s].
        joint_positions: Joint angles [rad], the model's joint order.
        joint_velocities: Joint velocities [rad/s].
        foot_forces: Foot -> its ground reaction (feet without contact absent).
    """

    time: float
    base_position: NDArray[np.float64]
    base_orientation: NDArray[np.float64]
    base_linear_velocity: NDArray[np.float64]
    base_angular_velocity: NDArray[np.float64]
    joint_positions: NDArray[np.float64]
    joint_velocities: NDArray[np.float64]
    foot_forces: dict[str, FootForce]
