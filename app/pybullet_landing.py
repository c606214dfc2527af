"""Landing correction: the swing foot aims where the planner will put its foothold.

The planner announces ``next_step`` every tick, but its jump comes at the first
control tick after the reference reaches the step set, so its foothold o_H (2 xi1*
at the jump) is a little further along than the last announcement. Measured on G1
with the nominal gait (0.1 m x 0.2 m steps, 10 ms ticks): o_H was 4.5 mm further
forward and 7 mm further outward than the announced position at every step.

The IK puts the stance sole at o_H, so a foot that landed on the announcement
stands (4.5, 7) mm from where the IK believes it is; the whole real robot is then
offset from the IK by that much, and the next foot lands that much short again:
the offsets add up (measured: the stance foot 2.8 cm behind o_H after 12 steps,
with a DCM error e_x growing from -0.2 cm to -1.2 cm that the planner's continuous
feedback did not remove).

:class:`LandingCorrection` learns the last jump's discrepancy in the stepping
foot's frame (x forward, y outward) and adds it to the announced position.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError
from planner.types import Foot, PlannerOutput, other_foot, sigma_of


class LandingCorrection:
    """The gap between the planner's foothold at its jump and its last announcement.

    Attributes:
        gain: Fraction [-] per axis (x forward, y outward) of each newly observed
            discrepancy taken into the estimate (1: the last step's; 0: off).
        limit: Bound on the correction per axis [m].
        correction: Current estimate (x forward, y outward) [m], shape (2,).
    """

    def __init__(self, gain: float | tuple[float, float] = 0.0, limit: float = 0.03) -> None:
        gains = np.broadcast_to(np.asarray(gain, float), (2,)).copy()
        if not (np.all((gains >= 0.0) & (gains <= 1.0)) and limit > 0.0):
            raise ParameterError("landing correction", (gain, limit), "gains in [0, 1], limit > 0")
        self.gain = gains
        self.limit = limit
        self.correction = np.zeros(2)
        self._announced: NDArray[np.float64] | None = None

    def reset(self) -> None:
        """Forget what was learned."""
        self.correction = np.zeros(2)
        self._announced = None

    def observe(self, command: PlannerOutput) -> None:
        """Learn from a jump of this tick; remember the announcement for the next."""
        if command.step is not None and self._announced is not None and np.any(self.gain > 0.0):
            gap = np.asarray(command.stance.position, float) - self._announced
            outward = np.array([gap[0], sigma_of(command.stance.foot) * gap[1]])
            estimate = self.correction + self.gain * (outward - self.correction)
            self.correction = np.clip(estimate, -self.limit, self.limit)
        self._announced = np.asarray(command.next_step.position, float).copy()

    def target(self, command: PlannerOutput) -> NDArray[np.float64]:
        """Where the swing foot should land [m], shape (2,)."""
        swing: Foot = other_foot(command.stance.foot)
        shift = np.array([self.correction[0], sigma_of(swing) * self.correction[1]])
        return np.asarray(command.next_step.position, float) + shift
