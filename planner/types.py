"""Value objects crossing the boundary between the planner and a simulation backend.

Frames: all positions are horizontal, in the world frame, x forward, y to the left
[m]. A foot is ``"left"`` or ``"right"``; the paper's stance indicator is
``sigma = +1`` for the left stance foot and ``-1`` for the right one.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

import numpy as np
from numpy.typing import NDArray

Foot = Literal["left", "right"]
Vector2 = NDArray[np.float64]


def sigma_of(foot: Foot) -> int:
    """Stance indicator sigma of the paper (+1 left stance, -1 right stance)."""
    return 1 if foot == "left" else -1


def other_foot(foot: Foot) -> Foot:
    """The other foot."""
    return "right" if foot == "left" else "left"


@dataclass(frozen=True)
class Foothold:
    """A foot on the ground.

    Attributes:
        foot: Which foot.
        position: Ankle position o_H in the world frame [m], shape (2,).
    """

    foot: Foot
    position: Vector2


@dataclass(frozen=True)
class Push:
    """An impulsive push f_H on the CoM (constant force over its duration).

    Attributes:
        time: Start time t_f [s].
        impulse: Impulse i_H [N s], shape (2,).
        duration: Duration Delta_f [s], > 0.
    """

    time: float
    impulse: Vector2
    duration: float = 0.1

    def force_at(self, time: float) -> Vector2:
        """Force [N] the push applies at ``time`` [s] (zero outside the push)."""
        if self.time <= time < self.time + self.duration:
            return np.asarray(self.impulse, dtype=float) / self.duration
        return np.zeros(2)

    def as_dict(self) -> dict:
        return {
            "t": float(self.time),
            "impulse": [float(v) for v in self.impulse],
            "duration": float(self.duration),
        }


@dataclass(frozen=True)
class MeasuredState:
    """What the planner needs from the robot, measured by a backend.

    Attributes:
        time: Time [s].
        com_position: Horizontal CoM c_H in the world [m], shape (2,).
        com_velocity: Horizontal CoM velocity [m/s], shape (2,). A robot whose limbs
            carry angular momentum may report the velocity of its momentum about the CoP
            instead (the CoM's once the limbs' momentum is back in the CoM), which moves
            as the LIPM's.
        swing_contact: Whether the swing sole touches the ground, when the backend
            measures it (foot force sensors); a jump that is due while it is False waits
            for the touchdown. None: the planner steps at its own jump time.
        stance_sole: Where the stance foot's sole stands, measured [m], shape (2,),
            when the backend reports it (once a step, after the double support):
            the planner moves its stance foothold o_H there, so its ZMP window and
            DCM error refer to the real foot. None: o_H stays where it stepped.
    """

    time: float
    com_position: Vector2
    com_velocity: Vector2
    swing_contact: bool | None = None
    stance_sole: Vector2 | None = None


@dataclass(frozen=True)
class StepEvent:
    """A jump of the hybrid LIPM: a new stance foot.

    Attributes:
        time: Step time s_j [s].
        foot: The new stance foot.
        position: Its ankle position o_H(s_j) [m].
        timing_adjusted: The step time came from D_T (not the nominal D_S).
        location_adjusted: The location came from the QP (27), not 2 xi1*.
        lyapunov_before: V_u(e_u(s_j^-)), just before the jump.
        lyapunov_after: V_u(e_u(s_j^+)), the post-step level V_u^dagger.
    """

    time: float
    foot: Foot
    position: Vector2
    timing_adjusted: bool
    location_adjusted: bool
    lyapunov_before: float = 0.0
    lyapunov_after: float = 0.0

    @property
    def adjusted(self) -> bool:
        """True when the step time or location was adjusted by the RSG."""
        return self.timing_adjusted or self.location_adjusted

    def as_dict(self) -> dict:
        return {
            "t": float(self.time),
            "foot": self.foot,
            "position": [float(v) for v in self.position],
            "adjusted": bool(self.adjusted),
            "timing_adjusted": bool(self.timing_adjusted),
            "location_adjusted": bool(self.location_adjusted),
            "lyapunov_before": float(self.lyapunov_before),
            "lyapunov_after": float(self.lyapunov_after),
        }


@dataclass(frozen=True)
class PlannerOutput:
    """What the reactive step generator commands at one control tick.

    Attributes:
        time: Time [s].
        zmp: Commanded ZMP p_H = o_H + p~_H + r~_H in the world [m].
        zmp_offset: p~_H = p_H - r_H [m] (the continuous input, bounded by (8)).
        window_center: r_H, the reference point of the moving ZMP window [m].
        angular_momentum_rate: Rate of change of centroidal angular momentum hdot_H
            [N m], shape (2,): feedback plus double-support compensation.
        angular_momentum_rate_feedback: Its feedback part (filtered sat(K_u e_u)),
            bounded by (12a) [N m].
        stance: Current stance foothold (o_H, sigma).
        previous_stance: Stance foothold before the last step.
        next_step: Where the swing foot is planned to land (re-planned every tick).
        next_step_time: When the planner expects to step [s] (re-planned every tick):
            the reference's next nominal jump, or the earliest step time
            s_{j-1} + T_DSP + T_SP while D_T,1 is about to fire.
        time_since_step: s~ = t - s_{j-1} [s].
        double_support: True while s~ < T_DSP.
        dcm_error: e_u (18) [m].
        lyapunov: V_u(e_u) (20).
        lyapunov_at_step: V_u^dagger, the post-step level of the last step.
        com_reference: xi1* + o_H, the reference CoM position [m].
        step: The step taken at this tick, if any.
        qp_infeasible: True if the QP (27) was infeasible at this tick's step.
    """

    time: float
    zmp: Vector2
    zmp_offset: Vector2
    window_center: Vector2
    angular_momentum_rate: Vector2
    angular_momentum_rate_feedback: Vector2
    stance: Foothold
    previous_stance: Foothold
    next_step: Foothold
    next_step_time: float
    time_since_step: float
    double_support: bool
    dcm_error: Vector2
    lyapunov: float
    lyapunov_at_step: float
    com_reference: Vector2
    step: StepEvent | None = None
    qp_infeasible: bool = False
    extra: dict = field(default_factory=dict)
