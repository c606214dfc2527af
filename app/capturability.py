"""N-step capturability of the LIPM as an impulse bound per push direction.

The physical limit a step controller is measured against in ``rsg sweep``.

Model (Koolen et al., IJRR 2012, "Capturability-based analysis and control of legged
locomotion, Part 1"): the DCM (instantaneous capture point) xi = c + cdot / omega
obeys xidot = omega (xi - r) with the CMP r held in a window around the stance ankle
o, and a step moves the ankle by u within the step bounds no earlier than the minimum
step time T_min = T_DSP + T_SP after the previous step. With x = xi - o (DCM relative
to the ankle), a constant r for a time t gives x(t) = r + (x0 - r) e^(omega t), so per
axis the DCM can be anywhere in [r_max + (x0 - r_max) e^(wt), r_min + (x0 - r_min)
e^(wt)] at time t. A state is N-step capturable when some N steps (or fewer) bring the
DCM into the window of the last stance foot, where it can be held still.

Per axis (1-D) the capturable set is an interval [a_N, b_N], with a_0 = r_min,
b_0 = r_max and, stepping as early as allowed (it only helps while the DCM diverges):

    b_N = max(b_{N-1}, (l_max + b'_{N-1} - r_max) e^(-omega t) + r_max),
    a_N = min(a_{N-1}, (l_min + a'_{N-1} - r_min) e^(-omega t) + r_min),

where l_max / l_min are the largest / smallest step along the axis and the primes
are the intervals of the next stance foot. With symmetric bounds this is Koolen's
d_N = (l_max + d_{N-1} - r_max) e^(-omega t_min) + r_max, d_0 = r_max, whose limit is
d_inf = r_max + l_max e^(-omega t) / (1 - e^(-omega t)).

Which foot steps next: the crossing constraint (27b) lets the swing foot land only
on its own side, at least 2 w_y + mu_2 from the stance ankle laterally. So in y the
step range alternates with the stance foot (a right step from the left stance has
u_y in [u_y^m, -(2 w_y + mu_2)], the left step after it u_y in [2 w_y + mu_2,
u_y^M]), and the y interval depends on the stance foot sigma: a push towards the
stance side first forces a step the wrong way, which the recursion accounts for. In x
the range is [u_x^m, u_x^M] for both feet.

The 2-D capturable set lies inside the product of the two 1-D intervals (each
axis alone, with its own free timing, is a relaxation of the coupled problem), so
the box [a_N, b_N]^2 is an upper bound; it is exact for pushes along an axis.

Impulse: during a push of force f over Delta, xidot = omega (xi - r) + f / (m omega).
For all times after the push, the state equals that of an instantaneous DCM jump at
the push start of i / (m omega) * kappa, kappa = (1 - e^(-omega Delta)) / (omega
Delta) (-> 1 for a short push), under the same CMP and steps (the DCM is linear in
f and the step is a shift of the frame). The largest impulse along unit direction d
is s* m omega / kappa, with s* the largest s such that x0 + s d stays in the capture
box, x0 the nominal DCM at the push.

When the first step may come: t_1 = max(T_min - s~, Delta) after the push start
(s~: time since the last step at the push), later ones every T_min. T_min - s~ is
the swing foot's readiness, measured from the last touchdown as the controller's
gate s~ >= T_DSP + T_SP. The Delta is causality: the equivalent jump above lumps
the whole impulse at the push start, but a controller measures the push only as it
acts (its size and end are unknown beforehand), so a step before the push ends
would be placed for an impulse not yet applied. A bound that lets the first step
land at the push start, placed for the whole impulse (t_1 = max(0, T_min - s~), an
earlier version), is a bound for a controller that knows the push in advance: at
phases with s~ >= T_min it was 30-40% above what any causal controller can reach
(e.g. 255 instead of 187 N s forward at phase 0.5). Between the push start and t_1
the CMP may sit anywhere in its window (the push direction is measured from its
first instant), which the per-axis box already allows. For s~ <= T_min - Delta
(phases 0 and 0.25 of the default gait) the two forms agree.

CMP window: by default the window is the ZMP window widened by the feedback rate of
change of angular momentum, |hdot| <= hdot_max shifts the CMP by up to
hdot_max / (m g) per axis (H is an axis swap), which the LIPM backend realises. With
``include_angular_momentum=False`` it is the ZMP window alone.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig
from planner.reference_model import NominalOrbit

MAX_STEPS = 50  # the recursion converges geometrically (ratio e^(-omega T_min))


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
    """

    omega: float
    mass: float
    cmp_min: tuple[float, float]
    cmp_max: tuple[float, float]
    step_min: tuple[float, float]
    step_max: tuple[float, float]
    min_lateral_step: float
    min_step_time: float

    def __post_init__(self) -> None:
        for name in ("omega", "mass", "min_step_time"):
            value = getattr(self, name)
            if not (math.isfinite(value) and value > 0.0):
                raise ParameterError(name, value, "a finite number > 0")
        if not all(lo < 0.0 < hi for lo, hi in zip(self.cmp_min, self.cmp_max, strict=True)):
            raise ParameterError("cmp_min/cmp_max", (self.cmp_min, self.cmp_max), "min < 0 < max")
        if not self.step_min[1] < -self.min_lateral_step < self.min_lateral_step < self.step_max[1]:
            raise ParameterError(
                "min_lateral_step", self.min_lateral_step, "inside the lateral step bounds"
            )

    @classmethod
    def from_config(
        cls, config: PlannerConfig, include_angular_momentum: bool = True
    ) -> CaptureModel:
        """The limits the controller of ``config`` works with."""
        cons, model = config.constraints, config.model
        shift = 0.0
        if include_angular_momentum:
            shift = cons.angular_momentum_rate_max / (model.mass * model.gravity)
        return cls(
            omega=model.omega,
            mass=model.mass,
            cmp_min=(cons.zmp_window_min[0] - shift, cons.zmp_window_min[1] - shift),
            cmp_max=(cons.zmp_window_max[0] + shift, cons.zmp_window_max[1] + shift),
            step_min=tuple(cons.step_min),  # type: ignore[arg-type]
            step_max=tuple(cons.step_max),  # type: ignore[arg-type]
            min_lateral_step=2.0 * cons.half_width + config.rsg.crossing_margin,
            min_step_time=config.gait.double_support_duration + config.rsg.swing_preparation_time,
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


def _interval_after(
    model: CaptureModel, axis: int, sigma: int, t: float, nxt: tuple[float, float]
) -> tuple[float, float]:
    """Interval of x0 from which one step after ``t`` [s] reaches ``nxt`` of the new stance."""
    u_lo, u_hi = model.step_range(axis, sigma)
    r_lo, r_hi = model.cmp_min[axis], model.cmp_max[axis]
    decay = math.exp(-model.omega * t)
    return r_lo + (nxt[0] + u_lo - r_lo) * decay, r_hi + (nxt[1] + u_hi - r_hi) * decay


def capture_box(
    model: CaptureModel, sigma: int, first_step_time: float, n_steps: float = math.inf
) -> tuple[np.ndarray, np.ndarray]:
    """The N-step capture box (lo, hi) of the DCM relative to the stance ankle [m].

    Args:
        model: Limits.
        sigma: Stance foot at the push (+1 left, -1 right).
        first_step_time: Earliest first step after the push [s] (>= 0).
        n_steps: N, or ``math.inf`` (iterated to convergence).
    """
    if not (first_step_time >= 0.0 and n_steps >= 0):
        raise ParameterError("first_step_time/n_steps", (first_step_time, n_steps), ">= 0")
    count = MAX_STEPS if math.isinf(n_steps) else int(n_steps)
    lo, hi = np.zeros(2), np.zeros(2)
    for axis in (0, 1):
        window = (model.cmp_min[axis], model.cmp_max[axis])
        # inner[s]: interval with k steps left, stance s, steps every T_min.
        inner = {1: window, -1: window}
        for _ in range(max(count - 1, 0)):
            inner = {
                s: _hull(inner[s], _interval_after(model, axis, s, model.min_step_time, inner[-s]))
                for s in (1, -1)
            }
        outer = window
        if count >= 1:
            first = _interval_after(model, axis, sigma, first_step_time, inner[-sigma])
            outer = _hull(inner[sigma], first)
        lo[axis], hi[axis] = outer
    return lo, hi


def _hull(a: tuple[float, float], b: tuple[float, float]) -> tuple[float, float]:
    if b[0] > b[1]:  # empty: that step cannot help
        return a
    return min(a[0], b[0]), max(a[1], b[1])


def max_dcm_shift(x0: np.ndarray, direction: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> float:
    """Largest s >= 0 with x0 + s d inside the box [lo, hi] [m] (0 if x0 is outside)."""
    x0, d = np.asarray(x0, float), np.asarray(direction, float)
    if np.any(x0 < lo - 1e-12) or np.any(x0 > hi + 1e-12):
        return 0.0
    best = math.inf
    for axis in (0, 1):
        if d[axis] > 1e-12:
            best = min(best, (hi[axis] - x0[axis]) / d[axis])
        elif d[axis] < -1e-12:
            best = min(best, (lo[axis] - x0[axis]) / d[axis])
    return max(best, 0.0)


def push_discount(omega: float, push_duration: float) -> float:
    """kappa = (1 - e^(-omega Delta)) / (omega Delta): DCM jump per i / (m omega) [-]."""
    x = omega * push_duration
    return 1.0 if x < 1e-9 else (1.0 - math.exp(-x)) / x


def first_step_time(min_step_time: float, time_since_step: float, push_duration: float) -> float:
    """Earliest first step after the push start [s]: the swing foot ready, the push over."""
    return max(min_step_time - time_since_step, push_duration, 0.0)


def nominal_dcm(config: PlannerConfig, sigma: int, time_since_step: float) -> np.ndarray:
    """DCM relative to the stance ankle on the nominal orbit [m]."""
    orbit = NominalOrbit(config.model.omega, config.gait)
    state = orbit.state_at(sigma, time_since_step)
    return state[:2] + state[2:] / config.model.omega


def impulse_bound(
    config: PlannerConfig,
    angle: float,
    sigma: int,
    time_since_step: float,
    push_duration: float,
    n_steps: float = math.inf,
    include_angular_momentum: bool = True,
) -> float:
    """Largest capturable impulse [N s] along ``angle`` [rad] from the nominal gait.

    Args:
        config: The controller's parameters (mass, window, steps, timing).
        angle: Push direction in the world, 0 = forward (+x), pi/2 = left (+y) [rad].
        sigma: Stance foot at the push start (+1 left, -1 right).
        time_since_step: s~ at the push start [s].
        push_duration: Delta [s].
        n_steps: N of the N-step bound (default: the limit N -> inf).
        include_angular_momentum: Widen the window by hdot_max / (m g).
    """
    model = CaptureModel.from_config(config, include_angular_momentum)
    first = first_step_time(model.min_step_time, time_since_step, push_duration)
    lo, hi = capture_box(model, sigma, first, n_steps)
    x0 = nominal_dcm(config, sigma, time_since_step)
    shift = max_dcm_shift(x0, np.array([math.cos(angle), math.sin(angle)]), lo, hi)
    return shift * model.mass * model.omega / push_discount(model.omega, push_duration)
