"""The whole-body controller: one control tick from measurement to joint command.

    measure -> (plan: the RSG, outside) -> stabilize -> swing foot -> IK -> actuate

Development version; see docs/full-robot.md for the design and references.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from app.pybullet_com_plan import momentum_aware_pivot
from kinematics.robot_model import RobotModel
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming
from kinematics.upper_body import UpperBodyFlywheel
from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, sole_pose
from planner.hybrid_lipm import H_MATRIX, integrate_lipm
from planner.parameters import GRAVITY, LipmModel
from planner.types import Foot, MeasuredState, PlannerOutput, other_foot
from robots.description import RobotDescription

from ..lowlevel import JointCommand, RobotMeasurement
from .estimator import RobotState, StateEstimator
from .wrench_distribution import ContactLimits, FootContact, distribute_wrench

UNITREE_STIFFNESS = {"hip": 150.0, "knee": 300.0, "ankle": 40.0, "waist_yaw": 60.0, "waist": 40.0, "shoulder": 40.0}
UNITREE_DAMPING = {"hip": 2.0, "knee": 4.0, "ankle": 2.0, "waist_yaw": 1.0, "waist": 1.0, "shoulder": 1.0}


def _group(name: str) -> str:
    for key in ("waist_yaw", "hip", "knee", "ankle", "waist", "shoulder"):
        if key in name:
            return key
    raise KeyError(name)


@dataclass
class ControllerOptions:
    stiffness_scale: float = 5.0
    damping_scale: float = 10.0
    ankle_stiffness_scale: float = 1.0
    ankle_damping_scale: float = 1.0
    contact_fraction: float = 0.05
    acceleration_limit: float = 50.0
    acceleration_filter: float = 0.02
    reanchor: bool = True
    touchdown_switch: bool = False
    touchdown_window: float = 0.08
    touchdown_fraction: float = 0.3
    estimator: str = "truth"
    friction: float = 0.7
    verbose: bool = False
    stance_from_measured: bool = False
    landing_depth: float = 0.0
    load_rate: float = 0.0
    press_time: float = 0.02
    touchdown_speed: float = 0.0
    landing_admittance: float = 0.0
    touch_force: float = 0.05
    yield_time: float = 0.05
    settle_from_swing: bool = False
    compensate_touch: bool = False
    settle: bool = True
    gain_rule: bool = False
    flywheel_return_time: float = 0.5
    flywheel_momentum: float = 2.0
    flywheel_cancel: float = 0.5
    flywheel_offset: float = 0.4
    joint_saturation: float = 0.1
    ankle_saturation: float = 1.0
    damping_time: float = 0.025
    ankle_damping_time: float = 0.05
    landing_window: float = 0.1


class WholeBodyController:
    """Torque-level controller of a biped under the RSG."""

    def __init__(
        self,
        description: RobotDescription,
        timing: SwingTiming,
        control_period: float,
        options: ControllerOptions | None = None,
        upper_body_momentum: float = 2.0,
    ) -> None:
        self.description = description
        self.options = options or ControllerOptions()
        self.period = control_period
        self.model = RobotModel(description)
        self.mass = self.model.mass
        self.estimator = StateEstimator(self.model, self.options.estimator)
        if not description.upper_body_joints:
            upper_body_momentum = 0.0
        self.ik = WholeBodyIK(description, upper_body=upper_body_momentum > 0.0)
        self._ik_to_model = np.array([self.ik.joint_names.index(n) for n in self.model.joint_names])
        self.flywheel: UpperBodyFlywheel | None = None
        if upper_body_momentum > 0.0:
            self.flywheel = UpperBodyFlywheel(
                self.ik.robot,
                self.ik.upper_body_joints,
                self.ik.upper_body_posture,
                return_time=self.options.flywheel_return_time,
                max_momentum=self.options.flywheel_momentum,
                cancel=self.options.flywheel_cancel,
                max_offset=self.options.flywheel_offset,
            )
        self.timing = timing
        self.swing = SwingFootTrajectory(
            timing,
            apex_height=description.swing_height,
            arrival_lead=0.1,
            touchdown_speed=self.options.touchdown_speed,
            max_acceleration=20.0,
            descent_slope=0.5,
            land_on_time=True,
        )
        self.lipm = LipmModel(mass=self.mass, com_height=description.com_height)
        self.limits = ContactLimits(description.sole, friction=self.options.friction)
        names = self.model.joint_names
        o = self.options
        if o.gain_rule:
            effort = self.model.effort_limits
            ankle = np.array(["ankle" in n or n.endswith(("_5_joint", "_6_joint")) and n.startswith("leg") for n in names])
            saturation = np.where(ankle, o.ankle_saturation, o.joint_saturation)
            self.stiffness = effort / saturation
            self.damping = self.stiffness * np.where(ankle, o.ankle_damping_time, o.damping_time)
        else:
          self.stiffness = np.array(
            [UNITREE_STIFFNESS[_group(n)] * (o.ankle_stiffness_scale if "ankle" in n else o.stiffness_scale) for n in names]
        )
          self.damping = np.array(
            [UNITREE_DAMPING[_group(n)] * (o.ankle_damping_scale if "ankle" in n else o.damping_scale) for n in names]
        )
        self.ankle_height = -float(description.sole_offset[2])
        self._reset_state()

    def _reset_state(self) -> None:
        self._stance: Foot = "left"
        self._previous_q: NDArray[np.float64] | None = None
        self._targets: list[NDArray[np.float64]] = []
        self._acceleration = np.zeros(len(self.model.joint_names))
        self._ik_momentum: NDArray[np.float64] | None = None
        self._ik_momentum_rate = np.zeros(2)
        self._stance_yaw = 0.0
        self.state: RobotState | None = None
        self.measurement: RobotMeasurement | None = None
        self.ik_failure: str | None = None
        self.planned_cop = np.zeros(2)
        self._report_touchdown: NDArray[np.float64] | None = None
        self._normal_forces: dict[str, float] = {}
        self._yield = 0.0
        self._last_swing_height = 0.0

    # ------------------------------------------------------------------ reset
    def reset(self, stance_sole: NDArray, swing_sole: NDArray, stance: Foot, com_xy: NDArray) -> NDArray:
        """Reset the IK to stand on the soles (4x4 poses) with the CoM at ``com_xy``;
        returns the IK joint angles in the model's joint order."""
        self._reset_state()
        self.estimator.reset()
        self._stance = stance
        soles = {stance: stance_sole, other_foot(stance): swing_sole}
        q = self.ik.reset(soles["left"], soles["right"], com_xy)
        self.swing.start(swing_sole[:2, 3])
        if self.flywheel is not None:
            self.flywheel.reset()
        target = q[self._ik_to_model]
        self._targets = [target, target]
        self.planned_cop = np.asarray(com_xy, float).copy()
        return target

    # ------------------------------------------------------------------- tick
    def tick(self, measurement: RobotMeasurement, command: PlannerOutput) -> JointCommand:
        dt = self.period
        o = self.options
        stance: Foot = command.stance.foot
        swing_foot = other_foot(stance)
        # measure (the estimate of this measurement was made by observe())
        if self.state is None or self.state.time != measurement.time:
            self.observe(measurement, stance)
        state = self.state
        self.measurement = measurement
        model = self.model
        if stance != self._stance:
            self._yield = 0.0
            self.swing.start(model.sole_frame(swing_foot)[0][:2])
            _, rotation = model.sole_frame(stance)
            self._stance_yaw = float(np.arctan2(rotation[1, 0], rotation[0, 0]))
            self._stance = stance
        # stabilize: the CoP and net force that realise the planner's pivot
        hdot = np.asarray(command.angular_momentum_rate, float)
        zmp = np.asarray(command.zmp, float)
        pivot = zmp - H_MATRIX @ hdot / (self.mass * GRAVITY)
        cop, _ = momentum_aware_pivot(
            zmp, hdot, self._ik_momentum_rate, self.mass, command, self.description.sole, 0.0
        )
        self.planned_cop = cop
        com = state.com[:2]
        com_target, _ = integrate_lipm(
            self.lipm, com, state.com_velocity[:2], pivot, np.zeros(2), np.zeros(2), dt
        )
        force = np.array(
            [*(self.mass * self.lipm.omega**2 * (com - pivot)), self.mass * GRAVITY]
        )
        # swing foot
        time_since_step = command.time_since_step + dt
        landing = command.next_step_time - (command.time - command.time_since_step)
        swing_position = self.swing.update(
            time_since_step, np.asarray(command.next_step.position, float), dt, landing
        )
        stance_position = model.sole_frame(stance)[0] if o.stance_from_measured else np.array([*command.stance.position, 0.0])
        if o.landing_depth > 0.0 and not command.double_support and o.landing_window > 0.0:
            # Aim below the ground at the landing time: contact comes by then, not after.
            lead = landing - time_since_step
            ramp = float(np.clip(1.0 - lead / o.landing_window, 0.0, 1.0))
            swing_position = swing_position.copy()
            swing_position[2] -= o.landing_depth * ramp
        if o.landing_admittance > 0.0 and not command.double_support:
            # Landing compliance: a touching swing sole yields to what it carries above
            # the touch force, and comes back down when unloaded.
            excess = measurement.normal_force(swing_foot) - o.touch_force * self.mass * GRAVITY
            self._yield += dt * (o.landing_admittance * excess - self._yield / o.yield_time)
            self._yield = min(max(self._yield, 0.0), o.landing_depth + 0.02)
            swing_position = swing_position.copy()
            swing_position[2] += self._yield
        if not command.double_support:
            self._last_swing_height = float(swing_position[2])
        settle = 0.0
        if o.settle_from_swing and command.double_support:
            settle = self._last_swing_height * max(0.0, 1.0 - time_since_step / self.timing.double_support)
        elif o.landing_depth > 0.0 and command.double_support and o.settle:
            if o.landing_window > 0.0:
                # The new stance sole comes up from the landing depth over the double support.
                settle = -o.landing_depth * max(0.0, 1.0 - time_since_step / self.timing.double_support)
            else:
                # The new stance sole is pressed down, then comes back, over the double support.
                rise = min(time_since_step / o.press_time, 1.0)
                fall = max(0.0, 1.0 - (time_since_step - o.press_time) / (self.timing.double_support - o.press_time))
                settle = -o.landing_depth * min(rise, fall)
        soles = {
            stance: sole_pose(np.array([stance_position[0], stance_position[1], settle]), self._stance_yaw),
            swing_foot: sole_pose(swing_position),
        }
        # IK
        support = "both" if command.double_support else stance
        offsets = None
        if self.flywheel is not None:
            rest = self.ik.angular_momentum[:2] - self.flywheel.momentum
            offsets = self.flywheel.follow_rate(command.angular_momentum_rate_feedback, dt, rest)
        try:
            q_ik = self.ik.solve(com_target, soles["left"], soles["right"], support, dt, upper_body_offsets=offsets)[self._ik_to_model]
        except IkInfeasibleError as error:
            self.ik_failure = f"whole-body IK infeasible at t = {command.time:.2f} s ({error.reason})"
            q_ik = self._targets[0]
        momentum = self.ik.angular_momentum[:2].copy()
        previous = momentum if self._ik_momentum is None else self._ik_momentum
        self._ik_momentum = momentum
        self._ik_momentum_rate += min(dt / 0.05, 1.0) * ((momentum - previous) / dt - self._ik_momentum_rate)
        velocity = (q_ik - self._targets[0]) / dt
        raw = (q_ik - 2.0 * self._targets[0] + self._targets[1]) / dt**2
        raw = np.clip(raw, -o.acceleration_limit, o.acceleration_limit)
        self._acceleration += min(dt / o.acceleration_filter, 1.0) * (raw - self._acceleration)
        self._targets = [q_ik, self._targets[0]]
        # contact wrenches
        planned = ["left", "right"] if command.double_support else [stance]
        threshold = o.contact_fraction * self.mass * GRAVITY
        touching = [f for f in ("left", "right") if measurement.normal_force(f) > threshold]
        # The planned supports that touch the ground; else the feet that do (a late
        # landing keeps the weight on the old foot); in the air, the stance foot.
        feet = [f for f in planned if f in touching] or touching or [stance]
        contacts = []
        change = o.load_rate * self.mass * GRAVITY * dt  # [N] per tick
        for foot in feet:
            position, rotation = model.sole_frame(foot)
            previous_force = self._normal_forces.get(foot, 0.0)
            bounds = (max(previous_force - change, 0.0), previous_force + change) if o.load_rate > 0 and len(feet) > 1 else (0.0, np.inf)
            contacts.append(
                FootContact(
                    np.array([position[0], position[1], 0.0]),
                    float(np.arctan2(rotation[1, 0], rotation[0, 0])),
                    self.ankle_height,
                    *bounds,
                )
            )
        if o.compensate_touch and not command.double_support and swing_foot not in feet:
            reading = measurement.foot_forces.get(swing_foot)
            if reading is not None and reading.normal_force > 1.0:
                # A touching swing sole is not a planned support: its measured force is
                # known, and the stance foot realises the rest about the desired CoP.
                share = min(reading.normal_force, 0.9 * force[2])
                cop = (cop * force[2] - reading.cop * share) / (force[2] - share)
                force = force - np.array([0.0, 0.0, share])
        wrenches = distribute_wrench(contacts, force, cop, self.limits)
        self._normal_forces = {foot: float(w[2]) for foot, w in zip(feet, wrenches, strict=True)}
        # inverse dynamics feed-forward
        acceleration = np.zeros(model.nv)
        acceleration[6:] = self._acceleration
        torque = model.inverse_dynamics(acceleration)
        self.expected_contact_force = np.zeros(model.nv)
        for foot, contact, wrench in zip(feet, contacts, wrenches, strict=True):
            self.expected_contact_force += model.wrench_generalized_force(
                foot, contact.sole_point, wrench
            )
        torque -= self.expected_contact_force
        # planner's measurement: re-anchor on the stance sole in single support
        self._stance_sole_report = None
        if o.reanchor and not command.double_support and measurement.normal_force(stance) > threshold:
            self._stance_sole_report = model.sole_frame(stance)[0][:2].copy()
        self._report_touchdown = None
        if o.touchdown_switch and not command.double_support:
            if 0.0 < command.next_step_time - measurement.time <= o.touchdown_window and (
                measurement.normal_force(swing_foot) > o.touchdown_fraction * self.mass * GRAVITY
            ):
                self._report_touchdown = model.sole_frame(swing_foot)[0][:2].copy()
        if o.verbose:
            forces = ",".join(f"{k[0]}{v.normal_force:.0f}" for k, v in measurement.foot_forces.items())
            print(f"{measurement.time:.2f} {'DS' if command.double_support else 'SS'} {stance[0]} feet={''.join(f[0] for f in feet)} cop=({cop[0]:.3f},{cop[1]:.3f}) fz={forces} e=({command.dcm_error[0]*100:+.1f},{command.dcm_error[1]*100:+.1f}) sw={np.round(model.sole_frame(swing_foot)[0],3)} swt={np.round(swing_position,3)}")
        return JointCommand(q_ik, velocity, self.stiffness, self.damping, torque[6:])

    def observe(self, measurement: RobotMeasurement, stance: Foot) -> MeasuredState:
        """Estimate the state from ``measurement``; return what the planner reads."""
        self.state = self.estimator.update(measurement, stance)
        return self.planner_state()

    def planner_state(self) -> MeasuredState:
        """What the RSG reads: CoM, its velocity, the stance sole, a touchdown."""
        assert self.state is not None
        return MeasuredState(
            self.state.time,
            self.state.com[:2].copy(),
            self.state.com_velocity[:2].copy(),
            self._report_touchdown,
            self._stance_sole_report,
        )
