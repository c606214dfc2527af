"""Parameters of the reactive step generator, validated when built.

Defaults are the paper's Section VI values where the paper gives them. The paper
gives no mass, CoM height, foot size or bounds for its robot (MAHRU-R, an adult-size
humanoid of about 1.5 m); the defaults below are documented choices for a robot of
that class:

- mass m = 60 kg, CoM height c_z = 0.8 m;
- ZMP window W (6): x in [-0.08, 0.12] m, y in [-0.07, 0.07] m around the ankle,
  inside a 0.26 m x 0.16 m foot whose ankle sits 0.09 m from the heel;
- feedback rate of change of angular momentum |hdot| <= 20 N m per axis (arms and
  trunk of a 60 kg robot; an effective ZMP shift of 3.4 cm). The double-support
  compensation term m g H^-1 r~_H of Section V-B is added after this saturation
  (see :mod:`planner.step_generator`);
- step bounds u_d: x in [-0.4, 0.6] m, y in [-0.6, 0.6] m.

With these values and gamma_v = 0.0015, the paper's Fig. 6 behaviour holds: the
first push drives V_u to about 1.4 gamma_v by its end (adjusted step), the second
to about 0.9 gamma_v (no adjusted step).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, fields

import numpy as np

from .exceptions import ParameterError

GRAVITY = 9.81  # [m/s^2]


@dataclass(frozen=True)
class Range:
    """The physically meaningful values of one parameter, with the unit they are in.

    Attributes:
        low: Smallest value (excluded when ``low_open``).
        high: Largest value (included).
        unit: Unit written after the range in messages (``"m"``, ``"s"``, ...).
        low_open: ``low`` itself is excluded.
    """

    low: float
    high: float
    unit: str = ""
    low_open: bool = False

    def describe(self) -> str:
        """``"a number in (0, 0.5] m"``."""
        left = "(" if self.low_open else "["
        unit = f" {self.unit}" if self.unit else ""
        return f"a number in {left}{self.low:g}, {self.high:g}]{unit}"

    def contains(self, value: object) -> bool:
        """Whether ``value`` is a number (not a bool) within the range."""
        if isinstance(value, bool) or not isinstance(value, int | float):
            return False
        number = float(value)
        above = number > self.low if self.low_open else number >= self.low
        return math.isfinite(number) and above and number <= self.high

    def check(self, name: str, value: object) -> None:
        """Raise a ParameterError naming ``name`` unless ``value`` is in the range."""
        if not self.contains(value):
            raise ParameterError(name, value, self.describe())


#: Every number of the planner's parameters, with the range in which it means something
#: physically (a robot from a few kg to an adult humanoid walking on Earth-like gravity).
#: Checked where each dataclass is built; the robot descriptions use the same table.
RANGES: dict[str, Range] = {
    # LipmModel
    "mass": Range(0.0, 1000.0, "kg", low_open=True),
    "com_height": Range(0.05, 5.0, "m"),
    "gravity": Range(0.0, 100.0, "m/s^2", low_open=True),
    # GaitParameters: a step of at most 1 m, phases from one G1 tick to a slow walk
    "stride_length": Range(-1.0, 1.0, "m"),
    "step_width": Range(0.0, 1.0, "m", low_open=True),
    "double_support_duration": Range(0.01, 2.0, "s"),
    "single_support_duration": Range(0.05, 5.0, "s"),
    # Constraints
    "angular_momentum_rate_max": Range(0.0, 10000.0, "N m", low_open=True),
    "com_reach": Range(0.0, 5.0, "m", low_open=True),
    # RsgParameters
    "filter_time_constant": Range(0.001, 1.0, "s"),
    "lyapunov_threshold": Range(1e-6, 1.0),
    "step_decrease_margin": Range(0.0, 1.0, low_open=True),
    "crossing_margin": Range(0.0, 0.5, "m", low_open=True),
    "com_margin": Range(0.0, 0.2, "m", low_open=True),
    "swing_preparation_time": Range(0.0, 2.0, "s", low_open=True),
    "lqr_dcm_error_scale": Range(1e-4, 1.0, "m"),
    "lqr_zmp_scale": Range(1e-4, 1.0, "m"),
    "lqr_angular_momentum_scale": Range(1e-3, 10000.0, "N m"),
    "step_reaction_time": Range(0.0, 1.0, "s"),
    "push_hold_time": Range(0.0, 1.0, "s"),
    "push_cmp_threshold": Range(0.0, 1.0, "m", low_open=True),
    "reanchor_time": Range(0.0, 1.0, "s"),
    "touchdown_window": Range(0.0, 1.0, "s"),
    "dcm_inset": Range(-0.1, 0.1, "m"),
}
#: Bound on each coordinate of the ZMP window and of the step bounds [m].
CORNER_RANGE = Range(-2.0, 2.0, "m")


def _check_ranges(owner: object, *names: str) -> None:
    for name in names:
        RANGES[name].check(name, getattr(owner, name))


def _check_pair(name: str, value: object) -> None:
    """Two finite numbers (x, y), each within :data:`CORNER_RANGE` [m]."""
    pair: tuple = tuple(value) if isinstance(value, tuple | list | np.ndarray) else ()
    if len(pair) != 2 or not all(CORNER_RANGE.contains(v) for v in pair):
        raise ParameterError(name, value, "two numbers (x, y), each in [-2, 2] m")


@dataclass(frozen=True)
class LipmModel:
    """Linear inverted pendulum (1).

    Attributes:
        mass: Total mass m [kg].
        com_height: Constant CoM height c_z [m].
        gravity: Gravitational acceleration g [m/s^2].
    """

    mass: float = 60.0
    com_height: float = 0.8
    gravity: float = GRAVITY

    def __post_init__(self) -> None:
        _check_ranges(self, "mass", "com_height", "gravity")

    @property
    def omega(self) -> float:
        """Natural frequency omega = sqrt(g / c_z) [1/s]."""
        return math.sqrt(self.gravity / self.com_height)


@dataclass(frozen=True)
class GaitParameters:
    """Nominal gait of the reference model (3).

    Attributes:
        stride_length: L_x^*, forward distance between successive steps [m].
        step_width: L_y^*, lateral distance between the feet [m].
        double_support_duration: T_DSP^* [s].
        single_support_duration: T_SSP^* [s].
    """

    stride_length: float = 0.2
    step_width: float = 0.2
    double_support_duration: float = 0.1
    single_support_duration: float = 0.7

    def __post_init__(self) -> None:
        _check_ranges(
            self,
            "stride_length",
            "step_width",
            "double_support_duration",
            "single_support_duration",
        )

    @property
    def step_duration(self) -> float:
        """Nominal walking cycle T^* = T_DSP^* + T_SSP^* [s]."""
        return self.double_support_duration + self.single_support_duration


@dataclass(frozen=True)
class Constraints:
    """State and input constraints (8), (12).

    Attributes:
        zmp_window_min: w_H^m, lower corner of the ZMP window around r_H [m].
        zmp_window_max: w_H^M, upper corner [m]; w_y = zmp_window_max[1] and the
            window must be symmetric in y (w_y^m = -w_y^M).
        angular_momentum_rate_max: Bound on |hdot| per axis [N m].
        step_min: u_d^m, lower bound of the step u_d = o_H^+ - o_H [m].
        step_max: u_d^M, upper bound of the step [m].
        com_reach: Leg reach: the largest horizontal CoM distance from the new
            stance ankle a QP step may leave, |xi1^+| <= com_reach [m] (an extension
            of (27), see :mod:`planner.step_qp`); ``math.inf`` turns it off (the
            paper's (27)). The default stays 2 cm inside the LIPM backend's fall
            rule (CoM within 0.6 m of the stance ankle).
    """

    zmp_window_min: tuple[float, float] = (-0.08, -0.07)
    zmp_window_max: tuple[float, float] = (0.12, 0.07)
    angular_momentum_rate_max: float = 20.0
    step_min: tuple[float, float] = (-0.4, -0.6)
    step_max: tuple[float, float] = (0.6, 0.6)
    com_reach: float = 0.58

    def __post_init__(self) -> None:
        if self.com_reach != math.inf and not RANGES["com_reach"].contains(self.com_reach):
            raise ParameterError("com_reach", self.com_reach, "a number in (0, 5] m, or inf: off")
        for name in ("zmp_window_min", "zmp_window_max", "step_min", "step_max"):
            _check_pair(name, getattr(self, name))
        lo, hi = self.zmp_window_min, self.zmp_window_max
        if not (lo[0] < 0.0 < hi[0]):
            raise ParameterError("zmp_window_min/zmp_window_max x", (lo[0], hi[0]), "min < 0 < max")
        if not (hi[1] > 0.0 and abs(lo[1] + hi[1]) < 1e-12):
            raise ParameterError(
                "zmp_window_min/zmp_window_max y", (lo[1], hi[1]), "symmetric: min = -max < 0"
            )
        _check_ranges(self, "angular_momentum_rate_max")
        if not (self.step_min[0] < 0.0 < self.step_max[0]):
            raise ParameterError(
                "step_min/step_max x", (self.step_min[0], self.step_max[0]), "min < 0 < max"
            )
        if not (self.step_min[1] < 0.0 < self.step_max[1]):
            raise ParameterError(
                "step_min/step_max y", (self.step_min[1], self.step_max[1]), "min < 0 < max"
            )

    @property
    def half_width(self) -> float:
        """w_y, half-width of the ZMP window [m]."""
        return self.zmp_window_max[1]

    def input_min(self) -> np.ndarray:
        """u_c^m = (p~^m, hdot^m), shape (4,)."""
        h = self.angular_momentum_rate_max
        return np.array([*self.zmp_window_min, -h, -h])

    def input_max(self) -> np.ndarray:
        """u_c^M = (p~^M, hdot^M), shape (4,)."""
        h = self.angular_momentum_rate_max
        return np.array([*self.zmp_window_max, h, h])


# True/False options of RsgParameters
_RSG_FLAGS = ("qp_at_timing_jump", "announced_foothold", "preview_at_touchdown")


@dataclass(frozen=True)
class RsgParameters:
    """Design parameters of the hybrid tracking controller (Section V, VI).

    Attributes:
        filter_time_constant: theta, time constant of the low-pass filter on u_c [s].
        lyapunov_threshold: gamma_v of (21).
        step_decrease_margin: mu_1 of (25), (26).
        crossing_margin: mu_2 of (27b) [m].
        com_margin: mu_3 of (27c) [m].
        swing_preparation_time: T_SP, time the swing foot needs after the DSP before
            it can land [s].
        lqr_dcm_error_scale: e_max of Bryson's rule Q = I / e_max^2 [m].
        lqr_zmp_scale: p~ scale of R, R_p = 1 / p_max^2 [m].
        lqr_angular_momentum_scale: hdot scale of R, R_h = 1 / h_max^2 [N m].
        step_reaction_time: Time [s] between the timing jump's decision (D_T) and
            the touchdown, for a robot whose swing foot needs time to reach a new
            foothold; 0 (the paper): the step is taken the tick D_T fires.
        push_hold_time: Longest time [s] D_T,1 is held back while a push is measured
            (an extension, see :mod:`planner.step_generator`); 0 gives the paper's
            jump set exactly.
        push_cmp_threshold: Size of the estimated push, as the CMP shift
            |f| c_z / (m g) it causes [m], above which a push counts as under way.
        reanchor_time: Time constant [s] with which o_H moves to a measured stance
            sole (``MeasuredState.stance_sole``); 0: at once.
        touchdown_window: An extension of D_T for a backend that measures the swing
            sole's contact (``MeasuredState.swing_contact``): a scheduled timing jump
            that brings a step forward comes at a touchdown measured at most this long
            [s] before its time, the swing sole's landing window (a contact earlier is
            a scrape, not a landing); 0 (the paper): at its time.
        dcm_inset: An extension of (27c) to the DCM [m]: a QP step puts the new stance
            sole's centre line at least this far outside the DCM predicted at the
            step, sigma+ (xi_dcm,y - u_d,y) <= -dcm_inset (see
            :mod:`planner.step_qp`); None (the paper): no such row.
        qp_at_timing_jump: An extension of the output map H_nu: a timing jump (D_T)
            steps where the QP (27) puts it even when V_u < gamma_v (a jump from D_T,2,
            or a decision kept through ``step_reaction_time``); False (the paper):
            below gamma_v H_nu steps 2 xi1*; with a reaction time the announced
            foothold then moves between the QP's and 2 xi1* as V_u crosses gamma_v.
        announced_foothold: An extension of the output map H_nu: a nominal jump (D_S)
            steps onto the foothold announced at the tick before, where a real swing
            foot was sent and has touched down by then; False (the paper): H_nu at the
            jump's own state.
        preview_at_touchdown: An extension of the announced next step: while V_u >=
            gamma_v it is the QP (27) at the state predicted when the step is expected
            (the LIPM under the current input), so a swing foot is sent from its
            lift-off where a pushed step will land; False: the QP at the current state.
    """

    filter_time_constant: float = 0.05
    lyapunov_threshold: float = 0.0015
    step_decrease_margin: float = 0.003
    crossing_margin: float = 0.05
    com_margin: float = 0.0001
    swing_preparation_time: float = 0.2
    lqr_dcm_error_scale: float = 0.05
    lqr_zmp_scale: float = 0.05
    lqr_angular_momentum_scale: float = 20.0
    step_reaction_time: float = 0.0
    push_hold_time: float = 0.15
    push_cmp_threshold: float = 0.02
    reanchor_time: float = 0.0
    touchdown_window: float = 0.0
    dcm_inset: float | None = None
    qp_at_timing_jump: bool = True
    announced_foothold: bool = True
    preview_at_touchdown: bool = True

    def __post_init__(self) -> None:
        for flag in _RSG_FLAGS:
            if not isinstance(getattr(self, flag), bool):
                raise ParameterError(flag, getattr(self, flag), "True or False")
        if self.dcm_inset is not None:
            _check_ranges(self, "dcm_inset")
        _check_ranges(
            self,
            *(f.name for f in fields(self) if f.name not in ("dcm_inset", *_RSG_FLAGS)),
        )


CONTROLLERS = ("rsg", "fixed-timing", "no-step")


@dataclass(frozen=True)
class PlannerConfig:
    """Everything the reactive step generator needs.

    Attributes:
        model: The LIPM.
        gait: The nominal gait.
        constraints: State and input constraints.
        rsg: Controller design parameters.
        controller: ``"rsg"`` (step time and location adjusted), ``"fixed-timing"``
            (location from the QP, steps only at the nominal time, D_S alone) or
            ``"no-step"`` (nominal steps; feedback only through ZMP and hdot).
    """

    model: LipmModel = field(default_factory=LipmModel)
    gait: GaitParameters = field(default_factory=GaitParameters)
    constraints: Constraints = field(default_factory=Constraints)
    rsg: RsgParameters = field(default_factory=RsgParameters)
    controller: str = "rsg"

    def __post_init__(self) -> None:
        if self.controller not in CONTROLLERS:
            raise ParameterError("controller", self.controller, f"one of {', '.join(CONTROLLERS)}")
        w_y = self.constraints.half_width
        min_width = 2.0 * w_y + self.rsg.crossing_margin
        if self.gait.step_width < min_width:
            raise ParameterError(
                "step_width",
                self.gait.step_width,
                f">= 2 w_y + crossing_margin = {min_width:.3f} m (w_y = {w_y:g} m, half the "
                "ZMP window) so the nominal gait meets (27b)",
            )
        if self.constraints.step_max[1] < min_width:
            raise ParameterError(
                "step_max y",
                self.constraints.step_max[1],
                f">= 2 w_y + crossing_margin = {min_width:.3f} m so the QP (27) can be feasible",
            )
        if self.gait.step_width > self.constraints.step_max[1]:
            raise ParameterError(
                "step_width",
                self.gait.step_width,
                f"<= step_max y = {self.constraints.step_max[1]:g} m",
            )
        if not (
            self.constraints.step_min[0] <= self.gait.stride_length <= self.constraints.step_max[0]
        ):
            raise ParameterError(
                "stride_length",
                self.gait.stride_length,
                f"within the step bounds step_min x, step_max x = [{self.constraints.step_min[0]:g}"
                f", {self.constraints.step_max[0]:g}] m",
            )
        if self.rsg.com_margin >= w_y:
            raise ParameterError(
                "com_margin",
                self.rsg.com_margin,
                f"< w_y = {w_y:g} m (half the ZMP window) so (27c) leaves room for a step",
            )
        if self.rsg.swing_preparation_time > self.gait.single_support_duration:
            raise ParameterError(
                "swing_preparation_time",
                self.rsg.swing_preparation_time,
                f"<= single_support_duration = {self.gait.single_support_duration:g} s (the "
                "swing foot must be ready by the nominal step)",
            )

    @property
    def adjusts_timing(self) -> bool:
        """Whether D_T (step-time adjustment) is active."""
        return self.controller == "rsg"

    @property
    def adjusts_location(self) -> bool:
        """Whether the QP (27) chooses the step location when V_u >= gamma_v."""
        return self.controller in ("rsg", "fixed-timing")
