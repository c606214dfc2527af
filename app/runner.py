"""The closed loop: planner and backend, tick by tick, with everything recorded.

Constraints are checked here, independently of how the planner enforces them:

- ``zmp_window`` (8): w^m <= p~_H <= w^M at every tick;
- ``angular_momentum`` (12a): |hdot| feedback part <= its bound at every tick;
- ``step_bounds`` (27d): u_d^m <= u_d <= u_d^M at every step;
- ``crossing`` (12b): sigma+ u_d,y >= 2 w_y at every step (the feet never cross);
- ``com_between_feet`` (12b): sigma (c_y - o_y) <= w_y at every tick.
"""

from __future__ import annotations

import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np

from planner.parameters import PlannerConfig
from planner.step_generator import ReactiveStepGenerator
from planner.types import Foothold, PlannerOutput, sigma_of

from .backend import Backend, FallStatus, InitialCondition
from .scenarios import Scenario

TOLERANCE = 1e-6  # [m] or [N m]: numerical slack of the constraint checks

TIMESERIES_COLUMNS = (
    "t",
    "com_x", "com_y", "com_vx", "com_vy",
    "zmp_x", "zmp_y", "zmp_offset_x", "zmp_offset_y", "window_x", "window_y",
    "hdot_x", "hdot_y", "hdot_feedback_x", "hdot_feedback_y",
    "foot_x", "foot_y", "stance_sigma", "next_step_x", "next_step_y",
    "com_ref_x", "com_ref_y",
    "dcm_error_x", "dcm_error_y", "lyapunov", "time_since_step",
    "push_fx", "push_fy",
)  # fmt: skip

CONSTRAINTS = ("zmp_window", "angular_momentum", "step_bounds", "crossing", "com_between_feet")


@dataclass
class StepRecord:
    """A step: the event (time, foot, position, adjusted, Lyapunov levels) and u_d [m]."""

    event: dict
    step: list[float]


@dataclass
class RunResult:
    """Everything a run produced.

    Attributes:
        config: Planner configuration.
        scenario: The scenario actually run (impulses scaled for the robot).
        backend: Backend name.
        mass: Robot mass [kg]; com_height: [m].
        timeseries: Array (ticks x columns) with :data:`TIMESERIES_COLUMNS`.
        steps: Steps taken.
        fall: Fall status at the end.
        violations: Count per constraint name.
        qp_infeasible: Number of steps where (27) fell back.
        sim_time: Simulated time [s]; wall_time: [s].
        impulse_scale: Factor applied to the scenario's impulses.
    """

    config: PlannerConfig
    scenario: Scenario
    backend: str
    mass: float
    com_height: float
    timeseries: np.ndarray
    steps: list[StepRecord]
    fall: FallStatus
    violations: dict[str, int]
    qp_infeasible: int
    sim_time: float
    wall_time: float
    impulse_scale: float = 1.0
    lyapunov_threshold: float = 0.0
    extra: dict = field(default_factory=dict)

    def column(self, name: str) -> np.ndarray:
        """One column of the time series."""
        return self.timeseries[:, TIMESERIES_COLUMNS.index(name)]

    @property
    def final_lyapunov(self) -> float:
        return float(self.column("lyapunov")[-1]) if len(self.timeseries) else 0.0

    @property
    def max_lyapunov(self) -> float:
        """Largest V_u of the run, including the levels just before each jump."""
        levels = [s.event["lyapunov_before"] for s in self.steps]
        if len(self.timeseries):
            levels.append(float(self.column("lyapunov").max()))
        return float(max(levels, default=0.0))

    @property
    def recovered(self) -> bool:
        """No fall, V_u below gamma_v at the end, and the last two steps nominal."""
        last = self.steps[-2:]
        return (
            not self.fall.fell
            and self.final_lyapunov < self.lyapunov_threshold
            and len(last) == 2
            and not any(s.event["adjusted"] for s in last)
        )

    @property
    def constraint_violations(self) -> int:
        return int(sum(self.violations.values()))


def walking_start(config: PlannerConfig) -> InitialCondition:
    """Nominal walking at the start of a single support on the left foot.

    The left foot is at (0, L_y/2), the right one a stride behind at (-L_x, -L_y/2);
    the CoM is on the reference orbit, so the DCM error starts at zero.
    """
    gait = config.gait
    stance = Foothold("left", np.array([0.0, gait.step_width / 2]))
    swing = Foothold("right", np.array([-gait.stride_length, -gait.step_width / 2]))
    generator = ReactiveStepGenerator(config)
    generator.reset(stance, swing)
    com, velocity = generator.initial_com_state()
    return InitialCondition(stance, swing, com, velocity)


def _check_tick(config: PlannerConfig, out: PlannerOutput, com: np.ndarray) -> list[str]:
    cons = config.constraints
    failed = []
    lo, hi = np.array(cons.zmp_window_min), np.array(cons.zmp_window_max)
    if np.any(out.zmp_offset < lo - TOLERANCE) or np.any(out.zmp_offset > hi + TOLERANCE):
        failed.append("zmp_window")
    if np.any(
        np.abs(out.angular_momentum_rate_feedback) > cons.angular_momentum_rate_max + TOLERANCE
    ):
        failed.append("angular_momentum")
    sigma = sigma_of(out.stance.foot)
    if sigma * (com[1] - out.stance.position[1]) > cons.half_width + TOLERANCE:
        failed.append("com_between_feet")
    return failed


def _check_step(config: PlannerConfig, step: np.ndarray, new_foot: str) -> list[str]:
    cons = config.constraints
    failed = []
    if np.any(step < np.array(cons.step_min) - TOLERANCE) or np.any(
        step > np.array(cons.step_max) + TOLERANCE
    ):
        failed.append("step_bounds")
    if sigma_of(new_foot) * step[1] < 2.0 * cons.half_width - TOLERANCE:  # type: ignore[arg-type]
        failed.append("crossing")
    return failed


def run_closed_loop(
    backend: Backend,
    config: PlannerConfig,
    scenario: Scenario,
    initial: InitialCondition | None = None,
    progress: Callable[[float], None] | None = None,
    qp_solver: str = "proxqp",
) -> RunResult:
    """Run ``scenario`` with the planner of ``config`` on ``backend``.

    Args:
        backend: The simulated robot.
        config: Planner parameters; its model must match the backend's mass/height.
        scenario: Duration and pushes (already scaled to the robot's mass).
        initial: Start state; default :func:`walking_start`.
        progress: Called with the fraction done, about 100 times a run.
        qp_solver: ``"proxqp"`` or ``"exact"`` for the QP (27).

    Returns:
        The recorded run. A fall ends the run early; it is never an exception.
    """
    initial = initial or walking_start(config)
    generator = ReactiveStepGenerator(config, qp_solver=qp_solver)
    generator.reset(initial.stance, initial.swing)
    period = backend.control_period
    ticks = int(round(scenario.duration / period))
    rows = np.zeros((ticks, len(TIMESERIES_COLUMNS)))
    steps: list[StepRecord] = []
    violations = dict.fromkeys(CONSTRAINTS, 0)
    qp_infeasible = 0
    report_every = max(1, ticks // 100)

    start = wallclock.perf_counter()
    measured = backend.reset(initial)
    done = 0
    for tick in range(ticks):
        time = tick * period
        measured = type(measured)(time, measured.com_position, measured.com_velocity)
        out = generator.update(measured, period)
        if out.step is not None:
            step = out.stance.position - out.previous_stance.position
            steps.append(StepRecord(out.step.as_dict(), step.tolist()))
            qp_infeasible += int(out.qp_infeasible)
            for name in _check_step(config, step, out.stance.foot):
                violations[name] += 1
        for name in _check_tick(config, out, measured.com_position):
            violations[name] += 1
        force = scenario.force_average(time, period)
        rows[tick] = (
            time, *measured.com_position, *measured.com_velocity,
            *out.zmp, *out.zmp_offset, *out.window_center,
            *out.angular_momentum_rate, *out.angular_momentum_rate_feedback,
            *out.stance.position, sigma_of(out.stance.foot), *out.next_step.position,
            *out.com_reference, *out.dcm_error, out.lyapunov, out.time_since_step, *force,
        )  # fmt: skip
        measured = backend.step(out, force)
        done = tick + 1
        if progress is not None and tick % report_every == 0:
            progress(tick / ticks)
        if backend.fall_status().fell:
            break
    wall = wallclock.perf_counter() - start
    if progress is not None:
        progress(1.0)
    return RunResult(
        config=config,
        scenario=scenario,
        backend=backend.name,
        mass=backend.mass,
        com_height=backend.com_height,
        timeseries=rows[:done],
        steps=steps,
        fall=backend.fall_status(),
        violations=violations,
        qp_infeasible=qp_infeasible,
        sim_time=done * period,
        wall_time=wall,
        lyapunov_threshold=generator.design.threshold,
        extra={
            "lyapunov_matrix": generator.design.matrix.tolist(),
            "feedback_gain": generator.design.gain.tolist(),
        },
    )
