"""Full-humanoid backend: the planner's commands realised on a robot in PyBullet.

Each control tick (``control_period``, several 1 ms physics steps):

1. CoM plan: a CoM reference state (c_ref, v_ref) is integrated over the tick
   with the LIPM driven by the commanded ZMP and rate of angular momentum; before
   that it is pulled toward the MEASURED state by ``com_reference_blend`` (0:
   open-loop reference, 1: integrate from the measurement). The IK CoM target is
   c_ref (+ optional K_p/K_v corrections and a LIPM look-ahead). Measured on G1:
   integrating from the measurement every tick (blend 1) turns the position
   controller into a pure inverted pendulum: with a constant ZMP command it
   drifts and falls within 1 s; blend 0 stands indefinitely.
2. Feet: the stance sole is put flat at ``command.stance.position``; the swing
   sole follows :class:`SwingFootTrajectory` toward ``command.next_step.position``
   with the planner's timing: touchdown ``touchdown_lead`` before
   ``command.next_step_time`` (absolute [s], re-planned every tick). The planner's jump (``command.step``) happens at its planned time: the
   swing foot becomes the stance foot at the step position at once.
3. Whole-body IK (placo) -> joint position targets (velocity feed-forward from
   the difference of successive solutions) -> PyBullet POSITION_CONTROL.
4. Physics steps, the push force being applied on the pelvis at every step.
5. Measurement: whole-body CoM and its velocity from the link states.
"""

from __future__ import annotations

import time as clock
from collections import defaultdict
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.backend import FallStatus, InitialCondition
from app.pybullet_robot import PHYSICS_TIME_STEP, SimulatedRobot
from kinematics.com_plan import lipm_integrate
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming
from kinematics.whole_body_ik import WholeBodyIK, sole_pose
from planner.exceptions import ParameterError, RsgError
from planner.types import Foot, MeasuredState, PlannerOutput, Vector2, other_foot
from robots import get_robot
from robots.description import RobotDescription

INITIAL_VELOCITY_HORIZON = 0.01  # [s] finite difference used to start with a CoM velocity


class PyBulletBackend:
    """A full humanoid in PyBullet implementing :class:`app.backend.Backend`.

    Attributes:
        name: ``"pybullet"``.
        mass: Total mass measured in PyBullet [kg].
        com_height: Nominal CoM height [m] (the planner's c_z).
        control_period: Duration of one :meth:`step` [s].
        timing: The planner's step timing used by the swing foot.
    """

    name = "pybullet"

    def __init__(
        self,
        robot: str | RobotDescription = "g1",
        control_period: float = 0.01,
        timing: SwingTiming | None = None,
        com_lookahead: float = 0.0,
        com_reference_blend: float = 0.0,
        com_tracking_gains: tuple[float, float] = (0.0, 0.0),
        arrival_lead: float = 0.1,
        use_angular_momentum: bool = False,
        interpolate_targets: bool = True,
        touchdown_lead: float = 0.0,
        touchdown_depth: float = 0.0,
        plan_angular_momentum: str = "full",
    ) -> None:
        """Load the robot.

        Args:
            robot: Registry name or description of the robot.
            control_period: Control period [s], a multiple of 1 ms.
            timing: Step timing of the planner (T_DSP, T_SP, nominal step time).
            com_lookahead: Extra horizon [s] by which the IK CoM target leads the
                CoM reference (compensates the position-control lag).
            com_reference_blend: Fraction [-] of the gap between the CoM reference
                and the measured CoM state closed at each tick (0: open-loop
                reference, 1: integrate from the measurement).
            com_tracking_gains: (K_p [-], K_v [s]): the IK CoM target is the
                reference plus K_p (reference - measured position) plus
                K_v (reference - measured velocity).
            arrival_lead: Time before touchdown at which the swing foot is above
                its target [s].
            use_angular_momentum: Add the IK's centroidal angular momentum task with
                a zero target (the upper body damps the legs' angular momentum).
                The commanded hdot enters only the CoM plan (as the CMP shift);
                it is not realised by an upper-body motion.
            interpolate_targets: Interpolate the joint targets linearly over the
                physics steps of a tick (else hold the tick's final target).
            touchdown_lead: The swing foot lands this long before the planner's
                step time [s].
            touchdown_depth: Once down, the swing sole target is this far below the
                ground [m], so the foot is loaded before it becomes the stance foot.
            plan_angular_momentum: Which hdot enters the CoM plan: ``"full"`` (the
                planner's hdot, with its double-support compensation: the plan's
                effective ZMP jumps to the new foot at the step), ``"feedback"``
                (without it: the plan's ZMP moves along the moving window from the
                old foot to the new one over T_DSP, as the feet can realise) or
                ``"none"``.
        """
        self.description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
        substeps = round(control_period / PHYSICS_TIME_STEP)
        if substeps < 1 or abs(substeps * PHYSICS_TIME_STEP - control_period) > 1e-9:
            raise ParameterError("control_period", control_period, "a positive multiple of 1 ms")
        self.control_period = control_period
        self._substeps = substeps
        if not com_lookahead >= 0.0:
            raise ParameterError("com_lookahead", com_lookahead, ">= 0 s")
        if not 0.0 <= com_reference_blend <= 1.0:
            raise ParameterError("com_reference_blend", com_reference_blend, "in [0, 1]")
        self.com_lookahead = com_lookahead
        self.com_reference_blend = com_reference_blend
        self.com_tracking_gains = com_tracking_gains
        self.interpolate_targets = interpolate_targets
        if not (0.0 <= touchdown_lead <= 0.2 and 0.0 <= touchdown_depth <= 0.02):
            raise ParameterError(
                "touchdown_lead/touchdown_depth",
                (touchdown_lead, touchdown_depth),
                "lead in [0, 0.2] s and depth in [0, 0.02] m",
            )
        self.touchdown_lead = touchdown_lead
        if plan_angular_momentum not in ("full", "feedback", "none"):
            raise ParameterError(
                "plan_angular_momentum", plan_angular_momentum, "full, feedback or none"
            )
        self.plan_angular_momentum = plan_angular_momentum
        self.touchdown_depth = touchdown_depth
        self._com_reference = np.zeros(2)
        self._com_velocity_reference = np.zeros(2)
        self.timing = timing or SwingTiming()
        self.sim = SimulatedRobot(self.description)
        self.ik = WholeBodyIK(self.description, use_angular_momentum=use_angular_momentum)
        self._ik_to_sim = [self.ik.joint_names.index(name) for name in self.sim.joint_names]
        self.mass = self.sim.mass
        self.com_height = self.description.com_height
        self.swing = SwingFootTrajectory(
            self.timing, apex_height=self.description.swing_height, arrival_lead=arrival_lead
        )
        self.timers: dict[str, float] = defaultdict(float)
        self.ticks = 0
        self._stance: Foot = "left"
        self._joint_targets = np.zeros(len(self.sim.joint_names))
        self._measured: MeasuredState | None = None

    # ------------------------------------------------------------------ reset
    def reset(self, initial: InitialCondition) -> MeasuredState:
        """Stand on both feet at the initial footholds with the initial CoM state."""
        if initial.stance.foot == initial.swing.foot:
            raise ParameterError("initial.swing.foot", initial.swing.foot, "the non-stance foot")
        soles: dict[str, NDArray[np.float64]] = {
            initial.stance.foot: _ground_pose(initial.stance.position),
            initial.swing.foot: _ground_pose(initial.swing.position),
        }
        com_xy = np.asarray(initial.com_position, float)
        com_velocity = np.asarray(initial.com_velocity, float)
        base0, q0 = self._ik_reset(soles, com_xy)
        base_velocity = np.zeros(3)
        base_angular_velocity = np.zeros(3)
        joint_velocity = np.zeros_like(q0)
        if np.any(com_velocity):
            h = INITIAL_VELOCITY_HORIZON
            q1 = self.ik.solve(com_xy + h * com_velocity, soles["left"], soles["right"], "both", h)
            base1 = self.ik.robot.get_T_world_fbase()
            base_velocity = (base1[:3, 3] - base0[:3, 3]) / h
            base_angular_velocity = (
                Rotation.from_matrix(base1[:3, :3] @ base0[:3, :3].T).as_rotvec() / h
            )
            joint_velocity = (q1 - q0) / h
            self._ik_reset(soles, com_xy)
        quaternion = Rotation.from_matrix(base0[:3, :3]).as_quat()
        self.sim.set_configuration(
            base0[:3, 3],
            quaternion,
            dict(zip(self.ik.joint_names, q0, strict=True)),
            base_velocity,
            base_angular_velocity,
            dict(zip(self.ik.joint_names, joint_velocity, strict=True)),
        )
        self.sim.time = 0.0
        self._joint_targets = q0[self._ik_to_sim]
        self.sim.set_joint_targets(self._joint_targets, joint_velocity[self._ik_to_sim])
        self._stance = initial.stance.foot
        self.swing.start(np.asarray(initial.swing.position, float))
        self.timers.clear()
        self.ticks = 0
        self._measured = self._measure()
        self._com_reference = com_xy.copy()
        self._com_velocity_reference = com_velocity.copy()
        return self._measured

    def _ik_reset(
        self, soles: Mapping[str, NDArray[np.float64]], com_xy: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        q = self.ik.reset(soles["left"], soles["right"], com_xy)
        return np.asarray(self.ik.robot.get_T_world_fbase(), float).copy(), q

    # ------------------------------------------------------------------- step
    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        """Realise ``command`` for one control period with ``push_force`` [N] on the pelvis."""
        if self._measured is None:
            raise ParameterError("backend", "not reset", "reset() before step()")
        start = clock.perf_counter()
        dt = self.control_period
        stance: Foot = command.stance.foot
        swing_foot = other_foot(stance)
        if stance != self._stance:
            # The planner stepped: the old stance foot lifts off from where it stood.
            self.swing.start(np.asarray(command.previous_stance.position, float))
            self._stance = stance
        com_target = self._advance_com_reference(command)
        time_since_step = command.time_since_step + dt
        # Touchdown a little before the planner's step so the foot carries load
        # when the stance switches (measured: landing exactly at the switch leaves
        # the CoP on the old foot for ~30 ms and costs ~2 cm of DCM error).
        landing = (
            command.next_step_time - (command.time - command.time_since_step)
        ) - self.touchdown_lead
        swing_position = self.swing.update(time_since_step, command.next_step.position, dt, landing)
        swing_position[2] = max(swing_position[2] - self._press_depth(swing_position), -0.01)
        soles = {
            stance: _ground_pose(command.stance.position),
            swing_foot: sole_pose(swing_position),
        }
        support = "both" if command.double_support else stance
        planned = clock.perf_counter()
        q = self.ik.solve(com_target, soles["left"], soles["right"], support, dt)[self._ik_to_sim]
        solved = clock.perf_counter()
        previous = self._joint_targets
        velocity = (q - previous) / dt
        self._joint_targets = q
        force = np.array([push_force[0], push_force[1], 0.0], dtype=float)
        for substep in range(1, self._substeps + 1):
            if self.interpolate_targets or substep == 1:
                fraction = substep / self._substeps if self.interpolate_targets else 1.0
                self.sim.set_joint_targets(previous + fraction * (q - previous), velocity)
            self.sim.step(force)
        stepped = clock.perf_counter()
        self._measured = self._measure()
        measured_at = clock.perf_counter()
        self.timers["planning"] += planned - start
        self.timers["ik"] += solved - planned
        self.timers["physics"] += stepped - solved
        self.timers["estimation"] += measured_at - stepped
        self.ticks += 1
        return self._measured

    def _press_depth(self, swing_position: NDArray[np.float64]) -> float:
        """How far below the ground the landed swing sole is commanded [m]."""
        return self.touchdown_depth if swing_position[2] <= 1e-4 else 0.0

    def _advance_com_reference(self, command: PlannerOutput) -> NDArray[np.float64]:
        """Blend the CoM reference toward the measurement, integrate it, return the IK target."""
        measured = self._measured
        if measured is None:
            raise RsgError("the PyBullet backend must be reset before it steps")
        position_error = self._com_reference - measured.com_position
        velocity_error = self._com_velocity_reference - measured.com_velocity
        correction = (
            self.com_tracking_gains[0] * position_error
            + self.com_tracking_gains[1] * velocity_error
        )
        blend = self.com_reference_blend
        self._com_reference = self._com_reference - blend * position_error
        self._com_velocity_reference = self._com_velocity_reference - blend * velocity_error
        hdot = {
            "full": command.angular_momentum_rate,
            "feedback": command.angular_momentum_rate_feedback,
            "none": np.zeros(2),
        }[self.plan_angular_momentum]
        self._com_reference, self._com_velocity_reference = lipm_integrate(
            self._com_reference,
            self._com_velocity_reference,
            command.zmp,
            hdot,
            self.mass,
            self.com_height,
            self.control_period,
        )
        if self.com_lookahead == 0.0:
            return self._com_reference + correction
        target, _ = lipm_integrate(
            self._com_reference,
            self._com_velocity_reference,
            command.zmp,
            hdot,
            self.mass,
            self.com_height,
            self.com_lookahead,
        )
        return target + correction

    def _measure(self) -> MeasuredState:
        com, com_velocity = self.sim.com_state()
        return MeasuredState(self.sim.time, com[:2].copy(), com_velocity[:2].copy())

    # ---------------------------------------------------------------- queries
    def fall_status(self) -> FallStatus:
        """Fallen if the pelvis is low or tilted, or a non-foot body touches the ground."""
        position, quaternion = self.sim.base_pose()
        if position[2] < self.description.fall_base_height:
            return FallStatus(True, f"pelvis height {position[2]:.3f} m")
        up = Rotation.from_quat(quaternion).as_matrix()[:, 2]
        tilt = float(np.arccos(np.clip(up[2], -1.0, 1.0)))
        if tilt > self.description.fall_tilt:
            return FallStatus(True, f"pelvis tilt {np.degrees(tilt):.0f} deg")
        others = self.sim.ground_contacts() - set(self.sim.foot_links.values())
        if others:
            names = sorted(self.sim.link_name(link) for link in others)
            return FallStatus(True, f"ground contact of {', '.join(names)}")
        return FallStatus(False)

    def feet_in_contact(self) -> set[str]:
        """Feet touching the ground."""
        return self.sim.feet_in_contact()

    def robot_configuration(self) -> tuple[NDArray[np.float64], NDArray[np.float64], dict]:
        """URDF base position [m], quaternion (x, y, z, w) and joint angles [rad]."""
        position, quaternion = self.sim.base_pose()
        return position, quaternion, self.sim.joint_angles()

    def sole_positions(self) -> dict[str, NDArray[np.float64]]:
        """Measured sole origin of each foot in the world [m], shape (3,)."""
        return {foot: self.sim.sole_position(foot) for foot in ("left", "right")}

    def timing_report(self) -> dict[str, float]:
        """Mean wall time per tick of each part [s] (planning, ik, physics, estimation)."""
        ticks = max(self.ticks, 1)
        report = {key: value / ticks for key, value in self.timers.items()}
        report["total"] = sum(report.values())
        return report

    def close(self) -> None:
        """Release the PyBullet client."""
        self.sim.close()


def _ground_pose(position_xy: NDArray[np.float64]) -> NDArray[np.float64]:
    """Flat sole pose on the ground at ``position_xy`` [m]."""
    return sole_pose(np.array([position_xy[0], position_xy[1], 0.0]))
