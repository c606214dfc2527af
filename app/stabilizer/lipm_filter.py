"""A Kalman filter of the CoM's horizontal state on the planner's pendulum, with an offset.

The CoM from the legs' kinematics is precise to a few millimetres, but its velocity sums
every joint's velocity noise and every impact's shake of the legs, and the planner's DCM
error grows with it at 1/omega. The pendulum says how the CoM moves under the pivot the
feet were asked for; this filter fuses that prediction with the kinematic measurement.

The model's CoM is not the robot's: a torso heavier or its CoM elsewhere than the URDF
says, or a CoP that sits off the one asked for, makes the measured CoM accelerate as if
the pendulum hung from a shifted pivot. The filter estimates that shift as a slowly
drifting CoM offset d (true CoM = kinematic CoM + d), observable through the pendulum's
dynamics, and returns the CoM with it: B. Stephens, "State estimation for
force-controlled humanoid balance using simple models in the presence of modeling
error", ICRA 2011 (the "CoM offset" model). Both axes share one covariance.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError


class LipmFilter:
    """Horizontal CoM position, velocity and offset, filtered on the LIPM.

    Args:
        omega: The pendulum's natural frequency [1/s].
        process_noise: The model's error as white acceleration [m/s^2] (the CoP's
            tracking error, angular momentum, a push).
        position_noise: The kinematic CoM's error [m].
        velocity_noise: The kinematic CoM velocity's error [m/s].
        offset_drift: How fast the CoM offset may drift, as a random walk [m/sqrt(s)];
            0 estimates no offset.
        max_offset: The largest offset believed [m] (the estimate is clipped to it).
    """

    def __init__(
        self,
        omega: float,
        process_noise: float,
        position_noise: float,
        velocity_noise: float,
        offset_drift: float = 0.0,
        max_offset: float = 0.1,
    ) -> None:
        for name, value in (
            ("omega", omega),
            ("process_noise", process_noise),
            ("position_noise", position_noise),
            ("velocity_noise", velocity_noise),
            ("max_offset", max_offset),
        ):
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(name, value, "a number > 0")
        if not (math.isfinite(offset_drift) and offset_drift >= 0.0):
            raise ParameterError("offset_drift", offset_drift, "a number >= 0")
        self.omega = omega
        self.process_noise = process_noise
        self.offset_drift = offset_drift
        self.max_offset = max_offset
        self._measurement = np.diag([position_noise**2, velocity_noise**2])
        self._observe = np.eye(2, 3)  # the kinematic CoM's position and velocity
        # rows: kinematic position, velocity, offset; columns: x, y
        self._x: NDArray[np.float64] | None = None
        self._p = self._initial_covariance()

    def _initial_covariance(self) -> NDArray[np.float64]:
        covariance = np.zeros((3, 3))
        covariance[:2, :2] = self._measurement
        return covariance

    @property
    def offset(self) -> NDArray[np.float64]:
        """The CoM offset estimate [m], shape (2,): true CoM = kinematic CoM + offset."""
        return np.zeros(2) if self._x is None else self._x[2].copy()

    def reset(self) -> None:
        """Start again from the next measurement (with no offset)."""
        self._x = None
        self._p = self._initial_covariance()

    def update(
        self,
        position: NDArray[np.float64],
        velocity: NDArray[np.float64],
        pivot: NDArray[np.float64],
        dt: float,
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The filtered CoM position (offset included) [m] and velocity [m/s], shape (2,)
        each, from the kinematic ones and the pivot [m] the feet were given over the last
        ``dt`` [s]."""
        measured = np.vstack([position, velocity]).astype(float)
        if self._x is None or dt <= 0.0:
            if self._x is None:
                self._x = np.vstack([measured, np.zeros((1, 2))])
            return self._x[0] + self._x[2], self._x[1].copy()
        w = self.omega
        c, s = math.cosh(w * dt), math.sinh(w * dt)
        # The pendulum about pivot - offset, written on (kinematic CoM, velocity, offset).
        transition = np.array([[c, s / w, c - 1.0], [w * s, c, w * s], [0.0, 0.0, 1.0]])
        drive = np.array([[1.0 - c], [-w * s], [0.0]])
        predicted = transition @ self._x + drive @ pivot[None, :]
        spread = np.array([[0.5 * dt * dt], [dt], [0.0]])
        covariance = transition @ self._p @ transition.T + self.process_noise**2 * (
            spread @ spread.T
        )
        covariance[2, 2] += self.offset_drift**2 * dt
        h = self._observe
        gain = covariance @ h.T @ np.linalg.inv(h @ covariance @ h.T + self._measurement)
        self._x = predicted + gain @ (measured - h @ predicted)
        self._x[2] = np.clip(self._x[2], -self.max_offset, self.max_offset)
        self._p = (np.eye(3) - gain @ h) @ covariance
        return self._x[0] + self._x[2], self._x[1].copy()
