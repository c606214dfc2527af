"""The robot's sensors, simulated from the simulator's truth.

What a G1 senses (:class:`app.lowlevel.RobotMeasurement`): per motor the encoder's angle
and velocity and the torque estimated from the motor current; the pelvis IMU's attitude,
gyroscope and accelerometer; and, only on robots whose description has them, the
ankles' force-torque sensors. Each reading gets white Gaussian noise with the standard
deviations of the run's reality (:mod:`app.reality`); the gyroscope has a constant bias
about its z axis, and the IMU's yaw, integrated from it as an attitude filter does, drifts
by that bias times the time (roll and pitch are referenced to gravity and do not drift).
The attitude's roll and pitch error is not white: an attitude filter's output is the
gyroscope's integral corrected slowly towards the accelerometer's gravity, so its error
wanders with the filter's time constant; it is a first-order Gauss-Markov process with
standard deviation ``orientation`` and correlation time :data:`ATTITUDE_CORRELATION_TIME`.
The accelerometer reads the specific force at the IMU's place averaged over the tick
(the velocity change of that point over the tick, as an IMU's anti-aliasing filter
averages it). The noise is drawn from the run's own seeded stream: the same run reads
the same noise.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.lowlevel import FootForce, ImuReading, RobotMeasurement, SimulatorTruth
from app.reality import SensorNoise
from robots.description import RobotDescription

GRAVITY = 9.81  # [m/s^2]
# [s] an attitude filter's crossover between gyroscope and gravity (a complementary
# filter's time constant, e.g. Mahony et al., IEEE TAC 2008, gains of about 1 rad/s)
ATTITUDE_CORRELATION_TIME = 1.0


class Sensors:
    """The sensor readings of one simulated robot.

    Args:
        description: The robot (its IMU's place and whether it has foot sensors).
        noise: Noise levels (None: exact readings).
        yaw_bias: The gyroscope's constant bias about its z axis [rad/s].
        rng: The noise's random stream.
    """

    def __init__(
        self,
        description: RobotDescription,
        noise: SensorNoise | None = None,
        yaw_bias: float = 0.0,
        rng: np.random.Generator | None = None,
    ) -> None:
        self.imu_position = np.asarray(description.imu_position, float)
        self.foot_sensors = description.foot_force_sensors
        self.noise = noise
        self._rng = rng or np.random.default_rng(0)
        self._yaw_bias = yaw_bias
        self._tilt: NDArray[np.float64] | None = None  # [rad] the attitude's roll, pitch error
        self._last: tuple[float, NDArray[np.float64]] | None = None

    def reset(self, rng: np.random.Generator | None = None) -> None:
        """Forget the last reading (the accelerometer starts at rest); ``rng``: the noise's
        stream from here on (a run re-started with the same stream reads the same noise)."""
        self._last = None
        self._tilt = None
        if rng is not None:
            self._rng = rng

    def _imu_velocity(
        self, truth: SimulatorTruth, rotation: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """World velocity [m/s] of the IMU's place on the pelvis."""
        omega = rotation @ truth.base_angular_velocity
        return truth.base_linear_velocity + np.cross(omega, rotation @ self.imu_position)

    def read(self, truth: SimulatorTruth, joint_torques: NDArray[np.float64]) -> RobotMeasurement:
        """The readings at ``truth``, with the motors' applied torques [N m]."""
        rotation = Rotation.from_quat(truth.base_orientation).as_matrix()
        velocity = self._imu_velocity(truth, rotation)
        acceleration = np.zeros(3)
        elapsed = 0.0
        if self._last is not None and truth.time > self._last[0]:
            elapsed = truth.time - self._last[0]
            acceleration = (velocity - self._last[1]) / elapsed
        self._last = (truth.time, velocity)
        specific_force = rotation.T @ (acceleration + np.array([0.0, 0.0, GRAVITY]))
        gyroscope = truth.base_angular_velocity + np.array([0.0, 0.0, self._yaw_bias])
        attitude = Rotation.from_euler("z", self._yaw_bias * truth.time) * Rotation.from_matrix(
            rotation
        )
        positions = truth.joint_positions
        velocities = truth.joint_velocities
        torques = np.asarray(joint_torques, float)
        feet = None
        if self.foot_sensors:
            feet = {
                foot: truth.foot_forces.get(foot, FootForce(0.0, np.zeros(2)))
                for foot in ("left", "right")
            }
        noise = self.noise
        if noise is not None:
            rng = self._rng
            n = len(positions)
            positions = positions + rng.normal(0.0, noise.joint_position, n)
            velocities = velocities + rng.normal(0.0, noise.joint_velocity, n)
            torques = torques + rng.normal(0.0, noise.joint_torque, n)
            gyroscope = gyroscope + rng.normal(0.0, noise.gyroscope, 3)
            specific_force = specific_force + rng.normal(0.0, noise.accelerometer, 3)
            fresh = rng.normal(0.0, noise.orientation, 2)
            if self._tilt is None:
                self._tilt = fresh
            else:
                keep = np.exp(-elapsed / ATTITUDE_CORRELATION_TIME)
                self._tilt = keep * self._tilt + np.sqrt(1.0 - keep**2) * fresh
            attitude = attitude * Rotation.from_rotvec([self._tilt[0], self._tilt[1], 0.0])
            if feet is not None:
                feet = {
                    foot: FootForce(
                        max(reading.normal_force + rng.normal(0.0, noise.foot_force), 0.0),
                        reading.cop,
                    )
                    for foot, reading in feet.items()
                }
        return RobotMeasurement(
            time=truth.time,
            joint_positions=positions,
            joint_velocities=velocities,
            joint_torques=torques,
            imu=ImuReading(attitude.as_quat(), gyroscope, specific_force),
            foot_forces=feet,
        )
