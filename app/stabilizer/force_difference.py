"""Foot force difference control: the feet's heights share the weight as distributed.

Kajita et al., "Biped walking stabilization based on linear inverted pendulum
tracking" (IROS 2010), Section III-E; also the stabilizer of Caron, Kheddar and
Tempier (ICRA 2019). In double support the two legs form a closed chain: which foot
carries the weight is set by a millimetre of difference between the feet's height
targets (with G1's leg stiffness, 5 mm is more than its weight), not by the
feed-forward's J^T f alone. The loop moves the difference of the targets,
delta = z_left - z_right, so that the measured difference of normal forces follows
the distributed one:

    d delta / dt = A ((f_L - f_R) - (f_L^d - f_R^d)) - delta / T_v

(a foot carrying more than asked for is raised, the other lowered by as much) with a
leak back to the planned heights over T_v. In single support only the leak acts.
"""

from __future__ import annotations

from dataclasses import dataclass

from planner.types import Foot

LEAK_TIME = 0.2  # [s] T_v: the difference returns to the planned heights over this time
MAX_DIFFERENCE = 0.02  # [m] bound on |delta|: a foot never leaves its target by more than 1 cm


@dataclass(frozen=True)
class FootLoads:
    """Normal force per foot [N] (0 for a foot in the air or given none)."""

    left: float
    right: float

    @property
    def difference(self) -> float:
        """f_L - f_R [N]."""
        return self.left - self.right


class ForceDifferenceControl:
    """Height offsets of the feet's targets from the error in their force difference.

    Args:
        admittance: A, height rate per newton of force-difference error [m/(N s)]
            (0: the feet's targets keep the planned heights).
    """

    def __init__(self, admittance: float) -> None:
        self.admittance = admittance
        self.difference = 0.0  # [m] delta = z_left - z_right offset

    def reset(self) -> None:
        self.difference = 0.0

    def update(
        self, measured: FootLoads, desired: FootLoads, double_support: bool, dt: float
    ) -> dict[Foot, float]:
        """Advance the loop by ``dt`` [s]; return the height offset of each foot [m]."""
        rate = -self.difference / LEAK_TIME
        if double_support:
            rate += self.admittance * (measured.difference - desired.difference)
        self.difference += dt * rate
        self.difference = min(max(self.difference, -MAX_DIFFERENCE), MAX_DIFFERENCE)
        return {"left": 0.5 * self.difference, "right": -0.5 * self.difference}
