"""Full-humanoid backend: the planner's commands realised on a robot in PyBullet.

The robot (:class:`app.backends.pybullet_robot.SimulatedRobot`) is driven as a real G1 is,
through its low-level interface (:mod:`app.lowlevel`): per joint a target, a
stiffness, a damping and a feed-forward torque, evaluated by the simulated motors at
every physics step (:mod:`app.backends.joint_motors`). One control tick of :meth:`step`:

    measurement (from the last tick) -> whole-body controller -> motors over the
    tick's physics steps (the push on the pelvis at each) -> next measurement

The whole-body controller (:mod:`app.stabilizer`) turns the planner's command into
the joint command; its options are :class:`app.stabilizer.config.StabilizerConfig`,
set per robot in its description (``backend_options``) and by ``--set``.
"""

from __future__ import annotations

import time as clock
from collections import defaultdict
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.backends.base import FallStatus, InitialCondition
from app.backends.physics_log import PhysicsLog
from app.backends.plant import Plant
from app.backends.pybullet_robot import GROUND_HALF_SIZE, SimulatedRobot
from app.backends.sensors import Sensors
from app.lowlevel import RobotMeasurement
from app.reality import DEFAULT_PROFILE, RealityDraw, robot_reality
from app.stabilizer.config import OPTION_NAMES, StabilizerConfig
from app.stabilizer.controller import WholeBodyController
from kinematics.swing_foot import SwingTiming
from kinematics.whole_body_ik import sole_pose
from planner.exceptions import ParameterError
from planner.types import Foot, MeasuredState, PlannerOutput, Vector2
from robots import get_robot
from robots.description import RobotDescription
from robots.model_error import perturbed_text
from robots.urdf_cache import derived_urdf, locked_angles

DEFAULT_CONTROL_PERIOD = 0.01  # [s]
CONTROL_PERIOD_RANGE = (0.002, 0.012)  # [s] measured on G1 (README, "--set")
INITIAL_VELOCITY_HORIZON = 0.01  # [s] finite difference for the initial joint velocities


def stabilizer_config(options: Mapping[str, object]) -> StabilizerConfig:
    """The stabilizer's options among a description's ``backend_options`` (checked)."""
    known = {k: v for k, v in options.items() if k != "control_period"}
    unknown = sorted(set(known) - set(OPTION_NAMES))
    if unknown:
        raise ParameterError("backend option", unknown[0], f"one of {', '.join(OPTION_NAMES)}")
    return StabilizerConfig(**known)  # type: ignore[arg-type]


def check_backend_options(description: RobotDescription, options: Mapping[str, object]) -> None:
    """Check backend ``options`` for ``description`` without loading anything: the
    stabilizer's options (:class:`StabilizerConfig`) and the control period, a whole
    multiple of the robot's physics step in [2, 12] ms.

    Raises:
        ParameterError: Naming the option, its value and what is allowed.
    """
    stabilizer_config(options)
    period = options.get("control_period", DEFAULT_CONTROL_PERIOD)
    low, high = CONTROL_PERIOD_RANGE
    if isinstance(period, bool) or not isinstance(period, int | float) or not low <= period <= high:
        raise ParameterError("control_period", period, f"a number in [{low:g}, {high:g}] s")
    physics_step = description.physics_time_step
    substeps = round(period / physics_step)
    if substeps < 1 or abs(substeps * physics_step - period) > 1e-9:
        raise ParameterError(
            "control_period/physics_time_step",
            (period, physics_step),
            "a control period that is a whole multiple of the physics step [s]",
        )


def simulated_robot(
    description: RobotDescription, reality: RealityDraw, plant: type[Plant] = SimulatedRobot
) -> Plant:
    """The simulated robot with ``reality``'s sensors, delay, gains and model errors, on
    the engine of ``plant``."""
    urdf_text = None
    if reality.model_error:
        urdf_text = perturbed_text(
            derived_urdf(description, merged=True).read_text(encoding="utf-8"),
            reality.link_mass_scale,
            (reality.torso_link, reality.torso_added_mass),
            (reality.torso_link, reality.com_offset),
        )
    sensors = Sensors(description, reality.noise, reality.gyro_yaw_bias, reality.sample_rng())
    sim = plant(
        description,
        sensors=sensors,
        delay=reality.delay,
        urdf_text=urdf_text,
        ground_friction=reality.ground_friction,
    )
    names = sim.model_joint_names
    scales = (
        np.array([reality.stiffness_scale.get(n, 1.0) for n in names]),
        np.array([reality.damping_scale.get(n, 1.0) for n in names]),
    )
    sim.set_gain_scales(*scales)
    return sim


class PyBulletBackend:
    """A full humanoid in PyBullet implementing :class:`app.backends.base.Backend`
    (another engine: a subclass with another ``plant``, :mod:`app.backends.mujoco`).

    Args:
        robot: Registry name or description of the robot; its ``backend_options``
            give the controller's options and the control period.
        timing: The planner's step timing (for the swing foot).
        physics_log: Records every physics step (None: nothing).
        reality: The sensors' noise, the control delay and the model's errors
            (:mod:`app.reality`; None: the nominal profile).

    Attributes:
        name: ``"pybullet"``.
        plant: The simulated robot's class (its engine).
        mass: Total mass measured in PyBullet [kg].
        com_height: Nominal CoM height [m] (the planner's pendulum is
            ``description.pendulum_height``, taller).
        control_period: Duration of one :meth:`step` [s].
        controller: The whole-body controller.
        sim: The simulated robot.
        physics_log: Records every physics step (None: nothing).
    """

    name = "pybullet"
    plant: type[Plant] = SimulatedRobot

    def __init__(
        self,
        robot: str | RobotDescription = "g1",
        timing: SwingTiming | None = None,
        physics_log: PhysicsLog | None = None,
        reality: RealityDraw | None = None,
    ) -> None:
        self.description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
        options = self.description.backend_options
        check_backend_options(self.description, options)
        self.control_period = float(options.get("control_period", DEFAULT_CONTROL_PERIOD))  # type: ignore[arg-type]
        self._substeps = round(self.control_period / self.description.physics_time_step)
        self._locked_angles = locked_angles(self.description)
        self.reality = reality or robot_reality(self.description, DEFAULT_PROFILE, 0)
        self.sim = simulated_robot(self.description, self.reality, self.plant)
        self.mass = self.sim.mass
        self.com_height = self.description.com_height
        self.controller = WholeBodyController(
            self.description,
            timing or SwingTiming(),
            self.control_period,
            stabilizer_config(options),
        )
        self.physics_log = physics_log
        self.timers: dict[str, float] = defaultdict(float)
        self.ticks = 0
        self._measurement: RobotMeasurement | None = None

    @property
    def timing(self) -> SwingTiming:
        """The planner's step timing used by the swing foot."""
        return self.controller.timing

    # ------------------------------------------------------------------ reset
    def reset(self, initial: InitialCondition) -> MeasuredState:
        """Stand on both feet at the initial footholds with the initial CoM state."""
        if initial.stance.foot == initial.swing.foot:
            raise ParameterError("initial.swing.foot", initial.swing.foot, "the non-stance foot")
        stance: Foot = initial.stance.foot
        soles: dict[Foot, NDArray[np.float64]] = {
            stance: sole_pose(np.array([*initial.stance.position, 0.0])),
            initial.swing.foot: sole_pose(np.array([*initial.swing.position, 0.0])),
        }
        com_xy = np.asarray(initial.com_position, float)
        velocity = self._initial_velocities(soles, com_xy, np.asarray(initial.com_velocity, float))
        target = self.controller.reset(soles, stance, com_xy)
        ik = self.controller.ik
        base = np.asarray(ik.robot.get_T_world_fbase(), float)
        self.sim.set_configuration(
            base[:3, 3],
            Rotation.from_matrix(base[:3, :3]).as_quat(),
            dict(zip(ik.joint_names, ik.joint_angles(), strict=True)),
            *velocity,
        )
        self.sim.time = 0.0
        self.sim.set_motor_target(target)
        self.sim.sensors.reset(self.reality.sample_rng())
        self.timers.clear()
        self.ticks = 0
        self._measurement = self.sim.measure()
        return self.controller.observe(self._measurement, stance, False)

    def _initial_velocities(
        self,
        soles: Mapping[Foot, NDArray[np.float64]],
        com_xy: NDArray[np.float64],
        com_velocity: NDArray[np.float64],
    ) -> tuple[NDArray[np.float64], NDArray[np.float64], dict[str, float]]:
        """Base linear and angular velocity and joint velocities that move the CoM at
        ``com_velocity`` [m/s] with the feet still (a finite difference of two IK
        solutions)."""
        ik = self.controller.ik
        q0 = ik.reset(soles["left"], soles["right"], com_xy)
        if not np.any(com_velocity):
            return np.zeros(3), np.zeros(3), {}
        h = INITIAL_VELOCITY_HORIZON
        base0 = np.asarray(ik.robot.get_T_world_fbase(), float).copy()
        q1 = ik.solve(com_xy + h * com_velocity, soles["left"], soles["right"], "both", h)
        base1 = np.asarray(ik.robot.get_T_world_fbase(), float)
        linear = (base1[:3, 3] - base0[:3, 3]) / h
        angular = Rotation.from_matrix(base1[:3, :3] @ base0[:3, :3].T).as_rotvec() / h
        joints = dict(zip(ik.joint_names, (q1 - q0) / h, strict=True))
        return linear, angular, joints

    # ------------------------------------------------------------------- step
    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        """Realise ``command`` for one control period with ``push_force`` [N] on the pelvis."""
        if self._measurement is None:
            raise ParameterError("backend", "not reset", "reset() before step()")
        start = clock.perf_counter()
        joint_command = self.controller.tick(self._measurement, command)
        controlled = clock.perf_counter()
        if self.physics_log is not None:
            controller = self.controller
            self.physics_log.plan(
                controller.planned_cop, controller.planned_forces, controller.sole_targets
            )
        force = np.array([push_force[0], push_force[1], 0.0]) if any(push_force) else None
        self.sim.actuate(
            joint_command,
            self._substeps,
            force,
            None if self.physics_log is None else self.physics_log.record,
        )
        stepped = clock.perf_counter()
        self._measurement = self.sim.measure()
        measured = self.controller.observe(
            self._measurement, command.stance.foot, command.double_support
        )
        self.timers["control"] += controlled - start
        self.timers["physics"] += stepped - controlled
        self.timers["estimation"] += clock.perf_counter() - stepped
        self.ticks += 1
        return measured

    # ---------------------------------------------------------------- queries
    def fall_status(self) -> FallStatus:
        """Fallen if the pelvis is low or tilted, a non-foot body touches the ground, or
        the controller could not command the joints (the whole-body IK or the wrench
        distribution had no solution)."""
        if self.controller.failure is not None:
            return FallStatus(True, self.controller.failure)
        position, quaternion = self.sim.base_pose()
        if position[2] < self.description.fall_base_height:
            return FallStatus(True, f"pelvis height {position[2]:.3f} m")
        if np.max(np.abs(position[:2])) > GROUND_HALF_SIZE:
            return FallStatus(True, f"off the ground at ({position[0]:.1f}, {position[1]:.1f}) m")
        tilt = _tilt(quaternion)
        if tilt > self.description.fall_tilt:
            return FallStatus(True, f"pelvis tilt {np.degrees(tilt):.0f} deg")
        others = self.sim.ground_contacts() - set(self.sim.foot_links.values())
        if others:
            names = sorted(self.sim.link_name(link) for link in others)
            return FallStatus(True, f"ground contact of {', '.join(names)}")
        return FallStatus(False)

    @property
    def planned_cop(self) -> NDArray[np.float64]:
        """CoP [m] the feet were asked for at the last tick, shape (2,)."""
        return self.controller.planned_cop

    def foot_pressure(self) -> dict[str, tuple[NDArray[np.float64], float]]:
        """Foot -> (measured CoP [m], normal force [N]) of the feet on the ground."""
        return self.sim.foot_pressure()

    def feet_in_contact(self) -> set[str]:
        """Feet touching the ground."""
        return self.sim.feet_in_contact()

    def robot_configuration(self) -> tuple[NDArray[np.float64], NDArray[np.float64], dict]:
        """URDF base position [m], quaternion (x, y, z, w) and joint angles [rad]
        (the description's locked joints at their standing angle)."""
        position, quaternion = self.sim.base_pose()
        return position, quaternion, {**self._locked_angles, **self.sim.joint_angles()}

    def sole_positions(self) -> dict[str, NDArray[np.float64]]:
        """Measured sole origin of each foot in the world [m], shape (3,)."""
        return {foot: self.sim.sole_position(foot) for foot in ("left", "right")}

    def timing_report(self) -> dict[str, float]:
        """Mean wall time per tick of each part [s] (control, physics, estimation)."""
        ticks = max(self.ticks, 1)
        report = {key: value / ticks for key, value in self.timers.items()}
        report["total"] = sum(report.values())
        return report

    def close(self) -> None:
        """Release the simulated robot's engine."""
        self.sim.close()


def _tilt(quaternion_xyzw: NDArray[np.float64]) -> float:
    """Angle [rad] between the body z axis of a unit quaternion (x, y, z, w) and the vertical."""
    x, y = quaternion_xyzw[0], quaternion_xyzw[1]
    return float(np.arccos(np.clip(1.0 - 2.0 * (x * x + y * y), -1.0, 1.0)))
