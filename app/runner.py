"""The closed loop: planner and backend, tick by tick, with everything recorded.

Constraints are checked here, independently of how the planner enforces them:

- ``zmp_window`` (8): w^m <= p~_H <= w^M at every tick;
- ``angular_momentum`` (12a): |hdot| feedback part <= its bound at every tick;
- ``step_bounds`` (27d): u_d^m <= u_d <= u_d^M at every step;
- ``crossing`` (12b): sigma+ u_d,y >= 2 w_y at every step (the feet never cross);
- ``com_between_feet`` (12b): sigma (c_y - o_y) <= w_y at every tick.
"""

from __future__ import annotations

import contextlib
import math
import signal
import threading
import time as wallclock
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace
from typing import Any, Protocol

import numpy as np

from app.backends.base import Backend, FallStatus, InitialCondition
from app.scenarios import Scenario
from planner.parameters import PlannerConfig
from planner.step_generator import ReactiveStepGenerator
from planner.types import Foothold, MeasuredState, PlannerOutput, Push, sigma_of

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


class StepPlanner(Protocol):
    """What the loop needs of a planner: the RSG's interface.

    ``design`` has ``threshold`` (gamma_v), ``matrix`` and ``gain`` (written to
    the results); :class:`planner.step_generator.ReactiveStepGenerator` is one,
    the placo-wpg baseline (:mod:`app.baselines.placo_wpg`) another.
    """

    design: Any

    def reset(self, stance: Foothold, previous: Foothold) -> None: ...

    def update(self, measured: MeasuredState, period: float) -> PlannerOutput: ...


PlannerFactory = Callable[[PlannerConfig], StepPlanner]

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
        interrupted: The run was stopped (Ctrl-C) before its end: what it holds is
            what was simulated until then.
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
    interrupted: bool = False

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
        """No fall, and the last two steps nominal, taken after the last push ended with
        V_u below gamma_v at their jumps (never for an interrupted run).

        V_u is judged where the planner judges it, at its jumps, not at the run's last
        instant: on a robot it rises above gamma_v for about 0.1 s after every
        touchdown of a nominal walk (docs/notes/2026-12-03-recovered-at-the-jumps.md).
        """
        last = self.steps[-2:]
        pushes_end = max((p.time + p.duration for p in self.scenario.pushes), default=-math.inf)
        return (
            not self.interrupted
            and not self.fall.fell
            and len(last) == 2
            and all(
                not s.event["adjusted"]
                and s.event["t"] >= pushes_end
                and s.event["lyapunov_before"] < self.lyapunov_threshold
                for s in last
            )
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


class ClosedLoop:
    """Planner and backend advanced one control tick at a time, everything recorded.

    Used by the batch runner (:func:`run_closed_loop`) and by the live browser demo,
    which adds pushes while it runs.

    Args:
        backend: The simulated robot.
        config: Planner parameters; its model must match the backend.
        scenario: Duration and pushes (already scaled to the robot's mass).
        initial: Start state; default :func:`walking_start`.
        qp_solver: ``"proxqp"`` or ``"exact"`` for the QP (27).
        capacity: Ticks to pre-allocate for the time series (grows when needed).
        planner: Builds the planner from ``config``; default the RSG
            (:class:`ReactiveStepGenerator` with ``qp_solver``).
        record: Keep the time series and the steps (False: a loop that runs
            without end, e.g. the live demo, keeps memory bounded).
    """

    def __init__(
        self,
        backend: Backend,
        config: PlannerConfig,
        scenario: Scenario,
        initial: InitialCondition | None = None,
        qp_solver: str = "proxqp",
        capacity: int | None = None,
        planner: PlannerFactory | None = None,
        record: bool = True,
    ) -> None:
        self.backend = backend
        self.record = record
        self.config = config
        self.scenario = scenario
        self.initial = initial or walking_start(config)
        self.generator: StepPlanner = (
            ReactiveStepGenerator(config, qp_solver=qp_solver)
            if planner is None
            else planner(config)
        )
        self.period = backend.control_period
        self._capacity = capacity or int(round(scenario.duration / self.period)) + 1
        if not record:
            self._capacity = 1
        self.reset()

    def reset(self) -> None:
        """Start again from the initial condition (pushes added live are kept)."""
        self.generator.reset(self.initial.stance, self.initial.swing)
        self.rows = np.zeros((self._capacity, len(TIMESERIES_COLUMNS)))
        self.ticks = 0
        self.steps: list[StepRecord] = []
        self.violations = dict.fromkeys(CONSTRAINTS, 0)
        self.qp_infeasible = 0
        self.wall_time = 0.0
        self.last_output: PlannerOutput | None = None
        self.measured = self.backend.reset(self.initial)

    @property
    def time(self) -> float:
        """Simulated time of the next tick [s]."""
        return self.ticks * self.period

    def add_push(self, push: Push) -> None:
        """Apply ``push`` too (its time is absolute [s])."""
        self.scenario = self.scenario.with_pushes([push])

    def push_now(self, push: Push) -> None:
        """Apply ``push`` and forget the pushes that are over: a loop without end (the
        live demo) keeps its list short."""
        ongoing = tuple(p for p in self.scenario.pushes if p.time + p.duration > self.time)
        self.scenario = replace(self.scenario, pushes=ongoing).with_pushes([push])

    def tick(self) -> PlannerOutput:
        """Run one control tick; returns the planner's output for it."""
        start = wallclock.perf_counter()
        time = self.time
        measured = MeasuredState(
            time,
            self.measured.com_position,
            self.measured.com_velocity,
            self.measured.swing_contact,
            self.measured.stance_sole,
        )
        out = self.generator.update(measured, self.period)
        if out.step is not None:
            step = out.stance.position - out.previous_stance.position
            if self.record:
                self.steps.append(StepRecord(out.step.as_dict(), step.tolist()))
            self.qp_infeasible += int(out.qp_infeasible)
            for name in _check_step(self.config, step, out.stance.foot):
                self.violations[name] += 1
        for name in _check_tick(self.config, out, measured.com_position):
            self.violations[name] += 1
        # The tick's mean push force: its impulse over [t_k, t_k+1), exact for any push.
        end = (self.ticks + 1) * self.period
        force = self.scenario.impulse_between(time, end) / self.period
        if self.record:
            if self.ticks >= len(self.rows):
                self.rows = np.vstack([self.rows, np.zeros_like(self.rows)])
            self.rows[self.ticks] = (
                time, *measured.com_position, *measured.com_velocity,
                *out.zmp, *out.zmp_offset, *out.window_center,
                *out.angular_momentum_rate, *out.angular_momentum_rate_feedback,
                *out.stance.position, sigma_of(out.stance.foot), *out.next_step.position,
                *out.com_reference, *out.dcm_error, out.lyapunov, out.time_since_step, *force,
            )  # fmt: skip
        self.measured = self.backend.step(out, force)
        self.ticks += 1
        self.last_output = out
        self.wall_time += wallclock.perf_counter() - start
        return out

    def result(self) -> RunResult:
        """What has been recorded so far."""
        return RunResult(
            config=self.config,
            scenario=self.scenario,
            backend=self.backend.name,
            mass=self.backend.mass,
            com_height=self.backend.com_height,
            timeseries=self.rows[: self.ticks].copy(),
            steps=list(self.steps),
            fall=self.backend.fall_status(),
            violations=dict(self.violations),
            qp_infeasible=self.qp_infeasible,
            sim_time=self.ticks * self.period,
            wall_time=self.wall_time,
            lyapunov_threshold=self.generator.design.threshold,
            extra={
                "lyapunov_matrix": self.generator.design.matrix.tolist(),
                "feedback_gain": self.generator.design.gain.tolist(),
            },
        )


def run_closed_loop(
    backend: Backend,
    config: PlannerConfig,
    scenario: Scenario,
    initial: InitialCondition | None = None,
    progress: Callable[[float], None] | None = None,
    qp_solver: str = "proxqp",
    planner: PlannerFactory | None = None,
    interruptible: bool = False,
    on_tick: Callable[[ClosedLoop, PlannerOutput], None] | None = None,
) -> RunResult:
    """Run ``scenario`` with the planner of ``config`` on ``backend``.

    Args:
        backend: The simulated robot.
        config: Planner parameters; its model must match the backend's mass/height.
        scenario: Duration and pushes (already scaled to the robot's mass).
        initial: Start state; default :func:`walking_start`.
        progress: Called with the fraction done, about 100 times a run.
        qp_solver: ``"proxqp"`` or ``"exact"`` for the QP (27).
        planner: Builds another planner than the RSG (see :class:`ClosedLoop`).
        interruptible: Ctrl-C (SIGINT) stops the run at the end of the current tick
            and returns what was simulated, marked ``interrupted``; a second Ctrl-C
            raises KeyboardInterrupt at once. Only in the main thread.
        on_tick: Called after every tick with the loop and the tick's output (e.g. a
            :class:`app.results.replay.ReplayRecorder`).

    Returns:
        The recorded run. A fall ends the run early; it is never an exception.

    Raises:
        ParameterError: The scenario does not fit the loop (:meth:`Scenario.check_fits`).
    """
    ticks = scenario.check_fits(backend.control_period)
    loop = ClosedLoop(backend, config, scenario, initial, qp_solver, planner=planner)
    report_every = max(1, ticks // 100)
    with _stop_on_sigint(interruptible) as stop:
        for tick in range(ticks):
            if stop.requested:
                break
            out = loop.tick()
            if on_tick is not None:
                on_tick(loop, out)
            if progress is not None and tick % report_every == 0:
                progress(tick / ticks)
            if backend.fall_status().fell:
                break
    if progress is not None and not stop.requested:
        progress(1.0)
    result = loop.result()
    result.interrupted = stop.requested
    return result


class _StopRequest:
    """Set by the SIGINT handler of :func:`_stop_on_sigint`."""

    requested = False


@contextlib.contextmanager
def _stop_on_sigint(enabled: bool) -> Iterator[_StopRequest]:
    """While active (``enabled``, main thread), the first SIGINT sets ``requested``
    instead of raising; a second one raises KeyboardInterrupt."""
    stop = _StopRequest()
    if not enabled or threading.current_thread() is not threading.main_thread():
        yield stop
        return

    def handler(signum: int, frame: object) -> None:
        if stop.requested:
            raise KeyboardInterrupt
        stop.requested = True

    previous = signal.signal(signal.SIGINT, handler)
    try:
        yield stop
    finally:
        signal.signal(signal.SIGINT, previous)
