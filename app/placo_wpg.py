"""The ``placo-wpg`` baseline: placo's walk pattern generator with ``update_supports``.

The baseline a placo user would pick (placo 0.10.2), driving the same robot through
the same whole-body IK (:class:`kinematics.whole_body_ik.WholeBodyIK`) and the same
PyBullet backend as the RSG. :class:`PlacoWalkPlanner` has the generator's
interface (``reset(stance, previous)``, ``update(measured, period)``, ``design``)
and is swapped into :class:`app.runner.ClosedLoop` through its ``planner`` factory.

Configuration (:func:`humanoid_parameters`, all from the robot description and the
RSG's :class:`planner.parameters.PlannerConfig`, so both walk the same gait):

- ``single_support_duration`` = T_SSP, ``double_support_ratio`` = T_DSP / T_SSP,
  ``single_support_timesteps`` = T_SSP / 0.05 s (the CoM QP's time step);
  ``walk_com_height`` = c_z; ``feet_spacing`` = L_y; footsteps repeat forward at
  L_x (``FootstepsPlannerRepetitive.configure(L_x, 0, 0, STEPS_AHEAD)``);
- the footstep frame is the centre of the sole rectangle (placo's support polygon
  is centred on it), ``foot_length``/``foot_width`` the sole's size and
  ``zmp_margin`` the RSG's ZMP margin (:data:`app.robot_setup.ZMP_MARGIN`);
  footholds in :class:`planner.types.PlannerOutput` are ankle positions o_H, as
  for the RSG;
- ``op_space_polygon`` (hard, where the next foot may land relative to the
  stance foot): the RSG's step box u_d^m <= u_d <= u_d^M with the no-crossing
  bound |u_d,y| >= 2 w_y + mu_2; ``dcm_offset_polygon`` (placo's soft
  "viability" region of the DCM relative to the next foot at touchdown): half a
  sole length fore and aft, half the step width sideways; both symmetric, as
  placo mirrors them through the origin for a left stance foot;
  ``walk_max_dx_forward``/``walk_max_dx_backward``/``walk_max_dy`` from u_d^M,
  u_d^m (footstep clipping).

Every control tick (:meth:`PlacoWalkPlanner.update`), in single support and while
placo allows it (``can_replan_supports``):

1. ``replan_supports(planner, trajectory, t, t_last)``: the current support and
   the footsteps ahead;
2. ``update_supports(t, [current, next single support], measured DCM)``: placo's
   QP on the current support's remaining duration and the next foot's location,
   fed the measured DCM c + cdot / omega. Two adaptations, both needed for it to
   do what its documentation says with a gait that has double supports: (a)
   ``replan_supports`` leaves ``target_world_dcm`` at zero, so it is set to the
   trajectory's DCM at the end of the current support
   (``get_part_end_dcm``); (b) placo moves ``supports[1].footsteps[0]``, which
   with double supports is the STANCE foot of the double support, so the QP is
   given the list without the double support and its result (next foot and
   ``time_ratio``) is written into the double support and the next single
   support;
3. ``replan(supports, trajectory, t)``: a new CoM trajectory from the old one's
   state at t (placo never resets its plan to the measurement; the measured
   DCM enters only through step 2).

The tick's command is read from the trajectory: ZMP ``get_p_world_ZMP``, CoM
reference ``get_p_world_CoM``, the footholds of the current/next supports and the
end time of the current single support (= the next step time). A "step" in the
RSG's sense (new stance foot, s~ = 0) is the start of a double support. hdot = 0.
Not defined for this planner: the Lyapunov level V_u (reported 0; ``design``
carries the RSG's gamma_v only so that the result files have the same fields).
On the full robot, recovery is "no fall" for every controller.

placo's step-time bounds are its own (hard-coded in 0.10.2): the current single
support may end 0.15 s after it started at the earliest, 3 s at the latest; the
RSG waits at least T_DSP + T_SP after a step (T_SP = 0.5 s on G1). An earlier
step finds the swing foot in the air; the backend then puts it down at once.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass, field
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import RsgError
from planner.parameters import PlannerConfig
from planner.types import Foot, Foothold, MeasuredState, PlannerOutput, StepEvent, other_foot
from robots.description import RobotDescription

from .backend import InitialCondition

PLANNING_TIME_STEP = 0.05  # [s] target time step of placo's CoM QP
STEPS_AHEAD = 4  # footsteps planned beyond the current one
VIRTUAL_STEPS = 1  # virtual strides (2 steps) walked in the plan only before t = 0, from rest
LOCATION_TOLERANCE = 1e-3  # [m] a step further than this from nominal is "adjusted"
ZMP_MARGIN = 0.005  # [m] same as app.robot_setup.ZMP_MARGIN


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
    params.single_support_duration = gait.single_support_duration
    params.single_support_timesteps = max(
        1, round(gait.single_support_duration / PLANNING_TIME_STEP)
    )
    params.double_support_ratio = gait.double_support_duration / gait.single_support_duration
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
    """

    def __init__(self, description: RobotDescription, config: PlannerConfig) -> None:
        import placo

        from kinematics.whole_body_ik import kinematic_urdf_text

        self.description = description
        self.config = config
        self.design = BaselineDesign(config.rsg.lyapunov_threshold)
        self.omega = math.sqrt(config.model.gravity / config.model.com_height)
        sole = description.sole
        self.sole_center = np.array([0.5 * (sole.x_min + sole.x_max), 0.0])
        self.parameters = humanoid_parameters(description, config)
        self.robot = placo.HumanoidRobot(
            "", placo.Flags.ignore_collisions, kinematic_urdf_text(description)
        )
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
        """Plan from rest so that at t = 0 a single support on ``stance`` begins.

        The plan starts at rest with a start double support (T_SSP long) on
        footholds ``2 VIRTUAL_STEPS + 1`` steps behind ``stance``, walks up to
        ``previous`` and ``stance`` (only in the plan: the simulation starts at
        t = 0 in the trajectory's state, :meth:`initial_condition`) and goes on
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
        step_time = gait.single_support_duration + gait.double_support_duration
        start_duration = float(self.parameters.startend_double_support_duration())
        t0 = -(start_duration + (-first - 1) * step_time)
        supports = placo.FootstepsPlanner.make_supports(steps, t0, True, True, True)
        middle = 0.5 * (steps[0].frame[:2, 3] + steps[1].frame[:2, 3])
        com = np.array([middle[0], middle[1], self.config.model.com_height])
        self.trajectory = self.wpg.plan(supports, com, t0)
        support = self.trajectory.get_support(1e-6)
        if support.is_both() or _foot(support.side()) != stance.foot:
            raise RsgError("placo-wpg: the plan does not start on the stance foot at t = 0")
        self.last_replan = 0.0
        self.stance = Foothold(stance.foot, stance_xy.copy())
        self.previous = Foothold(previous.foot, previous_xy.copy())
        self.step_time = -gait.double_support_duration  # s~ = T_DSP at t = 0
        self.updates = 0
        self.update_failures = 0
        self.replan_failures = 0

    def initial_condition(self) -> InitialCondition:
        """The trajectory's state at t = 0 (start of the single support on the stance foot)."""
        com = np.asarray(self.trajectory.get_p_world_CoM(0.0), float)[:2]
        velocity = np.asarray(self.trajectory.get_v_world_CoM(0.0), float)[:2]
        return InitialCondition(self.stance, self.previous, com, velocity)

    # ---------------------------------------------------------------- helpers
    def _ankle(self, support: Any, foot: Foot) -> NDArray[np.float64]:
        frame = np.asarray(support.footstep_frame(_side(foot)), float)
        return frame[:2, 3] - self.sole_center

    def _adapt(self, t: float, dcm: NDArray[np.float64]) -> None:
        """replan_supports, update_supports fed ``dcm``, replan (module notes)."""
        import placo

        wpg, trajectory = self.wpg, self.trajectory
        if not wpg.can_replan_supports(trajectory, t):
            return
        supports = list(wpg.replan_supports(self.footsteps, trajectory, t, self.last_replan))
        if len(supports) >= 3 and not supports[0].is_both() and supports[1].is_both():
            current, double, following = supports[0], supports[1], supports[2]
            current.target_world_dcm = np.asarray(trajectory.get_part_end_dcm(t, self.omega))
            swing = other_foot(_foot(current.side()))
            try:
                updated = wpg.update_supports(t, [current, following], dcm)
            except RuntimeError:
                self.update_failures += 1
            else:
                self.updates += 1
                current.time_ratio = updated[0].time_ratio
                landing = np.asarray(updated[1].footsteps[0].frame, float)
                for support in (double, following):
                    steps = list(support.footsteps)
                    for step in steps:
                        if _foot(step.side) == swing:
                            step.frame = landing
                    support.footsteps = steps
                supports[0], supports[1], supports[2] = current, double, following
        vector = placo.Supports()
        for support in supports:
            vector.append(support)
        replanned = wpg.replan(vector, trajectory, t)
        if not replanned.replan_success:
            self.replan_failures += 1
        self.trajectory = replanned
        self.last_replan = t

    def _stance_and_next(self, t: float) -> tuple[Foot, NDArray[np.float64], Any, float]:
        """Stance foot and ankle, the support holding the next step, the next step time."""
        trajectory = self.trajectory
        support = trajectory.get_support(t)
        end = float(trajectory.get_part_t_end(t))
        if support.is_both():  # a double support: the foot that just landed is the stance
            single = trajectory.get_next_support(t, 1)
            foot = _foot(single.side())
            return (
                foot,
                self._ankle(single, foot),
                trajectory.get_next_support(t, 2),
                float(trajectory.get_part_t_end(end + 1e-6)),
            )
        foot = _foot(support.side())
        return foot, self._ankle(support, foot), trajectory.get_next_support(t, 1), end

    # -------------------------------------------------------------- one tick
    def update(self, measured: MeasuredState, period: float) -> PlannerOutput:  # noqa: ARG002
        """Adapt the plan to the measured DCM, then read this tick's command from it."""
        started = time.perf_counter()
        t = float(measured.time)
        com = np.asarray(measured.com_position, float)
        dcm = com + np.asarray(measured.com_velocity, float) / self.omega
        if t > 0.0:
            self._adapt(t, dcm)
        trajectory = self.trajectory
        foot, ankle, next_support, next_time = self._stance_and_next(t)
        gait = self.config.gait
        step_event = None
        if foot != self.stance.foot:
            old = self.stance
            nominal_time = self.step_time + gait.step_duration
            landed = float(trajectory.get_part_t_start(t))
            side = 1.0 if old.foot == "left" else -1.0
            nominal = old.position + np.array([gait.stride_length, -side * gait.step_width])
            self.previous = old
            self.stance = Foothold(foot, ankle.copy())
            step_event = StepEvent(
                time=t,
                foot=foot,
                position=ankle.copy(),
                timing_adjusted=abs(landed - nominal_time) > 0.5 * period,
                location_adjusted=bool(np.max(np.abs(ankle - nominal)) > LOCATION_TOLERANCE),
            )
            self.step_time = landed
        elif np.any(ankle != self.stance.position):
            self.stance = Foothold(foot, ankle.copy())
        since = t - self.step_time
        double_support = since < gait.double_support_duration - 1e-9
        window = self.stance.position.copy()
        if double_support:
            share = (gait.double_support_duration - since) / gait.double_support_duration
            window = window - (self.stance.position - self.previous.position) * share
        zmp = np.asarray(trajectory.get_p_world_ZMP(t, self.omega), float)[:2]
        reference_dcm = np.asarray(trajectory.get_p_world_DCM(t, self.omega), float)[:2]
        swing = other_foot(foot)
        output = PlannerOutput(
            time=t,
            zmp=zmp,
            zmp_offset=zmp - window,
            window_center=window,
            angular_momentum_rate=np.zeros(2),
            angular_momentum_rate_feedback=np.zeros(2),
            stance=self.stance,
            previous_stance=self.previous,
            next_step=Foothold(swing, self._ankle(next_support, swing)),
            next_step_time=next_time,
            time_since_step=since,
            double_support=bool(double_support),
            dcm_error=dcm - reference_dcm,
            lyapunov=0.0,
            lyapunov_at_step=0.0,
            com_reference=np.asarray(trajectory.get_p_world_CoM(t), float)[:2],
            step=step_event,
            extra={"planned_step_time": next_time, "reference_dcm": reference_dcm},
        )
        self.tick_times.append(time.perf_counter() - started)
        return output


def planner_factory(description: RobotDescription):  # noqa: ANN201
    """``config -> PlacoWalkPlanner`` for :class:`app.runner.ClosedLoop`'s ``planner``."""

    def build(config: PlannerConfig) -> PlacoWalkPlanner:
        return PlacoWalkPlanner(description, config)

    return build


def build_placo_wpg_backend(robot: str):  # noqa: ANN201
    """PyBullet backend, configuration, initial condition and planner factory of placo-wpg.

    The backend, IK and configuration are the RSG's (:func:`app.robot_setup.
    build_robot_backend`); the initial state is placo's plan at t = 0.
    """
    from robots import get_robot

    from .robot_setup import build_robot_backend

    backend, config, _ = build_robot_backend(robot, "rsg")
    factory = planner_factory(get_robot(robot))
    initial = factory(config).initial_condition()
    return backend, config, initial, factory
