"""The whole-body controller: one control tick from the measurement to the joint command.

    measure -> (plan: the RSG, outside) -> swing foot -> stabilize -> IK -> actuate

* measure: the state estimate (:mod:`.estimator`) from what the robot senses, and each
  foot's load: its force sensor's where it has one, else the joint torques' through a
  momentum observer (:mod:`.contact_observer`);
* swing foot: the re-targetable swing trajectory and the landing rules (:mod:`.landing`);
  the swing sole's IK target is corrected for the real body's tilt on its stance ankle,
  and the new stance sole's is continuous at a step
  (:meth:`WholeBodyController._ik_sole_offsets`);
* stabilize: the pivot the planner commands, the CoP and net force that realise it and
  hold the CoM at the height the IK will be asked for (:mod:`.centroidal`), shared among
  the feet on the ground, each foot's CoP on its sole at the force it carries
  (:mod:`.wrench_distribution`);
* IK: placo's whole-body IK, with the upper body as a flywheel for hdot
  (:mod:`kinematics.upper_body`);
* actuate: per joint a target, stiffness, damping and the feed-forward torque from the
  floating-base inverse dynamics of the planned motion with the planned contact wrenches.

The design, loop by loop, with its references and measurements: docs/full-robot.md.
"""

from __future__ import annotations

import math

import numpy as np
from numpy.typing import NDArray

from app.lowlevel import JointCommand, RobotMeasurement
from app.stabilizer import centroidal
from app.stabilizer.config import StabilizerConfig
from app.stabilizer.contact_observer import ContactForceObserver
from app.stabilizer.estimator import RobotState, StateEstimator
from app.stabilizer.landing import Landing
from app.stabilizer.lipm_filter import LipmFilter
from app.stabilizer.wrench_distribution import (
    ContactLimits,
    FootContact,
    WrenchDistributionError,
    distribute_wrench,
    within_sole_at_force,
)
from kinematics.robot_model import RobotModel, yaw_of
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming, swing_yaw
from kinematics.upper_body import UpperBodyFlywheel
from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, leg_joints, sole_pose
from planner.exceptions import ParameterError
from planner.hybrid_lipm import integrate_lipm
from planner.parameters import GRAVITY, LipmModel
from planner.types import Foot, MeasuredState, PlannerOutput, other_foot
from robots.description import RobotDescription

CONTACT_LOAD = 0.05  # [-, of m g] a foot carrying more is on the ground
# [m] a planned support that has touched down stays a contact while its sole is this close
# to the ground, its load dipping or not (docs/notes/2026-12-06-landed-contact.md)
LANDED_HEIGHT = 0.01
ACCELERATION_FILTER = 0.02  # [s] low-pass of the IK's joint accelerations (not the swing leg's)
ACCELERATION_LIMIT = 50.0  # [rad/s^2] bound on the feed-forward joint accelerations (idem)
MOMENTUM_FILTER = 0.05  # [s] low-pass of the IK motion's angular momentum rate
SWING_ACCELERATION = 20.0  # [m/s^2] bound on the swing sole's re-planned approach
SWING_SPEED = 3.0  # [m/s] bound on the swing sole's speed: a catching step's foothold moves
# up to 0.6 m with 0.2-0.3 s left, which at 2 m/s lands late (docs/notes/2026-12-06-swing-speed.md)
SWING_CORRECTION_TIME = 0.05  # [s] low-pass of the swing sole's measured offset (impacts)
SWING_DESCENT_SLOPE = 0.5  # [-] the swing sole stays this high per metre still to go
# [rad/s] the planned speed over which the friction compensation's sign turns
FRICTION_SPEED = 0.05
# The CoM filter's noise (:mod:`.lipm_filter`): the pendulum's error as acceleration
# [m/s^2] (a 1 cm CoP error is 0.13 m/s^2; angular momentum and pushes more), the
# kinematic CoM's error [m] and its velocity's [m/s] (joint velocity noise, impacts).
LIPM_PROCESS_NOISE = 1.0
COM_POSITION_NOISE = 0.003
COM_VELOCITY_NOISE = 0.05
# [m/sqrt(s)] the CoM offset's random walk: a torso's CoM or mass off the model is learnt
# in seconds, while a push's 0.1 s moves it about 1 cm (tests/test_lipm_filter.py)
COM_OFFSET_DRIFT = 0.005
# [1/s] the contact observer's low-pass: a touchdown seen within about 1/K = 20 ms
OBSERVER_BANDWIDTH = 50.0


class WholeBodyController:
    """Joint commands that make a biped follow the RSG's commands.

    Args:
        description: The robot.
        timing: The planner's step timing (for the swing foot).
        control_period: [s].
        config: Options.

    Attributes:
        model: The robot's rigid-body model, holding the current state estimate.
        expected_contact_force: J^T f of the contact wrenches planned at the last
            tick [N, N m] (what the feed-forward torques are computed for).
        planned_cop: The CoP the feet were asked for at the last tick [m].
        planned_forces: Foot -> normal force [N] of the wrench it was given at the last
            tick (the feet given none are absent).
        sole_targets: Foot -> where the IK was asked to put its sole at the last tick
            [m], world, shape (3,).
        failure: Why the controller could not command the joints (the IK or the
            wrench distribution had no solution), once it could not.
    """

    def __init__(
        self,
        description: RobotDescription,
        timing: SwingTiming,
        control_period: float,
        config: StabilizerConfig,
    ) -> None:
        self.description = description
        self.config = config
        self.period = control_period
        self.model = RobotModel(description)
        self.mass = self.model.mass
        self.lipm = LipmModel(mass=self.mass, com_height=description.pendulum_height)
        self.estimator = StateEstimator(self.model, np.asarray(description.imu_position))
        flywheel = config.flywheel_momentum > 0.0 and bool(description.upper_body_joints)
        self.ik = WholeBodyIK(description, upper_body=flywheel)
        self._ik_order = np.array([self.ik.joint_names.index(n) for n in self.model.joint_names])
        legs = leg_joints(self.ik.robot.model)
        self._legs = {foot: self.model.index_of(legs[foot]) for foot in ("left", "right")}
        self.com_filter = LipmFilter(
            self.lipm.omega,
            LIPM_PROCESS_NOISE,
            COM_POSITION_NOISE,
            COM_VELOCITY_NOISE,
            COM_OFFSET_DRIFT,
        )
        self.observer = None
        if not description.foot_force_sensors:
            self.observer = ContactForceObserver(self.model, self._legs, OBSERVER_BANDWIDTH)
        self.flywheel = None
        if flywheel:
            self.flywheel = UpperBodyFlywheel(
                self.ik.robot,
                self.ik.upper_body_joints,
                self.ik.upper_body_posture,
                return_time=config.flywheel_return_time,
                max_momentum=config.flywheel_momentum,
                cancel=config.flywheel_cancel,
            )
        self.swing = SwingFootTrajectory(
            timing,
            apex_height=description.swing_height,
            max_speed=SWING_SPEED,
            max_acceleration=SWING_ACCELERATION,
            descent_slope=SWING_DESCENT_SLOPE,
            land_on_time=True,
        )
        self.landing = Landing(config.landing_depth, timing.double_support)
        self.limits = ContactLimits(
            description.sole,
            friction=config.friction,
            ankle_torque=self.model.ankle_effort_limits(),
        )
        self.stiffness, self.damping = joint_impedance(self.model, description)
        motors = [description.motors.get(name) for name in self.model.joint_names]
        self._static_friction = np.array([0.0 if m is None else m.static_friction for m in motors])
        self._viscous_friction = np.array(
            [0.0 if m is None else m.viscous_friction for m in motors]
        )
        self._ankle_height = -float(description.sole_offset[2])
        self.expected_contact_force = np.zeros(self.model.nv)
        self.state: RobotState | None = None
        self._reset_state(np.zeros(2))

    @property
    def timing(self) -> SwingTiming:
        """The planner's step timing used by the swing foot."""
        return self.swing.timing

    def _reset_state(self, com_xy: NDArray[np.float64]) -> None:
        self._stance: Foot = "left"
        self._targets: tuple[NDArray[np.float64], NDArray[np.float64]] = (
            np.zeros(len(self.model.joint_names)),
        ) * 2
        self._acceleration = np.zeros(len(self.model.joint_names))
        self._ik_momentum: NDArray[np.float64] | None = None
        self._motion_momentum_rate = np.zeros(2)
        self._stance_yaw = 0.0  # [rad] the stance sole's yaw when it landed
        self._step_time: float | None = None  # [s] the planner's last step (None: none yet)
        self._swing_error = np.zeros(2)  # [m] see _swing_correction
        self._landing_offset = np.zeros(2)  # [m] see _ik_sole_offsets
        self._ik_soles: dict[Foot, NDArray[np.float64]] = {}  # [m] x, y the IK was given
        self._swing_start_yaw = 0.0  # [rad] the swing sole's yaw when it lifted off
        self.planned_cop = np.array(com_xy, dtype=float)
        self.planned_forces: dict[Foot, float] = {}
        self.sole_targets: dict[Foot, NDArray[np.float64]] = {
            foot: np.full(3, np.nan) for foot in ("left", "right")
        }
        self.failure: str | None = None
        self._contacts: list[FootContact] = []
        self._landed: set[Foot] = {"left", "right"}  # supports that touched down since planned
        self.loads: dict[str, float] = {}  # [N] each foot's estimated normal force
        self._start: dict[Foot, NDArray[np.float64]] | None = None  # soles at reset [m]
        self._last_reading: float | None = None  # [s] the time of the last measurement
        self._pivot = np.array(com_xy, dtype=float)  # [m] the pivot of the last tick

    def reset(
        self,
        soles: dict[Foot, NDArray[np.float64]],
        stance: Foot,
        com_xy: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """Stand on ``soles`` (4x4 poses) with the CoM above ``com_xy`` [m].

        Returns:
            The IK's joint angles [rad] in the model's joint order.
        """
        self._reset_state(np.asarray(com_xy, float))
        self._start = {foot: np.asarray(pose[:3, 3], float) for foot, pose in soles.items()}
        self.com_filter.reset()
        self._stance = stance
        q = self.ik.reset(soles["left"], soles["right"], com_xy)[self._ik_order]
        self.swing.start(soles[other_foot(stance)][:2, 3])
        self.landing.start_swing()
        if self.flywheel is not None:
            self.flywheel.reset()
        self._targets = (q, q)
        return q

    # ------------------------------------------------------------------- tick
    def tick(self, measurement: RobotMeasurement, command: PlannerOutput) -> JointCommand:
        """One control tick: the joint command for ``command`` given ``measurement``."""
        dt = self.period
        stance: Foot = command.stance.foot
        swing: Foot = other_foot(stance)
        state = self._estimate(measurement, command)  # measure
        if stance != self._stance:  # the planner stepped: the old stance foot lifts off
            self._start_swing(command, stance, swing)
            self._step_time = command.time
        # swing foot
        soles = self._sole_targets(command, stance, swing)
        self.sole_targets = {foot: pose[:3, 3].copy() for foot, pose in soles.items()}
        # stabilize: the net force holds the IK's CoM height
        pivot = centroidal.pivot(command.zmp, command.angular_momentum_rate, self.mass)
        self._pivot = pivot
        lift = centroidal.height_acceleration(
            self.config.height_frequency,
            self.ik.com_z_target(soles["left"], soles["right"]) - state.com[2],
            state.com_velocity[2],
        )
        # the pendulum's CoM is the kinematic one plus the filter's offset
        com_offset = self.com_filter.offset
        force = centroidal.contact_force(self.lipm, state.com[:2] + com_offset, pivot, lift)
        sway = centroidal.sway_rate(force, self.description.rotational_height)
        self.planned_cop = centroidal.centre_of_pressure(
            pivot,
            self._motion_momentum_rate - sway,
            self.mass,
            np.asarray(command.stance.position, float),
            self.description.sole,
            command.double_support,
        )
        com_target, _ = integrate_lipm(
            self.lipm,
            state.com[:2] + com_offset,
            state.com_velocity[:2],
            pivot,
            np.zeros(2),
            np.zeros(2),
            dt,
        )
        com_target = com_target - com_offset
        # IK: the soles' targets as the IK is to reach them (the real body's tilt, a step)
        for foot, offset in self._ik_sole_offsets(command, stance, swing).items():
            soles[foot] = soles[foot].copy()
            soles[foot][:2, 3] += offset
        self._ik_soles = {foot: pose[:2, 3].copy() for foot, pose in soles.items()}
        q = self._solve_ik(command, com_target, soles)
        # actuate: feed-forward torques for the contact wrenches the feet are given
        feet, wrenches = self._contact_wrenches(command, force)
        velocity = (q - self._targets[0]) / dt
        torque = self._feedforward(feet, wrenches) + self._friction(velocity)
        self._targets = (q, self._targets[0])
        stiffness, damping = self._impedance(command, stance, swing)
        return JointCommand(q, velocity, stiffness, damping, torque)

    # ----------------------------------------------------------- the stages
    def _impedance(
        self, command: PlannerOutput, stance: Foot, swing: Foot
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """The joints' stiffness and damping, the legs' lowered around a touchdown
        (``StabilizerConfig.landing_compliance``): the swing leg's before its planned
        landing, the new stance leg's after a step this controller saw."""
        share = self.config.landing_compliance
        if share >= 1.0:
            return self.stiffness, self.damping
        time_since_step, landing_time = self._swing_clock(command)
        since_landing = math.inf
        if self._step_time is not None:
            since_landing = command.time - self._step_time + self.period
        landing, landed = self.landing.compliant(landing_time - time_since_step, since_landing)
        scale = np.ones_like(self.stiffness)
        if landing and not command.double_support:
            scale[self._legs[swing]] = share
        if landed:
            scale[self._legs[stance]] = share
        return self.stiffness * scale, self.damping * scale

    def _swing_clock(self, command: PlannerOutput) -> tuple[float, float]:
        """Time since the step [s] at the end of this tick (the command holds over it), and
        the planned landing time [s] on the same clock."""
        landing_time = command.next_step_time - (command.time - command.time_since_step)
        return command.time_since_step + self.period, landing_time

    def _estimate(self, measurement: RobotMeasurement, command: PlannerOutput) -> RobotState:
        """The estimate of ``measurement`` (made by :meth:`observe` unless it is new)."""
        if self.state is None or self.state.time != measurement.time:
            self.observe(measurement, command.stance.foot, command.double_support)
        assert self.state is not None  # set by observe()
        return self.state

    def _start_swing(self, command: PlannerOutput, stance: Foot, swing: Foot) -> None:
        self._swing_start_yaw = self._stance_yaw  # the old stance sole's target
        self._swing_error = np.zeros(2)
        landed = self._ik_soles.get(stance)
        foothold = np.asarray(command.stance.position, float)
        self._landing_offset = np.zeros(2) if landed is None else landed - foothold
        # from where the IK had the old stance sole (its foothold), which it stands on
        # through the double support: a target moved to the measured sole (up to 2 cm off
        # its foothold after a slip) is a step the IK's stiffest task takes in one tick
        previous = self._ik_soles.get(swing)
        self.swing.start(self.model.sole_frame(swing)[0][:2] if previous is None else previous)
        self.landing.start_swing()
        _, rotation = self.model.sole_frame(stance)
        self._stance_yaw = yaw_of(rotation)
        self._stance = stance

    def _sole_targets(
        self, command: PlannerOutput, stance: Foot, swing: Foot
    ) -> dict[Foot, NDArray[np.float64]]:
        """4x4 targets of both soles: the stance sole on the planner's foothold, the
        swing sole on its trajectory to the announced step, with the landing rules, and
        turning from the yaw it stood at to the planner's heading (world x) over the swing."""
        dt = self.period
        time_since_step, landing_time = self._swing_clock(command)
        position = self.swing.update(
            time_since_step, np.asarray(command.next_step.position, float), dt, landing_time
        )
        stance_height = 0.0
        if command.double_support:
            stance_height = self.landing.stance_height(time_since_step)
        else:
            position[2] = self.landing.swing_height(
                position[2], landing_time - time_since_step, time_since_step
            )
        foothold = np.array([*command.stance.position, stance_height])
        yaw = swing_yaw(
            time_since_step,
            self.swing.timing.double_support,
            landing_time,
            self._swing_start_yaw,
            0.0,
        )
        return {stance: sole_pose(foothold, self._stance_yaw), swing: sole_pose(position, yaw)}

    def _ik_sole_offsets(
        self, command: PlannerOutput, stance: Foot, swing: Foot
    ) -> dict[Foot, NDArray[np.float64]]:
        """How far [m] (x, y) the IK's sole targets are from the world's.

        In single support, the swing sole's: minus :meth:`_swing_correction`, so that the
        real sole lands where the IK puts it relative to the stance sole. In the double
        support after a step, the new stance sole's: it starts where the IK's swing sole
        was sent at the step (the correction, and where its trajectory had got to when it
        touched down) and reaches its foothold by the end of the double support, as its
        height does (:class:`app.stabilizer.landing.Landing`). From the step on the IK
        stands on it, and a target that jumped to the foothold in one tick (up to 13 cm
        after an early touchdown) is a jump of the legs' joints
        (docs/notes/2026-12-07-ik-at-the-legs-reach.md).
        """
        if command.double_support:
            settling = self.landing.settling(command.time_since_step + self.period)
            return {stance: self._landing_offset * settling}
        return {swing: -self._swing_correction(command, stance, swing)}

    def _swing_correction(
        self, command: PlannerOutput, stance: Foot, swing: Foot
    ) -> NDArray[np.float64]:
        """How far [m] (x, y) the swing sole's IK target is moved in single support: the
        low-passed offset, relative to the measured stance sole, of the real swing sole
        with the swing leg at the IK's angles (the body's tilt on its stance ankle, which
        the IK's body does not have; the swing leg's own lag is the feed-forward's) from
        the IK's, less the part that lengthens the step (a body leaning into a push carries
        its swing sole further that way, which the planner's step does not include and the
        recovery needs; docs/notes/2026-12-07-swing-sole-on-a-tilted-body.md).
        """
        q = self.model.q.copy()
        leg = self._legs[swing]
        q[7 + leg] = self._targets[0][leg]
        soles = self.model.sole_positions_at(q)
        real = soles[swing][:2] - soles[stance][:2]
        ik = self.ik.sole_world(swing)[:2, 3] - self.ik.sole_world(stance)[:2, 3]
        error = real - ik
        step = np.asarray(command.next_step.position, float) - np.asarray(
            command.stance.position, float
        )
        length = float(np.linalg.norm(step))
        if length > 1e-6:
            along = float(error @ step) / length
            error = error - max(along, 0.0) * step / length
        gain = min(self.period / SWING_CORRECTION_TIME, 1.0)
        self._swing_error = self._swing_error + gain * (error - self._swing_error)
        return self._swing_error

    def _solve_ik(
        self,
        command: PlannerOutput,
        com_target: NDArray[np.float64],
        soles: dict[Foot, NDArray[np.float64]],
    ) -> NDArray[np.float64]:
        """Joint targets [rad]; the IK motion's angular momentum rate is kept for the CoP."""
        dt = self.period
        support = "both" if command.double_support else command.stance.foot
        offsets = None
        if self.flywheel is not None:
            rest = self.ik.angular_momentum - self.flywheel.momentum  # x, y, z [N m s]
            offsets = self.flywheel.follow_rate(command.angular_momentum_rate_feedback, dt, rest)
        try:
            q = self.ik.solve(
                com_target, soles["left"], soles["right"], support, dt, upper_body_offsets=offsets
            )[self._ik_order]
        except IkInfeasibleError as error:
            # Not seen since the IK's tasks are soft: hold the last targets, report a fall.
            self.failure = f"whole-body IK infeasible at t = {command.time:.2f} s ({error.reason})"
            q = self._targets[0]
        momentum = self.ik.angular_momentum[:2].copy()
        previous = momentum if self._ik_momentum is None else self._ik_momentum
        self._ik_momentum = momentum
        self._motion_momentum_rate += min(dt / MOMENTUM_FILTER, 1.0) * (
            (momentum - previous) / dt - self._motion_momentum_rate
        )
        raw = (q - 2.0 * self._targets[0] + self._targets[1]) / dt**2
        gain = np.full(len(q), min(dt / ACCELERATION_FILTER, 1.0))
        limit = np.full(len(q), ACCELERATION_LIMIT)
        if not command.double_support:
            # The swing leg's targets follow its planned trajectory: its accelerations are
            # the plan's, and low-passed they come late and the sole overshoots its target.
            swing = self._legs[other_foot(command.stance.foot)]
            gain[swing], limit[swing] = 1.0, np.inf
        self._acceleration += gain * (np.clip(raw, -limit, limit) - self._acceleration)
        return q

    def _contact_wrenches(
        self, command: PlannerOutput, force: NDArray[np.float64]
    ) -> tuple[list[Foot], list[NDArray[np.float64]]]:
        """The planned supports on the ground (else the feet that touch it; in the air,
        the stance foot) and the wrench each is given.

        A planned support is on the ground while it carries load or, once it has touched
        down, while its sole is within ``LANDED_HEIGHT`` of the ground: a new stance foot
        whose load dips after its touchdown (a bounce, or a CoM far from it after a
        crossing step) keeps its wrench, so its leg's feed-forward presses it down."""
        threshold = CONTACT_LOAD * self.mass * GRAVITY
        planned: list[Foot] = ["left", "right"] if command.double_support else [command.stance.foot]
        touching: list[Foot] = [f for f in ("left", "right") if self.load(f) > threshold]
        self._landed.intersection_update(planned)  # a swinging foot has to touch down again
        self._landed.update(f for f in touching if f in planned)
        on_ground = [
            f
            for f in planned
            if f in touching
            or (f in self._landed and self.model.sole_frame(f)[0][2] < LANDED_HEIGHT)
        ]
        feet = on_ground or touching or [command.stance.foot]
        contacts = []
        for foot in feet:
            position, rotation = self.model.sole_frame(foot)
            yaw = yaw_of(rotation)
            ground_point = np.array([position[0], position[1], 0.0])
            contacts.append(FootContact(ground_point, yaw, self._ankle_height))
        try:
            wrenches = distribute_wrench(contacts, force, self.planned_cop, self.limits)
        except WrenchDistributionError as error:
            # Seen only while falling: no contact wrenches in the feed-forward; report it.
            self.failure = f"{error} at t = {command.time:.2f} s"
            wrenches = [np.zeros(6) for _ in contacts]
        self._contacts = contacts
        self.planned_forces = {f: float(w[2]) for f, w in zip(feet, wrenches, strict=True)}
        # A foot carrying less than planned (a bounce, a heel up) is not tipped onto its
        # edge by its ankle's feed-forward: its CoP stays on the sole at the force it carries.
        wrenches = [
            within_sole_at_force(contact, wrench, self.load(foot), self.limits.sole)
            for foot, contact, wrench in zip(feet, contacts, wrenches, strict=True)
        ]
        return feet, wrenches

    def _feedforward(
        self, feet: list[Foot], wrenches: list[NDArray[np.float64]]
    ) -> NDArray[np.float64]:
        """tau_ff [N m] from the floating base's inverse dynamics: the base accelerates as
        the planned wrenches and the IK's joint accelerations a_j make it (the base rows
        of M a + h = S^T tau + J^T f, which no torque enters), and the joints' rows give
        the torques for that motion."""
        model = self.model
        contact_force = np.zeros(model.nv)
        for foot, contact, wrench in zip(feet, self._contacts, wrenches, strict=True):
            contact_force += model.wrench_generalized_force(foot, contact.sole_point, wrench)
        self.expected_contact_force = contact_force
        mass_matrix = model.mass_matrix()
        bias = model.inverse_dynamics(np.zeros(model.nv))
        joints = self._acceleration
        base = np.linalg.solve(
            mass_matrix[:6, :6], contact_force[:6] - bias[:6] - mass_matrix[:6, 6:] @ joints
        )
        return (
            mass_matrix[6:, :6] @ base + mass_matrix[6:, 6:] @ joints + bias[6:] - contact_force[6:]
        )

    def _friction(self, velocity: NDArray[np.float64]) -> NDArray[np.float64]:
        """The motors' friction [N m] at the planned joint velocities [rad/s], which the
        feed-forward adds (friction compensation; the sign smoothed over
        ``FRICTION_SPEED``): the nominal model's Coulomb and viscous terms."""
        return (
            self._static_friction * np.tanh(velocity / FRICTION_SPEED)
            + self._viscous_friction * velocity
        )

    # ---------------------------------------------------------- observation
    def load(self, foot: str) -> float:
        """``foot``'s estimated normal force [N] at the last reading (0: in the air)."""
        return self.loads.get(foot, 0.0)

    def _update_loads(
        self, measurement: RobotMeasurement, state: RobotState, elapsed: float | None
    ) -> None:
        """Each foot's normal force: its force sensor's, else the contact observer's
        (``elapsed`` [s] since the last reading, None at the first)."""
        if measurement.foot_forces is not None:
            self.loads = {f: r.normal_force for f, r in measurement.foot_forces.items()}
            return
        assert self.observer is not None  # a robot without foot sensors has one
        if self._start is not None:
            self.observer.reset(state.q, state.v)
        dt = self.period if elapsed is None else elapsed
        # The joints feel the motors' torques less their friction (the nominal model's).
        torques = measurement.joint_torques - self._friction(measurement.joint_velocities)
        self.loads = dict(self.observer.update(state.q, state.v, torques, max(dt, 1e-9)))

    def observe(
        self, measurement: RobotMeasurement, stance: Foot, double_support: bool
    ) -> MeasuredState:
        """Estimate the state from ``measurement``; return what the planner reads: the CoM, the
        velocity of the angular momentum about the CoP (u,
        :func:`app.stabilizer.centroidal.momentum_velocity`) and, in single support, the
        stance sole (the planner re-anchors its foothold there) and whether the swing sole
        touches the ground (a step due before the touchdown waits for it)."""
        threshold = CONTACT_LOAD * self.mass * GRAVITY
        if self._start is not None:  # the first reading after a reset
            self.estimator.reset(self._start, measurement)
        planned = ("left", "right") if double_support else (stance,)
        # The planned supports that carried load at the last reading stand still.
        contacts = [f for f in planned if self._start is not None or self.load(f) > threshold]
        self.state = state = self.estimator.update(measurement, contacts)
        elapsed = None if self._last_reading is None else measurement.time - self._last_reading
        self._last_reading = measurement.time
        self._update_loads(measurement, state, elapsed)
        self._start = None
        sole, swing_contact = None, None
        if not double_support:
            if self.load(stance) > threshold:
                sole = self.model.sole_frame(stance)[0][:2].copy()
            swing_contact = self.load(other_foot(stance)) > threshold
        velocity = centroidal.momentum_velocity(
            state.com_velocity[:2],
            self.model.centroidal_angular_momentum()[:2],
            self.mass,
            self.lipm.com_height,
            self.description.rotational_height,
        )
        com, velocity = self.com_filter.update(
            state.com[:2], velocity, self._pivot, 0.0 if elapsed is None else elapsed
        )
        return MeasuredState(state.time, com, velocity, swing_contact, sole)


def joint_impedance(
    model: RobotModel, description: RobotDescription
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Per-joint stiffness [N m/rad] and damping [N m s/rad] in the model's joint order.

    Raises:
        ParameterError: A joint of the model has no gains in the description.
    """
    missing = [name for name in model.joint_names if name not in description.joint_impedance]
    if missing:
        raise ParameterError(
            "joint_impedance", missing, f"gains for every joint of {description.name}"
        )
    gains = [description.joint_impedance[name] for name in model.joint_names]
    return np.array([g.stiffness for g in gains]), np.array([g.damping for g in gains])
