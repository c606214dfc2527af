"""Landing: the swing sole's last centimetres and the new stance sole's first moments.

Two rules on the height of the sole targets given to the IK:

* contact by the planned time: over the last ``WINDOW`` before the planner's landing
  time the swing sole's target sinks to ``depth`` below the ground, so that a sole
  tracking a few millimetres high still touches down by the step (a late touchdown
  leaves the CoP on the old foot), and past that time it goes on down at
  ``TOUCHDOWN_SPEED`` until the sole touches (the planner's jump waits for that). The
  rule times that wait from when the landing first fell due: while the planner waits it
  announces the held step at the current tick, so the time left it gives never falls
  below minus one tick;
* continuity at the step: the new stance sole's target starts where the swing
  sole's last target was and reaches the ground by the end of the double support
  (a target that jumped there in one tick kicked the old foot off the ground: 2.6 m g
  on the feet and 20 ms in the air at every step, measured on G1).
"""

from __future__ import annotations

WINDOW = 0.1  # [s] before the planned landing over which the target sinks
# [m/s] downwards past the planned landing until the sole touches (IHMC's swing
# parameters use 0.1-0.3; 0.3 against 0.1 on G1's development pushes: 98 and 95 recovered)
TOUCHDOWN_SPEED = 0.3
COMPLIANT_AFTER = 0.05  # [s] after a step over which the new stance leg stays compliant


class Landing:
    """Height offsets of the feet's targets around a step.

    Args:
        depth: Depth below the ground the swing sole aims at at the landing time [m].
        double_support: T_DSP, over which the new stance sole settles [s].
    """

    def __init__(self, depth: float, double_support: float) -> None:
        self.depth = depth
        self.double_support = double_support
        self._last_height = 0.0  # [m] the swing sole's last target height
        self._due: float | None = None  # [s] the swing's time at which the landing fell due

    def start_swing(self) -> None:
        """A new swing begins: its landing is not due yet."""
        self._due = None

    def swing_height(self, profile: float, time_to_landing: float, time_since_step: float) -> float:
        """Target height [m] of the swing sole.

        Args:
            profile: The swing trajectory's height [m].
            time_to_landing: Time left until the planned landing [s].
            time_since_step: Time since the swing began [s].
        """
        sink = self.depth * min(max(1.0 - time_to_landing / WINDOW, 0.0), 1.0)
        if time_to_landing < 0.0 and self._due is None:
            self._due = time_since_step + time_to_landing
        if self._due is not None:  # a late touchdown: on down until the sole touches
            sink += TOUCHDOWN_SPEED * max(time_since_step - self._due, 0.0)
        self._last_height = profile - sink
        return self._last_height

    @staticmethod
    def compliant(time_to_landing: float, time_since_landing: float) -> tuple[bool, bool]:
        """Whether the swing leg (about to land: within ``WINDOW`` of its planned landing
        or late) and the new stance leg (within ``COMPLIANT_AFTER`` of its landing) are to
        be compliant [s, s]."""
        return time_to_landing < WINDOW, time_since_landing < COMPLIANT_AFTER

    def stance_height(self, time_since_step: float) -> float:
        """Target height [m] of the new stance sole in the double support after a step."""
        return self._last_height * self.settling(time_since_step)

    def settling(self, time_since_step: float) -> float:
        """Share [-] of its way to the ground (and, in the controller, to its foothold) that
        the new stance sole's target still has to go: 1 at the step, 0 from the end of the
        double support on."""
        if self.double_support <= 0.0:
            return 0.0
        return max(0.0, 1.0 - time_since_step / self.double_support)
