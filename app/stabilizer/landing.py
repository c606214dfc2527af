"""Landing: the swing sole's last centimetres and the new stance sole's first moments.

Three rules on the height of the sole targets given to the IK:

* contact by the planned time: over the last ``WINDOW`` before the planner's landing
  time the swing sole's target sinks to ``depth`` below the ground, so that a sole
  tracking a few millimetres high still touches down by the step (a late touchdown
  leaves the CoP on the old foot while the planner has moved it to the new one);
* landing compliance (the contact-seeking admittance of Caron, Kheddar and Tempier,
  ICRA 2019): a touching swing sole rises at ``admittance`` metres per second per
  newton it carries above ``touch_force``, and sinks back with ``YIELD_TIME`` when
  unloaded, so it yields to the touchdown instead of pushing the robot off its
  stance foot or bouncing;
* continuity at the step: the new stance sole's target starts where the swing
  sole's last target was and reaches the ground by the end of the double support
  (a target that jumped there in one tick kicked the old foot off the ground: 2.6 m g
  on the feet and 20 ms in the air at every step, measured on G1).
"""

from __future__ import annotations

WINDOW = 0.1  # [s] before the planned landing over which the target sinks
YIELD_TIME = 0.05  # [s] return of the compliance offset when the sole is unloaded


class Landing:
    """Height offsets of the feet's targets around a step.

    Args:
        depth: Depth below the ground the swing sole aims at at the landing time [m].
        admittance: Rise speed per newton above the touch force [m/(N s)].
        touch_force: Load a touching swing sole may carry [N].
        double_support: T_DSP, over which the new stance sole settles [s].
    """

    def __init__(
        self, depth: float, admittance: float, touch_force: float, double_support: float
    ) -> None:
        self.depth = depth
        self.admittance = admittance
        self.touch_force = touch_force
        self.double_support = double_support
        self._yield = 0.0  # [m] compliance offset of the swing sole
        self._last_height = 0.0  # [m] the swing sole's last target height

    def reset(self) -> None:
        """A new swing begins."""
        self._yield = 0.0

    def swing_height(self, profile: float, time_to_landing: float, load: float, dt: float) -> float:
        """Target height [m] of the swing sole.

        Args:
            profile: The swing trajectory's height [m].
            time_to_landing: Time left until the planned landing [s].
            load: Vertical force the swing sole carries [N].
            dt: Control period [s].
        """
        sink = self.depth * min(max(1.0 - time_to_landing / WINDOW, 0.0), 1.0)
        excess = load - self.touch_force
        self._yield += dt * (self.admittance * excess - self._yield / YIELD_TIME)
        self._yield = min(max(self._yield, 0.0), self.depth + 0.02)
        self._last_height = profile - sink + self._yield
        return self._last_height

    def stance_height(self, time_since_step: float) -> float:
        """Target height [m] of the new stance sole in the double support after a step."""
        remaining = max(0.0, 1.0 - time_since_step / self.double_support)
        return self._last_height * remaining
