"""The whole-body stabilizer's options: one typed record, checked when built."""

from __future__ import annotations

import math
from dataclasses import dataclass, fields

from planner.exceptions import ParameterError


@dataclass(frozen=True)
class StabilizerConfig:
    """Options of :class:`app.stabilizer.controller.WholeBodyController` (units in brackets).

    Attributes:
        landing_depth: How far below the ground the swing sole aims at the planned
            landing time [m], so it touches down by then rather than after.
        friction: Coulomb coefficient of the wrench distribution's contacts [-].
        flywheel_momentum: h_max, angular momentum the upper body may carry [N m s]
            (0: no flywheel; the whole hdot goes to the CoP).
        flywheel_return_time: T_r, band-pass of hdot for the flywheel and its return
            to the posture [s].
        flywheel_cancel: Share of the legs' high-passed angular momentum the upper
            body takes back [-] (a leg swinging outwards otherwise pulls the pivot
            off the stance sole's edge).
        height_frequency: omega_z, natural frequency of the CoM height loop in the net
            force, critically damped [rad/s] (0: the LIPM's m g): the feet's moments are
            planned for the force the legs will push with after a touchdown's bounce
            (docs/notes/2026-12-06-height-loop.md).
        landing_compliance: Share of the legs' joint stiffness and damping kept by the
            swing leg over the last 0.1 s before its planned landing and by the new stance
            leg over the first 0.05 s after the step [-] (1: always stiff): a compliant leg
            takes the impact rather than passing it to the body (impedance modulation,
            N. Hogan, "Impedance control", J. Dyn. Syst. Meas. Control 107, 1985).
    """

    landing_depth: float = 0.005
    friction: float = 0.7
    flywheel_momentum: float = 2.0
    flywheel_return_time: float = 0.5
    flywheel_cancel: float = 0.75
    height_frequency: float = 10.0
    landing_compliance: float = 0.3

    def __post_init__(self) -> None:
        for name, (low, high) in RANGES.items():
            value = getattr(self, name)
            if isinstance(value, bool) or not isinstance(value, int | float):
                raise ParameterError(name, value, f"a number in [{low:g}, {high:g}]")
            if not (math.isfinite(value) and low <= value <= high):
                raise ParameterError(name, value, f"a number in [{low:g}, {high:g}]")


#: Physically meaningful range of each number option (units as in the attributes).
RANGES: dict[str, tuple[float, float]] = {
    "landing_depth": (0.0, 0.02),
    "friction": (0.1, 2.0),
    "flywheel_momentum": (0.0, 10.0),
    "flywheel_return_time": (0.05, 10.0),
    "flywheel_cancel": (0.0, 1.0),
    "height_frequency": (0.0, 50.0),
    "landing_compliance": (0.05, 1.0),
}

OPTION_NAMES = tuple(field.name for field in fields(StabilizerConfig))
