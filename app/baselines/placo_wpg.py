"""The ``placo-wpg`` baseline: placo's walk pattern generator with ``update_supports``.

The baseline a placo user would pick (placo 0.10.2): its walk pattern generator
re-planned with ``update_supports`` on the measured DCM, driving the same robot through
the same whole-body IK and PyBullet backend as the RSG. :class:`PlacoWalkPlanner` has
the generator's interface and is swapped into :class:`app.runner.ClosedLoop` through
its ``planner`` factory. One line of why per choice below; the configuration, the tick
and the measurements behind each choice: ``docs/baselines.md``.

- one placo support per RSG step, no placo double support: the backend moves the
  weight at the jump, and placo's mid-feet ZMP in double support cannot be realised;
- the ZMP command is placo's plus the RSG's ZMP feedback on the DCM error: placo's
  open-loop ZMP lets any DCM error grow as exp(omega t) on this backend;
- ``update_supports`` every tick from T_DSP into a support, a replan only when the
  step moves by ``STEP_TOLERANCE`` or ``TIME_TOLERANCE``: replanning every tick
  chatters and falls;
- a hard-constraint replan that is infeasible is redone with soft constraints: placo
  otherwise drops the adaptation;
- the jump ``CROSSING_DELAY`` into placo's support, when its ZMP is nearer the new
  sole: the clipped plan then errs as much before the jump as after it.

V_u is not defined for this planner (reported 0); on the full robot recovery is "no
fall" for every controller.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from app.backends.base import InitialCondition
from app.backends.physics_log import PhysicsLog
from app.reality import DEFAULT_PROFILE
from app.setup.build import build_robot_backend
from app.setup.overrides import Overrides
from planner.exceptions import RsgError
from planner.lyapunov import design_lyapunov
from planner.parameters import PlannerConfig
from planner.types import Foot, Foothold, MeasuredState, PlannerOutput, StepEvent, other_foot
from robots.description import RobotDescription

PLANNING_TIME_STEP = 0.05  # [s] target time step of placo's CoM QP
STEPS_AHEAD = 2  # footsteps planned beyond the current one
VIRTUAL_STEPS = 1  # virtual strides (2 steps) walked in the plan only before t = 0, from rest
LOCATION_TOLERANCE = 1e-3  # [m] a step further than this from nominal is "adjusted"
STEP_TOLERANCE = 0.02  # [m] update_supports moving the next foot less than this: no replan
TIME_TOLERANCE = 0.01  # [s] ... or moving the end of the support less than this
CROSSING_DELAY = 0.5 * PLANNING_TIME_STEP  # [s] placo's ZMP crosses between the feet then
ZMP_MARGIN = 0.005  # [m] same as app.setup.robot_config.ZMP_MARGIN


@dataclass(frozen=True)
class BaselineDesign:
    """What :class:`app.runner.ClosedLoop` reads from ``generator.design``.

    placo-wpg has no Lyapunov function: ``level`` is 0 everywhere, the matrix and
    the gain are zero; ``threshold`` is the RSG's gamma_v (only so that the
    result files keep their fields; "V_u < gamma_v" is then always true).
    """

    threshold: float
    matrix: NDArray[np.float64] = field(default_factory=lambda: np.zeros((2, 2)))
    gain: NDArray[np.float64] = field(default_factory=lambda: np.zeros((4, 2)))

    def level(self, error: NDArray[np.float64]) -> float:  # noqa: ARG002
        return 0.0


def _side(foot: Foot) -> Any:
    import placo

    return placo.HumanoidRobot_Side.left if foot == "left" else placo.HumanoidRobot_Side.right


def _foot(side: Any) -> Foot:
    return "left" if str(side).endswith("left") else "right"


def _box(x: tuple[float, float], y: tuple[float, float]) -> list[NDArray[np.float64]]:
    """Rectangle as placo's polygons want it (clockwise)."""
    return [np.array([x[0], y[0]]), np.array([x[0], y[1]]), np.array([x[1], y[1]]),
            np.array([x[1], y[0]])]  # fmt: skip


def humanoid_parameters(description: RobotDescription, config: PlannerConfig) -> Any:
    """placo's ``HumanoidParameters`` for the robot and the RSG's gait (module notes)."""
    import placo

    gait, cons = config.gait, config.constraints
    sole = description.sole
    params = placo.HumanoidParameters()
    params.single_support_duration = gait.step_duration  # T_SSP + T_DSP (module notes)
    params.single_support_timesteps = max(1, round(gait.step_duration / PLANNING_TIME_STEP))
    params.double_support_ratio = 0.0
    params.startend_double_support_ratio = 1.0
    params.planned_timesteps = params.single_support_timesteps * (STEPS_AHEAD + 1)
    params.walk_com_height = config.model.com_height
    params.feet_spacing = gait.step_width
    params.foot_length = sole.x_max - sole.x_min
    params.foot_width = 2.0 * sole.half_width
    params.zmp_margin = ZMP_MARGIN
    params.walk_max_dx_forward = cons.step_max[0]
    params.walk_max_dx_backward = -cons.step_min[0]
    params.walk_max_dy = max(cons.step_max[1] - gait.step_width, 0.0)
    crossing = 2.0 * cons.half_width + config.rsg.crossing_margin
    reach_x = min(-cons.step_min[0], cons.step_max[0])  # symmetric: placo mirrors it
    params.op_space_polygon = _box((-reach_x, reach_x), (crossing, cons.step_max[1]))
    half_length = 0.5 * params.foot_length
    params.dcm_offset_polygon = _box(
        (-half_length, half_length), (-0.5 * gait.step_width, 0.5 * gait.step_width)
    )
    return params


class PlacoWalkPlanner:
    """placo's ``WalkPatternGenerator`` + ``update_supports`` behind the RSG's interface.

    Args:
        description: The robot (URDF for placo's ``HumanoidRobot``, sole).
        config: The RSG's configuration of the same robot (gait, bounds, c_z).

    Attributes:
        feedback: ZMP feedback gain K_p on the DCM error [-], shape (2, 2) (the
            RSG's, module notes).
        tick_times: Wall time of each :meth:`update` [s].
        updates, update_failures: ``update_supports`` calls that succeeded/raised.
        replans, replan_failures: ``replan`` calls, and those placo reported failed.
    """

    def __init__(self, description: RobotDescription, config: PlannerConfig) -> None:
        import placo

        from kinematics.whole_body_ik import humanoid_robot

        self.description = description
        self.config = config
        self.design = BaselineDesign(config.rsg.lyapunov_threshold)
        self.feedback = design_lyapunov(config.model, config.constraints, config.rsg).gain[:2]
        self.window_min = np.array(config.constraints.zmp_window_min, float)
        self.window_max = np.array(config.constraints.zmp_window_max, float)
        self.omega = math.sqrt(config.model.gravity / config.model.com_height)
        sole = description.sole
        self.sole_center = np.array([0.5 * (sole.x_min + sole.x_max), 0.0])
        self.parameters = humanoid_parameters(description, config)
        self.robot = humanoid_robot(description)
        self.wpg = placo.WalkPatternGenerator(self.robot, self.parameters)
        self.footsteps = placo.FootstepsPlannerRepetitive(self.parameters)
        self.footsteps.configure(config.gait.stride_length, 0.0, 0.0, STEPS_AHEAD + 1)
        self.tick_times: list[float] = []
        self.reset(
            Foothold("left", np.array([0.0, 0.1])), Foothold("right", np.array([-0.1, -0.1]))
        )

    # ------------------------------------------------------------------ setup
    def _footstep(self, foot: Foot, ankle: NDArray[np.float64]) -> Any:
        import placo

        step = placo.Footstep(self.parameters.foot_width, self.parameters.foot_length)
        step.side = _side(foot)
        frame = np.eye(4)
        frame[:2, 3] = np.asarray(ankle, float) + self.sole_center
        step.frame = frame
        return step

    def reset(self, stance: Foothold, previous: Foothold) -> None:
        """Plan from rest so that at t = 0 the single support on ``stance`` begins.

        placo's support on ``stance`` starts at -T_DSP (the RSG's s~ = T_DSP at
        t = 0). The plan starts at rest with a start double support (T_SSP + T_DSP
        long) on footholds ``2 VIRTUAL_STEPS + 1`` steps behind ``stance``, walks
        up to ``previous`` and ``stance`` (only in the plan: the simulation starts
        at t = 0 in the trajectory's state, :meth:`initial_condition`) and goes on
        at L_x, ``STEPS_AHEAD`` steps ahead.
        """
        import placo

        gait = self.config.gait
        stride = np.array([gait.stride_length, 0.0])
        stance_xy = np.asarray(stance.position, float)
        previous_xy = np.asarray(previous.position, float)
        # Step i: the stance foot for even i (at stance + i L_x), the other foot for
        # odd i; i = 0 is the stance foot at t = 0, i = -1 the previous one.
        first = -(2 * VIRTUAL_STEPS + 1)
        steps = []
        for i in range(first, STEPS_AHEAD + 1):
            if i % 2 == 0:
                steps.append(self._footstep(stance.foot, stance_xy + i * stride))
            else:
                steps.append(self._footstep(previous.foot, previous_xy + (i + 1) * stride))
        start_duration = float(self.parameters.startend_double_support_duration())
        t0 = -(gait.double_support_duration + start_duration + (-first - 1) * gait.step_duration)
        supports = placo.FootstepsPlanner.make_supports(steps, t0, True, False, True)
        middle = 0.5 * (steps[0].frame[:2, 3] + steps[1].frame[:2, 3])
        com = np.array([middle[0], middle[1], self.config.model.com_height])
        self.trajectory = self.wpg.plan(supports, com, t0)
        support = self.trajectory.get_support(0.0)
        if support.is_both() or _foot(support.side()) != stance.foot:
            raise RsgError("placo-wpg: the plan does not start on the stance foot at t = 0")
        self.last_replan = t0
        self._replanned_on: NDArray[np.float64] | None = None
        self.stance = Foothold(stance.foot, stance_xy.copy())
        self.previous = Foothold(previous.foot, previous_xy.copy())
        self.step_time = -gait.double_support_duration  # s~ = T_DSP at t = 0
        self.support_start = float(self.trajectory.get_part_t_start(0.0))
        self._support_key: tuple = ()
        self._support_boundary = self.support_start
        self.updates = 0
        self.update_failures = 0
        self.replans = 0
        self.replan_failures = 0
        self.soft_replan_failures = 0

    def initial_condition(self) -> InitialCondition:
        """The trajectory's state at t = 0 (T_DSP into the support on the stance foot)."""
        com = np.asarray(self.trajectory.get_p_world_CoM(0.0), float)[:2]
        velocity = np.asarray(self.trajectory.get_v_world_CoM(0.0), float)[:2]
        return InitialCondition(self.stance, self.previous, com, velocity)

    # ---------------------------------------------------------------- helpers
    def _ankle(self, support: Any, foot: Foot) -> NDArray[np.float64]:
        frame = np.asarray(support.footstep_frame(_side(foot)), float)
        return frame[:2, 3] - self.sole_center

    def _adapt(self, t: float, dcm: NDArray[np.float64]) -> None:
        """replan_supports, update_supports fed ``dcm``, replan if needed (module notes)."""
        import placo

        wpg, trajectory = self.wpg, self.trajectory
        if not wpg.can_replan_supports(trajectory, t):
            return
        supports = list(wpg.replan_supports(self.footsteps, trajectory, t, self.last_replan))
        current = supports[0]
        current.target_world_dcm = np.asarray(trajectory.get_part_end_dcm(t, self.omega))
        try:
            updated = list(wpg.update_supports(t, [current, supports[1]], dcm))
        except RuntimeError:
            self.update_failures += 1
        else:
            self.updates += 1
            supports[0], supports[1] = updated[0], updated[1]
        stance = _foot(current.side())
        swing = other_foot(stance)
        landing = self._ankle(supports[1], swing)
        remaining = (
            (1.0 - current.elapsed_ratio)
            * self.parameters.single_support_duration
            * supports[0].time_ratio
        )
        moved = np.max(np.abs(landing - self._ankle(trajectory.get_next_support(t, 1), swing)))
        retimed = abs(t + remaining - float(trajectory.get_part_t_end(t)))
        on = self._ankle(current, stance)
        new_support = self._replanned_on is None or bool(np.any(on != self._replanned_on))
        if not (new_support or moved > STEP_TOLERANCE or retimed > TIME_TOLERANCE):
            return
        vector = placo.Supports()
        for support in supports:
            vector.append(support)
        replanned = wpg.replan(vector, trajectory, t)
        self.replans += 1
        if not replanned.replan_success:  # infeasible with hard ZMP constraints
            self.replan_failures += 1
            wpg.soft = True
            replanned = wpg.replan(vector, trajectory, t)
            wpg.soft = False
            if not replanned.replan_success:
                self.soft_replan_failures += 1
        self.trajectory = replanned
        self.last_replan = t
        self._replanned_on = on

    # -------------------------------------------------------------- one tick
    def update(self, measured: MeasuredState, period: float) -> PlannerOutput:
        """Adapt the plan to the measured DCM, then read this tick's command from it."""
        started = time.perf_counter()
        t = float(measured.time)
        com = np.asarray(measured.com_position, float)
        dcm = com + np.asarray(measured.com_velocity, float) / self.omega
        current = self.trajectory.get_support(t)
        key = (_foot(current.side()), *self._ankle(current, _foot(current.side())))
        if key != self._support_key:  # a new support: its start, from the plan made before it
            self._support_key = key
            self._support_boundary = float(self.trajectory.get_part_t_start(t))
        boundary = self._support_boundary
        if t > 0.0 and t - boundary >= self.config.gait.double_support_duration - 1e-9:
            self._adapt(t, dcm)
        trajectory = self.trajectory
        support = trajectory.get_support(t)
        if support.is_both():
            raise RsgError(f"placo-wpg: the plan has no single support at t = {t:.3f} s")
        foot = _foot(support.side())
        ankle = self._ankle(support, foot)
        reference_zmp = np.asarray(trajectory.get_p_world_ZMP(t, self.omega), float)[:2]
        gait = self.config.gait
        step_event = None
        if foot != self.stance.foot and (
            t - boundary >= PLANNING_TIME_STEP - 1e-9
            or np.linalg.norm(reference_zmp - self.sole_center - ankle)
            <= np.linalg.norm(reference_zmp - self.sole_center - self.stance.position)
        ):  # the jump: placo's ZMP is now nearer the new foot (module notes)
            old = self.stance
            side = 1.0 if old.foot == "left" else -1.0
            nominal = old.position + np.array([gait.stride_length, -side * gait.step_width])
            nominal_time = self.support_start + gait.step_duration
            self.previous = old
            self.stance = Foothold(foot, ankle.copy())
            step_event = StepEvent(
                time=t,
                foot=foot,
                position=ankle.copy(),
                timing_adjusted=abs(boundary - nominal_time) > 0.5 * period,
                location_adjusted=bool(np.max(np.abs(ankle - nominal)) > LOCATION_TOLERANCE),
            )
            self.step_time = t  # the jump tick, as the RSG's s_j
            self.support_start = boundary
        if foot == self.stance.foot:
            swing = other_foot(foot)
            next_step = Foothold(swing, self._ankle(trajectory.get_next_support(t, 1), swing))
            next_time = float(trajectory.get_part_t_end(t)) + CROSSING_DELAY
        else:  # placo's new support began, its ZMP is still nearer the old foot
            next_step = Foothold(foot, ankle.copy())
            next_time = max(boundary + CROSSING_DELAY, t)  # as announced before
        since = t - self.step_time
        reference_dcm = np.asarray(trajectory.get_p_world_DCM(t, self.omega), float)[:2]
        error = dcm - reference_dcm
        window = self.stance.position.copy()
        feedforward = reference_zmp - window
        if np.any(feedforward < self.window_min) or np.any(feedforward > self.window_max):
            feedforward = self.sole_center.copy()  # placo's transition between the feet
        offset = np.clip(feedforward + self.feedback @ error, self.window_min, self.window_max)
        output = PlannerOutput(
            time=t,
            zmp=window + offset,
            zmp_offset=offset,
            window_center=window,
            angular_momentum_rate=np.zeros(2),
            angular_momentum_rate_feedback=np.zeros(2),
            stance=self.stance,
            previous_stance=self.previous,
            next_step=next_step,
            next_step_time=next_time,
            time_since_step=since,
            double_support=bool(since < gait.double_support_duration - 1e-9),
            dcm_error=error,
            lyapunov=0.0,
            lyapunov_at_step=0.0,
            com_reference=np.asarray(trajectory.get_p_world_CoM(t), float)[:2],
            step=step_event,
            extra={
                "planned_step_time": next_time,
                "reference_dcm": reference_dcm,
                "reference_zmp": reference_zmp,
            },
        )
        self.tick_times.append(time.perf_counter() - started)
        return output


def planner_factory(description: RobotDescription):  # noqa: ANN201
    """``config -> PlacoWalkPlanner`` for :class:`app.runner.ClosedLoop`'s ``planner``."""

    def build(config: PlannerConfig) -> PlacoWalkPlanner:
        return PlacoWalkPlanner(description, config)

    return build


def build_placo_wpg_backend(  # noqa: ANN201
    robot: str,
    overrides: Overrides = (),
    physics_log: PhysicsLog | None = None,
    reality: str = DEFAULT_PROFILE,
    seed: int = 0,
    engine: str = "pybullet",
):
    """Full-robot backend on ``engine``, configuration, initial condition and planner
    factory of placo-wpg.

    The backend, IK and configuration are the RSG's (:func:`app.setup.build.
    build_robot_backend`, with ``overrides``, ``physics_log`` and the reality profile
    ``reality`` drawn from ``seed``); the initial state is placo's plan at t = 0.
    """
    backend, config, _ = build_robot_backend(
        robot, "rsg", overrides, physics_log=physics_log, reality=reality, seed=seed,
        engine=engine,
    )  # fmt: skip
    factory = planner_factory(backend.description)
    initial = factory(config).initial_condition()
    return backend, config, initial, factory
