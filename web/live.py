"""The live simulation of the browser demo: the closed loop in its own thread.

Why one long module: the thread, the requests it applies and the snapshots it
publishes share the loop, which only the thread touches.

:class:`LiveSimulation` advances :class:`app.runner.ClosedLoop` at real time (times
the slow-motion factor) when the machine allows, and as fast as it can otherwise;
the measured speed is reported in the status. The page never touches the loop: it
sends requests (push, reset, pause, slow motion, controller) that the thread applies
between ticks, and reads the latest immutable :class:`Snapshot`.

Every push applied and every step taken is printed as one line (``push ...``,
``step ...``), as are falls, resets and controller changes.
"""

from __future__ import annotations

import queue
import sys
import threading
import time as wallclock
from collections.abc import Callable

import numpy as np
from numpy.typing import NDArray

from app.reality import DEFAULT_PROFILE, RealityDraw, check_profile
from app.runner import ClosedLoop
from app.scenarios import Scenario, load_scenario
from app.setup.build import backend_reality, build_backend, resolve_robot
from planner.exceptions import RsgError
from planner.parameters import CONTROLLERS
from planner.types import PlannerOutput, Push

from .push_input import PushInput, push_refusal
from .scene_model import ControllerState, StepMark, Trail
from .snapshot import (
    DCM_ERROR_TRAIL_TIME,
    PLOT_TIME,
    STEP_MARKS,
    TRAIL_TIME,
    PageStatus,
    RobotPose,
    Snapshot,
    sole_corners,
)
from .worker import Worker

Array = NDArray[np.float64]

RECORD_PERIOD = 0.01  # [s] sampling period of trails and plots
PUBLISH_PERIOD = 1.0 / 60.0  # [s] wall time between snapshots while running
LAG_LIMIT = 0.25  # [s] simulated lag after which pacing restarts (machine too slow)
SPEED_WINDOW = 1.0  # [s] wall time over which the speed is measured
# [-] simulated seconds per wall second; above 1 as fast as one core allows (G1 ~5x)
SLOW_MOTION_FACTORS = (0.1, 0.25, 0.5, 1.0, 2.0, 4.0)


def push_line(push: Push, source: str) -> str:
    """The printed line of a push (time [s], impulse [N s], duration [s])."""
    ix, iy = (float(v) for v in push.impulse)
    return (
        f"push t={push.time:.3f} s impulse=({ix:.2f}, {iy:.2f}) N s "
        f"duration={push.duration:.3f} s source={source}"
    )


def step_line(mark: StepMark, lyapunov_before: float, lyapunov_after: float) -> str:
    """The printed line of a step (time [s], foot, position [m], adjusted)."""
    x, y = (float(v) for v in mark.position)
    return (
        f"step t={mark.time:.3f} s foot={mark.foot} position=({x:.3f}, {y:.3f}) m "
        f"adjusted={'yes' if mark.adjusted else 'no'} "
        f"V_u={lyapunov_before:.3g}->{lyapunov_after:.3g}"
    )


class LiveSimulation:
    """The closed loop running in a background thread, driven by requests.

    Args:
        model: ``lipm``, ``pybullet`` or ``mujoco``.
        robot: Robot name (``None``: G1 on a full-robot model, the paper's point mass on
            ``lipm``; a robot on ``lipm`` is its planner on the point mass).
        controller: One of :data:`planner.parameters.CONTROLLERS`.
        scenario: Built-in scenario name or TOML path; its pushes are applied too.
        log: Called with each event line (default: print to stdout and flush).
        log_steps: Log a line per step too (``rsg demo --quiet`` does not).
        slow_motion: Simulated seconds per wall second at start, one of
            :data:`SLOW_MOTION_FACTORS`.
        reality: The full robot's reality profile (:mod:`app.reality`; ignored on
            ``lipm``), drawn from ``reality_seed``: every rebuild (another controller)
            meets the same robot.

    Raises:
        RsgError: Unknown model, robot, controller or scenario (from the builders).
    """

    def __init__(
        self,
        model: str = "pybullet",
        robot: str | None = None,
        controller: str = "rsg",
        scenario: str = "walk",
        log: Callable[[str], None] | None = None,
        log_steps: bool = True,
        slow_motion: float = 1.0,
        reality: str = DEFAULT_PROFILE,
        reality_seed: int = 0,
    ) -> None:
        if slow_motion not in SLOW_MOTION_FACTORS:
            raise ValueError(f"slow motion {slow_motion!r}: expected one of {SLOW_MOTION_FACTORS}")
        self.model = model
        self.reality = check_profile(reality)
        self.reality_seed = reality_seed
        self._log_steps = log_steps
        self.robot = resolve_robot(model, robot)
        self._log = log or _print_line
        self._scenario_source: Scenario = load_scenario(scenario)
        self._requests: queue.Queue[tuple[str, object]] = queue.Queue()
        self._worker = Worker(self._run, "rsg-live-sim")
        self._serial = 0
        self._paused = False
        self._slow_motion = float(slow_motion)
        self._speed = 0.0
        self._last_event = ""
        self._busy = ""
        self._error = ""
        self._loop: ClosedLoop | None = None
        self._closed = False
        self._build(controller)
        self._snapshot = self._make_snapshot()

    # ------------------------------------------------------------------ public API
    @property
    def controller(self) -> str:
        """The step controller in the loop."""
        return self._controller

    def start(self) -> None:
        """Start the simulation thread (idempotent)."""
        self._worker.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop the thread and release the backend."""
        self._worker.stop(timeout)
        if self._loop is not None and not self._closed:
            self._closed = True
            self._loop.backend.close()

    def snapshot(self) -> Snapshot:
        """The latest snapshot (never blocks)."""
        return self._snapshot

    def request_push(self, push: PushInput) -> None:
        """Apply ``push`` at the next tick (safe from any thread)."""
        self._requests.put(("push", push))

    def request_reset(self) -> None:
        """Restart the run: the robot stands again at the initial state."""
        self._requests.put(("reset", None))

    def set_paused(self, paused: bool) -> None:
        """Pause or resume the simulation."""
        self._requests.put(("pause", bool(paused)))

    def set_slow_motion(self, factor: float) -> None:
        """Simulated seconds per wall second, one of :data:`SLOW_MOTION_FACTORS`.

        Raises:
            ValueError: ``factor`` is not one of them.
        """
        if factor not in SLOW_MOTION_FACTORS:
            raise ValueError(f"slow motion {factor!r}: expected one of {SLOW_MOTION_FACTORS}")
        self._requests.put(("slow", float(factor)))

    def request_controller(self, controller: str) -> None:
        """Rebuild the loop with another controller and restart the run.

        Raises:
            ValueError: Unknown controller.
        """
        if controller not in CONTROLLERS:
            raise ValueError(f"controller {controller!r}: expected one of {', '.join(CONTROLLERS)}")
        self._requests.put(("controller", controller))

    def reality_draw(self) -> RealityDraw | None:
        """The reality the full robot's backend applies (None on the LIPM)."""
        loop = self._require_loop()
        return backend_reality(loop.backend, self.reality, self.reality_seed)

    # ------------------------------------------------------------------- building
    def _build(self, controller: str) -> None:
        backend, config, initial = build_backend(
            self.model, self.robot, controller, reality=self.reality, seed=self.reality_seed
        )
        if self._loop is not None:
            self._loop.backend.close()
        scenario, _ = self._scenario_source.scaled_to(backend.mass)
        self._scenario = scenario
        self._loop = ClosedLoop(backend, config, scenario, initial, record=False)
        self._controller = controller
        self._config = config
        window = config.constraints
        self._foot_lower, self._foot_upper = sole_corners(
            window.zmp_window_min, window.zmp_window_max
        )
        self._fresh_run()

    def _fresh_run(self) -> None:
        loop = self._require_loop()
        self._record_every = max(1, round(RECORD_PERIOD / loop.period))
        samples = round(TRAIL_TIME / RECORD_PERIOD)
        self._com_trail = Trail(samples)
        self._zmp_trail = Trail(samples)
        self._dcm_trail = Trail(samples)
        self._dcm_error_trail = Trail(round(DCM_ERROR_TRAIL_TIME / RECORD_PERIOD))
        self._plot = Trail(round(PLOT_TIME / RECORD_PERIOD), dimension=3)
        self._steps: list[StepMark] = []
        self._pushes_applied = 0
        self._last_push: NDArray[np.float64] | None = None
        self._adjusted_steps = 0
        self._fall_reported = False
        self._out: PlannerOutput | None = None

    def _require_loop(self) -> ClosedLoop:
        if self._loop is None:
            raise RuntimeError("the live simulation has no closed loop")
        return self._loop

    # ----------------------------------------------------------------- the thread
    def _run(self, stop: threading.Event) -> None:
        anchor_wall, anchor_sim = wallclock.perf_counter(), self._require_loop().time
        speed_wall, speed_sim = anchor_wall, anchor_sim
        last_publish = 0.0
        while not stop.is_set():
            if self._handle_requests():
                anchor_wall, anchor_sim = wallclock.perf_counter(), self._require_loop().time
                speed_wall, speed_sim = anchor_wall, anchor_sim
                self._publish()
            loop = self._require_loop()
            if not self._running():
                self._speed = 0.0
                self._publish()
                stop.wait(0.02)
                anchor_wall, anchor_sim = wallclock.perf_counter(), loop.time
                speed_wall, speed_sim = anchor_wall, anchor_sim
                continue
            now = wallclock.perf_counter()
            target = anchor_sim + (now - anchor_wall) * self._slow_motion
            batch_end = now + PUBLISH_PERIOD
            while (
                loop.time + 0.5 * loop.period <= target
                and wallclock.perf_counter() < batch_end
                and self._running()
                and self._requests.empty()
            ):
                self._tick()
            now = wallclock.perf_counter()
            if target - loop.time > LAG_LIMIT * self._slow_motion:
                anchor_wall, anchor_sim = now, loop.time  # too slow: run flat out
            if now - speed_wall >= SPEED_WINDOW:
                self._speed = (loop.time - speed_sim) / (now - speed_wall)
                speed_wall, speed_sim = now, loop.time
            if now - last_publish >= PUBLISH_PERIOD or not self._running():
                self._publish()
                last_publish = now
            wait = (loop.time + loop.period - target) / self._slow_motion
            if wait > 0.0:
                stop.wait(min(wait, PUBLISH_PERIOD))

    def _running(self) -> bool:
        return not (
            self._paused
            or self._busy
            or self._error
            or self._require_loop().backend.fall_status().fell
        )

    def _handle_requests(self) -> bool:
        """Apply pending requests; True if pacing must restart."""
        changed = False
        while True:
            try:
                kind, value = self._requests.get_nowait()
            except queue.Empty:
                return changed
            changed = True
            try:
                if kind == "push" and isinstance(value, PushInput):
                    self._apply_push(value)
                elif kind == "reset":
                    self._reset()
                elif kind == "pause":
                    self._paused = bool(value)
                    self._event("pause" if self._paused else "resume")
                elif kind == "slow" and isinstance(value, float):
                    self._slow_motion = value
                elif kind == "controller" and isinstance(value, str):
                    self._busy = f"building the {value} controller"
                    self._publish()
                    try:
                        self._build(value)
                    finally:
                        self._busy = ""
                    self._error = ""
                    self._event(f"controller {value}: run restarted")
            except (RsgError, RuntimeError, ValueError) as exc:
                self._error = f"{kind} failed: {exc}"
                self._event(f"error {self._error}")

    def _apply_push(self, push_input: PushInput) -> None:
        loop = self._require_loop()
        why = push_refusal(push_input)
        if loop.backend.fall_status().fell:
            why = "the robot has fallen (press Reset)"
        elif self._paused:
            why = "the run is paused (press Resume)"
        elif self._error:
            why = "the run has stopped (press Reset)"
        if why:
            self._event(f"push refused: {why}")
            return
        push = Push(loop.time, push_input.impulse_xy(), push_input.duration)
        loop.push_now(push)
        self._pushes_applied += 1
        self._last_push = np.asarray(push.impulse, float)
        self._event(push_line(push, "page"))

    def _reset(self) -> None:
        loop = self._require_loop()
        self._busy = "resetting"
        self._publish()
        try:
            loop.scenario = self._scenario
            loop.reset()
        finally:
            self._busy = ""
        self._error = ""
        self._fresh_run()
        self._event("reset: the robot stands again, the run restarts")

    def _tick(self) -> None:
        loop = self._require_loop()
        time = loop.time
        for push in self._scenario.pushes:
            if time - 1e-9 <= push.time < time + loop.period - 1e-9:
                self._pushes_applied += 1
                self._last_push = np.asarray(push.impulse, float)
                self._event(push_line(push, "scenario"))
        try:
            out = loop.tick()
        except RsgError as exc:
            self._error = f"simulation stopped at t={time:.3f} s: {exc}"
            self._event(f"error {self._error}")
            return
        self._out = out
        if out.step is not None:
            mark = StepMark(
                out.step.time, out.step.foot, np.array(out.step.position), out.step.adjusted
            )
            self._steps.append(mark)
            del self._steps[:-STEP_MARKS]
            self._adjusted_steps += int(mark.adjusted)
            line = step_line(mark, out.step.lyapunov_before, out.step.lyapunov_after)
            self._event(line, printed=self._log_steps)
        if loop.ticks % self._record_every == 0:
            measured = loop.measured
            omega = self._config.model.omega
            self._com_trail.append(measured.com_position)
            self._zmp_trail.append(out.zmp)
            self._dcm_trail.append(measured.com_position + measured.com_velocity / omega)
            self._dcm_error_trail.append(out.dcm_error)
            self._plot.append((loop.time, out.lyapunov, out.time_since_step))
        fall = loop.backend.fall_status()
        if fall.fell and not self._fall_reported:
            self._fall_reported = True
            self._event(f"fall t={loop.time:.3f} s reason={fall.reason}")

    def _event(self, line: str, printed: bool = True) -> None:
        """``line`` becomes the status's last event; printed unless told not to."""
        self._last_event = line
        if printed:
            self._log(line)

    # ----------------------------------------------------------------- snapshots
    def _publish(self) -> None:
        self._snapshot = self._make_snapshot()

    def _make_snapshot(self) -> Snapshot:
        loop = self._require_loop()
        fall = loop.backend.fall_status()
        status = PageStatus(
            time=loop.time,
            model=self.model,
            robot=self.robot or "",
            controller=self._controller,
            paused=self._paused,
            slow_motion=self._slow_motion,
            speed=self._speed,
            last_event=self._last_event,
            fell=fall.fell,
            fall_reason=fall.reason,
            busy=self._busy,
            error=self._error,
        )
        self._serial += 1
        plot = self._plot.points()
        return Snapshot(
            serial=self._serial,
            state=self._controller_state(loop),
            robot=self._robot_pose(loop),
            status=status,
            plot_time=plot[:, 0],
            plot_lyapunov=plot[:, 1],
            plot_time_since_step=plot[:, 2],
            level_set=loop.generator.design.level_set,
            foot_lower=self._foot_lower,
            foot_upper=self._foot_upper,
            mass=loop.backend.mass,
            pushes_applied=self._pushes_applied,
            adjusted_steps=self._adjusted_steps,
            last_push=self._last_push,
        )

    def _controller_state(self, loop: ClosedLoop) -> ControllerState | None:
        out = self._out
        if out is None:
            return None
        measured = loop.measured
        cons = self._config.constraints
        time = loop.time
        active = [p for p in loop.scenario.pushes if p.time <= time < p.time + p.duration]
        impulse = np.sum([np.asarray(p.impulse, float) for p in active], axis=0) if active else None
        fall = loop.backend.fall_status()
        return ControllerState(
            time=time,
            com=measured.com_position.copy(),
            com_velocity=measured.com_velocity.copy(),
            com_height=loop.backend.com_height,
            omega=self._config.model.omega,
            zmp=np.array(out.zmp),
            window_center=np.array(out.window_center),
            window_min=np.array(cons.zmp_window_min),
            window_max=np.array(cons.zmp_window_max),
            stance_foot=out.stance.foot,
            stance=np.array(out.stance.position),
            previous_foot=out.previous_stance.foot,
            previous=np.array(out.previous_stance.position),
            next_foot=out.next_step.foot,
            next_step=np.array(out.next_step.position),
            steps=tuple(self._steps),
            dcm_error=np.array(out.dcm_error),
            lyapunov=float(out.lyapunov),
            threshold=float(loop.generator.design.threshold),
            time_since_step=float(out.time_since_step),
            push_impulse=impulse,
            fell=fall.fell,
            fall_reason=fall.reason,
            com_trail=self._com_trail.points(),
            zmp_trail=self._zmp_trail.points(),
            dcm_trail=self._dcm_trail.points(),
            dcm_error_trail=self._dcm_error_trail.points(),
        )

    def _robot_pose(self, loop: ClosedLoop) -> RobotPose | None:
        configuration = getattr(loop.backend, "robot_configuration", None)
        if configuration is None:
            return None
        position, quaternion_xyzw, joints = configuration()
        x, y, z, w = (float(v) for v in quaternion_xyzw)
        return RobotPose(
            np.asarray(position, float).copy(),
            np.array([w, x, y, z]),
            {name: float(angle) for name, angle in joints.items()},
        )


def _print_line(line: str) -> None:
    print(line, flush=True)
    sys.stdout.flush()
