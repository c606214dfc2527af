"""State estimation: the robot's full state from what it senses.

The joint encoders give the joints; the pelvis IMU's attitude and gyroscope give the
base's orientation and angular velocity (its yaw drifts as the IMU's does). The base's
position and velocity, which nothing measures, come from a Kalman filter that fuses the
accelerometer with leg kinematics (Bloesch et al., "State Estimation for Legged Robots:
Consistent Fusion of Leg Kinematics and IMU", RSS 2012, in the linear form of the MIT
Cheetah 3's estimator, Bledt et al., IROS 2018): the state is the base position and
velocity in the world; the prediction integrates the accelerometer's specific force,
rotated to the world, plus gravity; each foot in contact corrects it, its sole taken to
stay where it was at the last tick (position) and to be still (velocity), through the
legs' forward kinematics and Jacobians. Each foot is re-anchored at every tick where the
filter then puts it: the legs measure how far the base moved over the tick, not how far
from where the foot touched down (a sole that rolls onto its edge, as every push makes
the stance sole do, moves its frame's origin; anchored at its touchdown it pulled the
estimate back by centimetres).

The IMU's roll and pitch wander (an attitude filter's error is slow), and an error of
0.3 deg moves the CoM 4 mm against the stance sole. A foot flat on level ground is a tilt
sensor with the encoders' accuracy (the foot's orientation as a measurement, Rotella et
al., "State estimation for a humanoid robot", IROS 2014): the roll and pitch that make
the feet in contact level correct the IMU's, low-passed over ``TILT_CORRECTION_TIME`` so
that a foot rolling on its edge for a moment does not tilt the estimate.

Everything else (CoM, its velocity, the soles) follows from q and v through the
rigid-body model.
"""

from __future__ import annotations

from collections.abc import Collection, Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.lowlevel import RobotMeasurement
from kinematics.robot_model import RobotModel
from planner.types import Foot

GRAVITY = np.array([0.0, 0.0, -9.81])  # [m/s^2]
# The filter's noise: the accelerometer's, and the unmodelled lever-arm term of the
# IMU (the angular acceleration across 9 cm), as white acceleration [m/s^2]; a stance
# sole's position [m] and velocity [m/s] (a sole rolls and slips a little, an impact
# shakes the legs' velocities).
ACCELERATION_NOISE = 1.0
FOOT_POSITION_NOISE = 0.005
FOOT_VELOCITY_NOISE = 0.05
INITIAL_POSITION_NOISE = 0.01  # [m] where the robot is told it starts
TILT_CORRECTION_TIME = 0.1  # [s] low-pass of the feet's tilt correction of the IMU


@dataclass(frozen=True)
class RobotState:
    """The estimated state after :meth:`StateEstimator.update` (world frame, SI units).

    Attributes:
        time: [s].
        q: Configuration in the model's layout.
        v: Velocity in the model's layout.
        com: Centre of mass [m], shape (3,).
        com_velocity: [m/s], shape (3,).
    """

    time: float
    q: NDArray[np.float64]
    v: NDArray[np.float64]
    com: NDArray[np.float64]
    com_velocity: NDArray[np.float64]


class StateEstimator:
    """The full state of the robot from encoders, IMU and the feet in contact.

    Args:
        model: The robot's rigid-body model (updated with each estimate).
        imu_position: The IMU's place in the base frame [m], shape (3,).
    """

    def __init__(self, model: RobotModel, imu_position: NDArray[np.float64]) -> None:
        self.model = model
        self.imu_position = np.asarray(imu_position, float)
        self._x = np.zeros(6)  # base position [m], velocity [m/s], world
        self._p = np.eye(6)
        self._time: float | None = None
        self._anchors: dict[str, NDArray[np.float64]] = {}
        self._tilt = np.zeros(2)  # [rad] world x, y rotation that levels the feet

    def reset(
        self, soles: Mapping[Foot, NDArray[np.float64]], measurement: RobotMeasurement
    ) -> None:
        """Start standing with the soles at ``soles`` (world positions [m], shape (3,)),
        at rest: the base where the legs' kinematics put it."""
        q, _ = self._configuration(measurement, np.zeros(3))
        self.model.update(q, np.zeros(self.model.nv))
        offsets = [soles[foot] - self.model.sole_frame(foot)[0] for foot in soles]
        self._x = np.concatenate([np.mean(offsets, axis=0), np.zeros(3)])
        self._p = np.diag([INITIAL_POSITION_NOISE**2] * 3 + [FOOT_VELOCITY_NOISE**2] * 3)
        self._time = measurement.time
        self._anchors = {}
        self._tilt = np.zeros(2)

    def _configuration(
        self, measurement: RobotMeasurement, base_position: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        q = np.concatenate(
            [base_position, measurement.imu.orientation, measurement.joint_positions]
        )
        return q, Rotation.from_quat(measurement.imu.orientation).as_matrix()

    def update(self, measurement: RobotMeasurement, contacts: Collection[str]) -> RobotState:
        """Estimate the state; ``contacts`` are the feet standing on the ground."""
        dt = 0.0 if self._time is None else measurement.time - self._time
        self._time = measurement.time
        q, rotation = self._configuration(measurement, np.zeros(3))
        if contacts:
            self.model.update(q, np.zeros(self.model.nv))
            level = np.mean([_levelling(self.model.sole_frame(f)[1]) for f in contacts], axis=0)
            gain = min(dt / TILT_CORRECTION_TIME, 1.0) if dt > 0.0 else 1.0
            self._tilt += gain * (level - self._tilt)
        correction = Rotation.from_rotvec([self._tilt[0], self._tilt[1], 0.0])
        rotation = correction.as_matrix() @ rotation
        q[3:7] = (correction * Rotation.from_quat(measurement.imu.orientation)).as_quat()
        gyro = measurement.imu.angular_velocity
        omega = rotation @ gyro
        lever = rotation @ self.imu_position
        # The base origin's acceleration: the IMU's, less its centripetal part about it.
        acceleration = (
            rotation @ measurement.imu.linear_acceleration
            + GRAVITY
            - np.cross(omega, np.cross(omega, lever))
        )
        if dt > 0.0:
            self._predict(acceleration, dt)
        # Kinematics with the base at the origin: the soles relative to it, world axes.
        model = self.model
        v = np.concatenate([np.zeros(3), gyro, measurement.joint_velocities])
        model.update(q, v)
        for foot in list(self._anchors):
            if foot not in contacts:
                del self._anchors[foot]
        for foot in contacts:
            sole = model.sole_frame(foot)[0]
            if foot not in self._anchors:
                self._anchors[foot] = self._x[:3] + sole
            # The sole's velocity with the base still (world axes, at the sole).
            jacobian = model.foot_jacobian(foot)
            offset = sole - model.ankle_frame(foot)[0]
            linear = jacobian[:3] - _skew(offset) @ jacobian[3:]
            self._correct(self._anchors[foot] - sole, -(linear[:, 3:] @ v[3:]))
            self._anchors[foot] = self._x[:3] + sole
        q[:3] = self._x[:3]
        v[:3] = rotation.T @ self._x[3:]
        model.update(q, v)
        return RobotState(measurement.time, q, v, model.com, model.com_velocity)

    def _predict(self, acceleration: NDArray[np.float64], dt: float) -> None:
        x = self._x
        x[:3] += dt * x[3:] + 0.5 * dt * dt * acceleration
        x[3:] += dt * acceleration
        transition = np.eye(6)
        transition[:3, 3:] = dt * np.eye(3)
        noise = np.vstack([0.5 * dt * dt * np.eye(3), dt * np.eye(3)])
        self._p = transition @ self._p @ transition.T + ACCELERATION_NOISE**2 * noise @ noise.T

    def _correct(self, position: NDArray[np.float64], velocity: NDArray[np.float64]) -> None:
        """One foot's measurement of the base position and velocity (world)."""
        residual = np.concatenate([position, velocity]) - self._x
        covariance = self._p + np.diag([FOOT_POSITION_NOISE**2] * 3 + [FOOT_VELOCITY_NOISE**2] * 3)
        gain = np.linalg.solve(covariance, self._p).T
        self._x = self._x + gain @ residual
        self._p = (np.eye(6) - gain) @ self._p


def _levelling(rotation: NDArray[np.float64]) -> NDArray[np.float64]:
    """The world x, y rotation vector [rad] that turns a frame of ``rotation`` level
    (its z axis vertical)."""
    z = rotation[:, 2]
    axis = np.cross(z, [0.0, 0.0, 1.0])
    sine = float(np.linalg.norm(axis))
    if sine < 1e-12:
        return np.zeros(2)
    angle = float(np.arctan2(sine, z[2]))
    return np.asarray((axis / sine * angle)[:2], dtype=np.float64)


def _skew(vector: NDArray[np.float64]) -> NDArray[np.float64]:
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
