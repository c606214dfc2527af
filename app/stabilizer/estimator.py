"""State estimation: the robot's full state from one measurement record.

Two sources for the floating base, which the joint encoders and the IMU do not give:

* ``"truth"``: the simulator's base position and velocity (a motion-capture system);
* ``"odometry"``: leg odometry (the stance sole does not move; e.g. Bloesch et al.,
  "State estimation for legged robots", RSS 2012, without its filter): the base
  orientation and angular velocity come from the IMU, the base position from the
  stance sole's position, fixed when it became the stance foot, through the legs'
  forward kinematics, and the base velocity from the same constraint on velocities
  (the stance sole's velocity is zero).

Everything else (CoM, its velocity, the soles) follows from q and v through the
rigid-body model.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.lowlevel import RobotMeasurement
from kinematics.robot_model import RobotModel
from planner.exceptions import ParameterError

SOURCES = ("truth", "odometry")


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
    """The full state of the robot from encoders, IMU and (``truth``) the base.

    Args:
        model: The robot's rigid-body model (updated with each estimate).
        source: ``"truth"`` or ``"odometry"`` (module docstring).
    """

    def __init__(self, model: RobotModel, source: str = "truth") -> None:
        if source not in SOURCES:
            raise ParameterError("estimator", source, f"one of {', '.join(SOURCES)}")
        self.model = model
        self.source = source
        self._anchor: tuple[str, NDArray[np.float64]] | None = None

    def reset(self) -> None:
        self._anchor = None

    def update(self, measurement: RobotMeasurement, stance: str) -> RobotState:
        """Estimate the state; ``stance`` is the foot that carries the robot."""
        rotation = Rotation.from_quat(measurement.base_orientation).as_matrix()
        q = np.concatenate(
            [measurement.base_position, measurement.base_orientation, measurement.joint_positions]
        )
        v = np.concatenate(
            [
                rotation.T @ measurement.base_linear_velocity,
                measurement.base_angular_velocity,
                measurement.joint_velocities,
            ]
        )
        model = self.model
        if self.source == "odometry" and self._anchor is not None:
            # Through the foot that stood until now; a new stance foot is anchored
            # where that estimate puts it.
            q, v = self._odometry(q, v, self._anchor[0])
        model.update(q, v)
        if self._anchor is None or self._anchor[0] != stance:
            self._anchor = (stance, model.sole_frame(stance)[0])
        return RobotState(measurement.time, q, v, model.com, model.com_velocity)

    def _odometry(
        self, q: NDArray[np.float64], v: NDArray[np.float64], stance: str
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Base position and velocity from the stance sole (leg odometry)."""
        model = self.model
        assert self._anchor is not None
        # Base at the origin: where the stance sole is relative to the base.
        q = q.copy()
        q[:3] = 0.0
        model.update(q, v)
        sole, _ = model.sole_frame(stance)
        q[:3] = self._anchor[1] - sole
        model.update(q, v)
        # Stance sole velocity zero: J_base v_base + J_joints v_joints = 0 (linear rows).
        jacobian = model.foot_jacobian(stance)
        offset = model.sole_frame(stance)[0] - model.ankle_frame(stance)[0]
        linear = jacobian[:3] - _skew(offset) @ jacobian[3:]
        v = v.copy()
        known = linear[:, 3:] @ v[3:]
        v[:3] = np.linalg.solve(linear[:, :3], -known)
        return q, v


def _skew(vector: NDArray[np.float64]) -> NDArray[np.float64]:
    x, y, z = vector
    return np.array([[0.0, -z, y], [z, 0.0, -x], [-y, x, 0.0]])
