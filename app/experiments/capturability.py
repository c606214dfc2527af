"""The largest push any controller can capture on the LIPM: the yardstick of ``rsg sweep``.

The bound is an upper limit for every controller on the LIPM with the controller's
limits and the LIPM backend's fall rule, causal or not. Derivation and measurements:
``docs/bound.md``. In short, with the DCM xi = c + cdot / omega and the convergent
component zeta = c - cdot / omega (per axis, c = (xi + zeta) / 2):

    xidot = omega (xi - r) + f / (m omega),   zetadot = -omega (zeta - r) - f / (m omega),

r the CMP, f the push force. A controller chooses r(t), the step times and the steps
u_k = o_k - o_{k-1}; the limits it has (all of them are kept):

- the CMP in the ZMP window widened by hdot_max / (m g) per axis around the stance
  ankle, and in double support (T_DSP after a step) anywhere between the windows of the
  two feet (per axis), which contains the paper's moving window (7), (8);
- steps in the box (27d), laterally on the swing foot's own side (27b), the first no
  sooner than the swing foot is ready (T_min = T_DSP + T_SP after the last step, the
  controller's gate), later ones T_min apart; during the push if that helps;
- the LIPM backend's fall rule: the CoM within ``leg_reach`` (0.6 m) of the stance ankle.

Left out, each a relaxation (fewer limits can only raise the bound): the fall rule on
the DCM error (it depends on the controller's reference), (27c) (the QP drops it when
it is infeasible), and anything a particular controller adds (the QP's own leg reach,
push hold, reaction time).

The push (its force over [0, Delta] and its direction) is known to the bound from its
start: an upper limit may be non-causal. Viability is what is bounded: a state from
which no choice avoids a fall is lost; "recovered" implies viable.

Computation (:mod:`app.experiments.capture_lp`, called by
:func:`app.experiments.capture_bound.impulse_bound`): for the step times in given
windows, the largest impulse is bounded by a linear programme in which every relaxation
only widens the feasible set (the CMP's effect per time cell through its two exact
moments, the reach at sample instants on a circumscribed polygon, the feet's windows
merged while a step may or may not have happened, and after two explicit steps the
per-axis capture interval below, which has no reach). Branch and bound over the
step-time windows returns the largest relaxed value among windows no wider than
``LEAF_WIDTH``, which is an upper limit over all step times.

Per-axis capture interval (Koolen et al., IJRR 2012, "Capturability-based analysis
and control of legged locomotion, Part 1", extended by the double-support hull and
the crossing rule): B_sigma, the largest DCM offset x = xi - o from the ankle of
stance sigma from which a step now still captures, obeys

    B_sigma = hi_sigma + max(0, -hi_sigma)(1 - e^(-omega T_DSP)) + r_max
              + max(0, B_{-sigma} - r_max) e^(-omega T_min),

hi_sigma the largest step along the axis from stance sigma (negative for the step
(27b) forces the wrong way; the hull then keeps the CMP at the old foot in double
support), and A_sigma likewise with the smallest step and r_min. With steps of l_max
along x this is Koolen's d_inf = r_max + l_max e^(-omega T) / (1 - e^(-omega T)) plus
the step l_max taken now.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from app.backends.lipm import LEG_REACH
from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig


@dataclass(frozen=True)
class CaptureModel:
    """The LIPM limits the bound is computed with.

    Attributes:
        omega: sqrt(g / c_z) [1/s].
        mass: Robot mass m [kg].
        cmp_min: Lower corner of the CMP window around the ankle (x, y) [m].
        cmp_max: Upper corner [m].
        step_min: Smallest step u_d (x, y) [m].
        step_max: Largest step u_d (x, y) [m].
        min_lateral_step: 2 w_y + mu_2, the smallest lateral step of (27b) [m].
        min_step_time: T_DSP + T_SP, the shortest time between steps [s].
        double_support_duration: T_DSP, after a step the CMP may lie between both feet [s].
        leg_reach: Largest CoM distance from the stance ankle (the fall rule) [m].
    """

    omega: float
    mass: float
    cmp_min: tuple[float, float]
    cmp_max: tuple[float, float]
    step_min: tuple[float, float]
    step_max: tuple[float, float]
    min_lateral_step: float
    min_step_time: float
    double_support_duration: float
    leg_reach: float = LEG_REACH

    def __post_init__(self) -> None:
        for name in ("omega", "mass", "min_step_time", "double_support_duration", "leg_reach"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(name, value, "a finite number > 0")
        if not self.double_support_duration < self.min_step_time:
            raise ParameterError(
                "double_support_duration", self.double_support_duration, "< min_step_time"
            )
        if not all(lo < 0.0 < hi for lo, hi in zip(self.cmp_min, self.cmp_max, strict=True)):
            raise ParameterError("cmp_min/cmp_max", (self.cmp_min, self.cmp_max), "min < 0 < max")
        if not self.step_min[1] < -self.min_lateral_step < self.min_lateral_step < self.step_max[1]:
            raise ParameterError(
                "min_lateral_step", self.min_lateral_step, "inside the lateral step bounds"
            )
        if not self.step_min[0] < self.step_max[0]:
            raise ParameterError("step_min/step_max x", (self.step_min, self.step_max), "min < max")

    @classmethod
    def from_config(
        cls, config: PlannerConfig, include_angular_momentum: bool = True
    ) -> CaptureModel:
        """The limits the controller of ``config`` works with, and the LIPM's leg reach."""
        cons, model = config.constraints, config.model
        shift = 0.0
        if include_angular_momentum:
            shift = cons.angular_momentum_rate_max / (model.mass * model.gravity)
        return cls(
            omega=model.omega,
            mass=model.mass,
            cmp_min=(cons.zmp_window_min[0] - shift, cons.zmp_window_min[1] - shift),
            cmp_max=(cons.zmp_window_max[0] + shift, cons.zmp_window_max[1] + shift),
            step_min=(cons.step_min[0], cons.step_min[1]),
            step_max=(cons.step_max[0], cons.step_max[1]),
            min_lateral_step=2.0 * cons.half_width + config.rsg.crossing_margin,
            min_step_time=config.gait.double_support_duration + config.rsg.swing_preparation_time,
            double_support_duration=config.gait.double_support_duration,
        )

    def step_range(self, axis: int, sigma: int) -> tuple[float, float]:
        """Range of u_d along ``axis`` (0: x, 1: y) [m] from the stance foot ``sigma``."""
        if axis == 0:
            return self.step_min[0], self.step_max[0]
        if sigma > 0:  # left stance: the right foot steps, u_y <= -(2 w_y + mu_2)
            return self.step_min[1], -self.min_lateral_step
        return self.min_lateral_step, self.step_max[1]


def capture_distance(
    n_steps: float, l_max: float, r_max: float, omega: float, t_step: float
) -> float:
    """Koolen's d_N [m]: largest capturable DCM distance from the ankle with N steps.

    Args:
        n_steps: N >= 0, or ``math.inf`` for the closed-form limit.
        l_max: Largest step length [m].
        r_max: Largest CoP distance from the ankle [m].
        omega: sqrt(g / c_z) [1/s].
        t_step: Minimum step time [s].
    """
    decay = math.exp(-omega * t_step)
    if math.isinf(n_steps):
        return r_max + l_max * decay / (1.0 - decay)
    distance = r_max
    for _ in range(int(n_steps)):
        distance = (l_max + distance - r_max) * decay + r_max
    return distance


@dataclass(frozen=True)
class CaptureEdges:
    """Per-axis capture interval of the DCM offset x = xi - o from the stance ankle [m].

    ``lower[axis][sigma]`` / ``upper[axis][sigma]`` (sigma +1 left, -1 right stance):
    the extreme offsets from which stepping at once still captures. :meth:`interval`
    adds waiting: the union with [r_min, r_max] of the stance foot's own window.
    """

    lower: dict[int, dict[int, float]]
    upper: dict[int, dict[int, float]]
    cmp_min: tuple[float, float]
    cmp_max: tuple[float, float]

    def interval(self, axis: int, sigma: int) -> tuple[float, float]:
        """Offsets [m] capturable from stance ``sigma`` out of double support, stepping
        now or at any later time (no leg reach: a relaxation of it)."""
        return (
            min(self.lower[axis][sigma], self.cmp_min[axis]),
            max(self.upper[axis][sigma], self.cmp_max[axis]),
        )


def capture_edges(model: CaptureModel) -> CaptureEdges:
    """The fixed point of the per-axis recursion (module docstring)."""
    decay = math.exp(-model.omega * model.min_step_time)
    hull = 1.0 - math.exp(-model.omega * model.double_support_duration)
    lower: dict[int, dict[int, float]] = {}
    upper: dict[int, dict[int, float]] = {}
    for axis in (0, 1):
        r_lo, r_hi = model.cmp_min[axis], model.cmp_max[axis]
        ranges = {s: model.step_range(axis, s) for s in (1, -1)}
        up = {s: ranges[s][1] + max(0.0, -ranges[s][1]) * hull + r_hi for s in (1, -1)}
        lo = {s: ranges[s][0] + min(0.0, -ranges[s][0]) * hull + r_lo for s in (1, -1)}
        for _ in range(10_000):  # a contraction with rate e^(-omega T_min)
            new_up = {
                s: ranges[s][1] + max(0.0, -ranges[s][1]) * hull + r_hi
                + max(0.0, up[-s] - r_hi) * decay
                for s in (1, -1)
            }  # fmt: skip
            new_lo = {
                s: ranges[s][0] + min(0.0, -ranges[s][0]) * hull + r_lo
                + min(0.0, lo[-s] - r_lo) * decay
                for s in (1, -1)
            }  # fmt: skip
            change = max(abs(new_up[s] - up[s]) + abs(new_lo[s] - lo[s]) for s in (1, -1))
            up, lo = new_up, new_lo
            if change < 1e-14:
                break
        lower[axis], upper[axis] = lo, up
    return CaptureEdges(lower, upper, model.cmp_min, model.cmp_max)
