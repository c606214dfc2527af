"""Re-targetable swing-foot trajectory matched to the planner's step timing.

Timing (s~ = time since the last step [s]), from the planner's model:

* ``s~ < T_DSP``: double support, the foot stays on the ground;
* ``T_DSP <= s~ <= landing``: the foot lifts (``sin^2`` profile, apex
  ``apex_height`` half-way) and touches the ground with zero vertical velocity at
  ``landing`` = the planner's planned step time when the caller knows it, else
  the nominal step time T_DSP + T_SSP. Horizontally it arrives above the landing
  target ``arrival_lead`` before landing, never earlier than the ready time
  T_DSP + T_SP.

Measured on G1: arriving horizontally at the ready time (0.2 s after lift-off)
needs foot accelerations of ~30 m/s^2; the legs (7 kg each of 33 kg) then shift
the real ZMP by several cm and the stance foot pivots and spins. A swing timed
on the planned step time is therefore the default; a foot still in the air at
the planned time is the caller's to bring down (the planner's jump then waits for
the measured touchdown).

Horizontally, each update re-plans a cubic from the current position/velocity to
the current target with zero final velocity, over the time left until arrival
(at least ``min_horizontal_time``), and takes one ``dt`` of it; the speed is
bounded by ``max_speed``. A target that moves during the swing is thus tracked
smoothly, and after arrival the foot follows it like a critically damped filter.
The height changes at most ``max_vertical_speed`` per second, so a change of the
landing time does not make the foot jump.

Reactive steps (the planner moves the step earlier and the foothold away while the
foot is in the air) need two more bounds, both off unless given:

* ``max_acceleration`` [m/s^2]: the horizontal horizon is at least
  sqrt(6 d / a_max) for a distance d to go (the peak acceleration of a
  rest-to-rest cubic), so a foothold that jumps away is reached with bounded
  leg accelerations instead of within ``min_horizontal_time``;
* ``descent_slope`` [-]: while the foot is d away from the target horizontally
  it does not descend below ``descent_slope * d`` (it is never raised by it), so
  it arrives from above instead of dragging over the ground.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError


@dataclass(frozen=True)
class SwingTiming:
    """Step timing of the planner [s].

    Attributes:
        double_support: T_DSP, time after a step with both feet on the ground [s].
        ready: T_SP, time after the end of the DSP by which the foot can land [s].
        nominal_step: Nominal time between steps, T_DSP + T_SSP [s].
    """

    double_support: float = 0.1
    ready: float = 0.2
    nominal_step: float = 0.8

    def __post_init__(self) -> None:
        if not self.double_support >= 0.0:
            raise ParameterError("double_support", self.double_support, ">= 0 s")
        if not self.ready > 0.0:
            raise ParameterError("ready", self.ready, "> 0 s")
        if not self.nominal_step >= self.double_support + self.ready:
            raise ParameterError("nominal_step", self.nominal_step, ">= double_support + ready")

    @property
    def ready_time(self) -> float:
        """s~ at which the foot can land [s]."""
        return self.double_support + self.ready


def swing_height(time_since_step: float, lift_off: float, landing: float, apex: float) -> float:
    """Height of the swing sole above the ground [m] at s~ [s].

    ``apex * sin^2(pi phase)`` with phase = (s~ - lift_off) / (landing - lift_off)
    clipped to [0, 1]: zero height and zero vertical velocity at both ends.
    """
    if landing <= lift_off:
        return 0.0
    phase = min(max((time_since_step - lift_off) / (landing - lift_off), 0.0), 1.0)
    return apex * np.sin(np.pi * phase) ** 2


def swing_yaw(
    time_since_step: float, lift_off: float, landing: float, start: float, end: float
) -> float:
    """Yaw [rad] of the swing sole at s~ [s]: ``start``, the yaw the foot stood at, until
    ``lift_off``, then turning at a constant rate the shorter way to ``end``, reached at
    ``landing``.

    A target that jumped to ``end`` at the step twisted the foot while it was still loaded
    in the double support and spun the new stance foot (docs/notes/2026-12-05-swing-yaw.md).
    """
    arrival = start + math.remainder(end - start, 2.0 * math.pi)  # end, the shorter way
    progress = min(max((time_since_step - lift_off) / max(landing - lift_off, 1e-6), 0.0), 1.0)
    return start * (1.0 - progress) + arrival * progress


class SwingFootTrajectory:
    """Stateful swing-foot position generator, updated once per control tick.

    Attributes:
        position: Current sole position in the world [m], shape (3,).
        velocity: Current horizontal sole velocity [m/s], shape (2,).
    """

    def __init__(
        self,
        timing: SwingTiming,
        apex_height: float = 0.06,
        arrival_lead: float = 0.1,
        max_speed: float = 2.0,
        max_vertical_speed: float = 1.0,
        min_horizontal_time: float = 0.05,
        ground_height: float = 0.0,
        max_acceleration: float | None = None,
        descent_slope: float = 0.0,
        land_on_time: bool = False,
    ) -> None:
        """Set the parameters.

        Args:
            timing: The planner's step timing.
            apex_height: Highest sole height above the ground [m].
            arrival_lead: Time before landing at which the foot is above the
                target [s].
            max_speed: Bound on the horizontal sole speed [m/s].
            max_vertical_speed: Bound on the vertical sole speed [m/s].
            min_horizontal_time: Shortest horizontal re-planning horizon [s].
            ground_height: Height of the ground [m].
            max_acceleration: Bound [m/s^2] on the horizontal acceleration of
                a re-planned approach (None: only ``min_horizontal_time``).
            descent_slope: Height [m] kept per metre still to go horizontally.
            land_on_time: The ``max_acceleration`` horizon never reaches past the
                landing time: the foot is above the target when it lands, at the
                cost of larger accelerations in its last moments.
        """
        if not 0.0 < apex_height < 0.5:
            raise ParameterError("apex_height", apex_height, "0 < h < 0.5 m")
        if not arrival_lead >= 0.0:
            raise ParameterError("arrival_lead", arrival_lead, ">= 0 s")
        if not (max_speed > 0.0 and max_vertical_speed > 0.0):
            raise ParameterError("max_speed", (max_speed, max_vertical_speed), "> 0 m/s")
        if not min_horizontal_time > 0.0:
            raise ParameterError("min_horizontal_time", min_horizontal_time, "> 0 s")
        self.timing = timing
        self.apex_height = apex_height
        self.arrival_lead = arrival_lead
        self.max_speed = max_speed
        self.max_vertical_speed = max_vertical_speed
        self.min_horizontal_time = min_horizontal_time
        self.ground_height = ground_height
        if max_acceleration is not None and not max_acceleration > 0.0:
            raise ParameterError("max_acceleration", max_acceleration, "> 0 m/s^2 or None")
        if not 0.0 <= descent_slope <= 10.0:
            raise ParameterError("descent_slope", descent_slope, "in [0, 10]")
        self.max_acceleration = max_acceleration
        self.descent_slope = descent_slope
        self.land_on_time = land_on_time
        self.position = np.zeros(3)
        self.velocity = np.zeros(2)

    def start(self, liftoff_position: NDArray[np.float64]) -> None:
        """Begin a swing from ``liftoff_position`` (x, y [, z]) [m], at rest."""
        self.position = np.array([liftoff_position[0], liftoff_position[1], self.ground_height])
        self.velocity = np.zeros(2)

    def update(
        self,
        time_since_step: float,
        target_xy: NDArray[np.float64],
        dt: float,
        landing_time: float | None = None,
    ) -> NDArray[np.float64]:
        """Advance by ``dt`` [s] and return the sole position [m], shape (3,).

        Args:
            time_since_step: s~ at the END of this update [s].
            target_xy: Current landing target (x, y) [m].
            dt: Time since the previous update [s], > 0.
            landing_time: Planned s~ of the touchdown [s]; None: the nominal step
                time. Clipped to at least the ready time T_DSP + T_SP.
        """
        if not dt > 0.0:
            raise ParameterError("dt", dt, "> 0 s")
        timing = self.timing
        landing = timing.nominal_step if landing_time is None else landing_time
        landing = max(landing, timing.ready_time)
        arrival = max(landing - self.arrival_lead, timing.ready_time)
        target = np.asarray(target_xy, dtype=float)
        if time_since_step > timing.double_support:
            remaining = max(arrival - (time_since_step - dt), 0.0)
            horizon = max(remaining, self.min_horizontal_time, dt)
            if self.max_acceleration is not None:
                distance = float(np.linalg.norm(target - self.position[:2]))
                bounded = float(np.sqrt(6.0 * distance / self.max_acceleration))
                if self.land_on_time:
                    bounded = min(bounded, max(landing - (time_since_step - dt), dt))
                horizon = max(horizon, bounded)
            position, velocity = _cubic_step(self.position[:2], self.velocity, target, horizon, dt)
            displacement = position - self.position[:2]
            limit = self.max_speed * dt
            norm = float(np.linalg.norm(displacement))
            if norm > limit:
                displacement *= limit / norm
                velocity = displacement / dt
            self.position[:2] = self.position[:2] + displacement
            self.velocity = velocity
        height = swing_height(time_since_step, timing.double_support, landing, self.apex_height)
        step_limit = self.max_vertical_speed * dt
        current = self.position[2] - self.ground_height
        if self.descent_slope > 0.0 and time_since_step > timing.double_support:
            to_go = float(np.linalg.norm(target - self.position[:2]))
            height = max(height, min(current, self.descent_slope * to_go))
        self.position[2] = self.ground_height + float(
            np.clip(height, current - step_limit, current + step_limit)
        )
        return self.position.copy()


def _cubic_step(
    position: NDArray[np.float64],
    velocity: NDArray[np.float64],
    target: NDArray[np.float64],
    horizon: float,
    dt: float,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """State after ``dt`` on the cubic from (position, velocity) to (target, 0) in ``horizon``."""
    tau = min(dt / horizon, 1.0)
    # Cubic Hermite basis with end velocity zero; derivatives scaled by 1/horizon.
    h00 = 2 * tau**3 - 3 * tau**2 + 1
    h10 = tau**3 - 2 * tau**2 + tau
    h01 = -2 * tau**3 + 3 * tau**2
    d00 = (6 * tau**2 - 6 * tau) / horizon
    d10 = 3 * tau**2 - 4 * tau + 1
    d01 = (-6 * tau**2 + 6 * tau) / horizon
    new_position = h00 * position + h10 * horizon * velocity + h01 * target
    new_velocity = d00 * position + d10 * velocity + d01 * target
    return new_position, new_velocity
