"""A Kalman filter of the CoM's horizontal state on the planner's pendulum.

The CoM from the legs' kinematics is precise to a few millimetres, but its velocity sums
every joint's velocity noise and every impact's shake of the legs, and the planner's DCM
error grows with it at 1/omega. The pendulum says how the CoM moves under the pivot the
feet were asked for; this filter fuses that prediction with the kinematic measurement
(B. Stephens, "State estimation for force-controlled humanoid balance using simple
models in the presence of modeling error", ICRA 2011: a Kalman filter on the LIPM with
the CoP as its input). Both horizontal axes share one covariance (same noise, same model).
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError


class LipmFilter:
    """Horizontal CoM position and velocity, filtered on the LIPM.

    Args:
        omega: The pendulum's natural frequency [1/s].
        process_noise: The model's error as white acceleration [m/s^2] (the CoP's
            tracking error, angular momentum, a push).
        position_noise: The kinematic CoM's error [m].
        velocity_noise: The kinematic CoM velocity's error [m/s].
    """

    def __init__(
        self, omega: float, process_noise: float, position_noise: float, velocity_noise: float
    ) -> None:
        for name, value in (
            ("omega", omega),
            ("process_noise", process_noise),
            ("position_noise", position_noise),
            ("velocity_noise", velocity_noise),
        ):
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(name, value, "a number > 0")
        self.omega = omega
        self.process_noise = process_noise
        self._measurement = np.diag([position_noise**2, velocity_noise**2])
        self._x: NDArray[np.float64] | None = None  # rows: position, velocity; columns: x, y
        self._p = self._measurement.copy()

    def reset(self) -> None:
        """Start again from the next measurement."""
        self._x = None
        self._p = self._measurement.copy()

    def update(
        self,
        position: NDArray[np.float64],
        velocity: NDArray[np.float64],
        pivot: NDArray[np.float64],
        dt: float,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The filtered CoM position [m] and velocity [m/s], shape (2,) each, from the
        kinematic ones and the pivot [m] the feet were given over the last ``dt`` [s]."""
        measured = np.vstack([position, velocity]).astype(float)
        if self._x is None or dt <= 0.0:
            self._x = measured
            return position.copy(), velocity.copy()
        w = self.omega
        c, s = math.cosh(w * dt), math.sinh(w * dt)
        transition = np.array([[c, s / w], [w * s, c]])
        relative = self._x - np.vstack([pivot, np.zeros(2)])
        predicted = transition @ relative + np.vstack([pivot, np.zeros(2)])
        spread = np.array([[0.5 * dt * dt], [dt]])
        covariance = transition @ self._p @ transition.T + self.process_noise**2 * (
            spread @ spread.T
        )
        gain = covariance @ np.linalg.inv(covariance + self._measurement)
        self._x = predicted + gain @ (measured - predicted)
        self._p = (np.eye(2) - gain) @ covariance
        return self._x[0].copy(), self._x[1].copy()
