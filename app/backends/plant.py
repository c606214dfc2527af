"""The simulated robot behind its low-level interface, whatever engine moves it.

A :class:`Plant` takes the low-level command (:class:`app.lowlevel.JointCommand`) and
gives the sensors' readings (:class:`app.lowlevel.RobotMeasurement`) and, apart, the
simulator's truth (:class:`app.lowlevel.SimulatorTruth`). What does not depend on the
engine lives here: the command stream (the target moves linearly across a tick's
physics steps and reaches the motors ``delay`` late), the drivers' law at every physics
step (:meth:`app.backends.joint_motors.JointMotors.driver` on the joint's own encoder,
less the viscous friction), the gains' error and the sensors. An engine
(:mod:`app.backends.pybullet_robot`, :mod:`app.backends.mujoco_robot`) reads the joints,
applies their torques, steps, and reports its state in the same frames and units.
"""

from __future__ import annotations

from abc import ABC, abstractmethod
from collections import deque
from collections.abc import Callable, Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from app.backends.joint_motors import JointMotors
from app.backends.sensors import Sensors
from app.lowlevel import JointCommand, RobotMeasurement, SimulatorTruth
from robots.description import RobotDescription

Observer = Callable[["Plant", NDArray[np.float64] | None], None]


class Plant(ABC):
    """A torque-driven biped on flat ground, stepped at the description's physics step.

    Attributes:
        description: The robot.
        joint_names: Actuated joint names, in the engine's order.
        model_joint_names: The rigid-body model's joint order: that of every low-level
            array (commands, truth, readings, ``applied_torques``).
        link_masses: Mass of each body part [kg]; index 0 is the base.
        mass: Total mass [kg].
        foot_links: Foot -> the engine's identifier of its ankle link.
        time_step: The physics step [s] (the description's).
        time: Simulated time [s].
        motors: The joints' motors, the model's joint order.
        applied_torques: The drivers' torques [N m] averaged over the last tick.
        sensors: The robot's sensors.
    """

    description: RobotDescription
    joint_names: list[str]
    model_joint_names: list[str]
    link_masses: NDArray[np.float64]
    mass: float
    foot_links: dict[str, int]
    time_step: float
    time: float
    motors: JointMotors
    applied_torques: NDArray[np.float64]
    sensors: Sensors

    @abstractmethod
    def __init__(
        self,
        description: RobotDescription,
        sensors: Sensors | None = None,
        delay: float = 0.0,
        urdf_text: str | None = None,
        ground_friction: float | None = None,
    ) -> None:
        """Load ``description`` from its physics URDF (``urdf_text``: that text with a
        model error), with its ``sensors``, the command ``delay`` [s] late and the ground's
        friction [-] (None: the description's)."""

    def _init_command_stream(self, delay: float) -> None:
        """The motors' command stream, ``delay`` [s] late (rounded to physics steps);
        ``motors`` and ``time_step`` must be set."""
        count = len(self.motors.static_friction)
        self._gain_scales = (np.ones(count), np.ones(count))
        self._delay_steps = round(delay / self.time_step)
        self._queue: deque[JointCommand] = deque(maxlen=self._delay_steps + 1)
        self._motor_target = np.zeros(count)
        self.applied_torques = np.zeros(count)

    # ------------------------------------------------------------ the engine
    @abstractmethod
    def _joint_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Encoder angles [rad] and velocities [rad/s], the model's joint order."""

    @abstractmethod
    def _apply_joint_torques(self, torques: NDArray[np.float64]) -> None:
        """Hold ``torques`` [N m] (model order) on the joints for the next physics step."""

    @abstractmethod
    def step(self, base_force_world: NDArray[np.float64] | None = None) -> None:
        """One physics step with a force [N] on the base's CoM (None: none)."""

    @abstractmethod
    def set_configuration(
        self,
        base_position: NDArray[np.float64],
        base_quaternion_xyzw: Sequence[float],
        joint_angles: Mapping[str, float],
        base_linear_velocity: NDArray[np.float64] | None = None,
        base_angular_velocity: NDArray[np.float64] | None = None,
        joint_velocities: Mapping[str, float] | None = None,
    ) -> None:
        """Teleport the robot to a state of its URDF base frame (world velocities)."""

    @abstractmethod
    def base_pose(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and quaternion (x, y, z, w) of the URDF base frame."""

    @abstractmethod
    def joint_angles(self) -> dict[str, float]:
        """Joint name -> angle [rad]."""

    @abstractmethod
    def com_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Whole-body CoM position [m] and velocity [m/s] in the world."""

    @abstractmethod
    def ground_contacts(self) -> set[int]:
        """The engine's identifiers of the links touching the ground."""

    @abstractmethod
    def link_name(self, link: int) -> str:
        """URDF name of the engine's link ``link``."""

    @abstractmethod
    def foot_pressure(self) -> dict[str, tuple[NDArray[np.float64], float]]:
        """Foot -> (CoP on the ground [m], shape (2,), normal force [N]); feet without
        contact absent."""

    @abstractmethod
    def sole_frame(
        self, foot: str, forward_kinematics: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s sole frame."""

    @abstractmethod
    def sole_yaw(self, foot: str) -> float:
        """Yaw [rad] of ``foot``'s sole about the world z axis."""

    @abstractmethod
    def truth(self) -> SimulatorTruth:
        """The simulator's state: for judging and logging only."""

    @abstractmethod
    def close(self) -> None:
        """Release the engine (idempotent)."""

    # ------------------------------------------------------- shared queries
    def feet_in_contact(self) -> set[str]:
        """Feet whose ankle link touches the ground."""
        contacts = self.ground_contacts()
        return {foot for foot, link in self.foot_links.items() if link in contacts}

    def sole_position(self, foot: str, forward_kinematics: bool = True) -> NDArray[np.float64]:
        """World position [m] of the sole frame origin of ``foot``, shape (3,)."""
        return self.sole_frame(foot, forward_kinematics)[0]

    def measure(self) -> RobotMeasurement:
        """What the robot senses now (:mod:`app.backends.sensors`); the motors' torques are
        the drivers' over the last tick, averaged (the low level reports them at every
        physics step)."""
        return self.sensors.read(self.truth(), self.applied_torques)

    # ------------------------------------------------------- torque control
    def set_gain_scales(self, stiffness: NDArray[np.float64], damping: NDArray[np.float64]) -> None:
        """Factors on each motor's kp and kd [-], the model's joint order: the real gains'
        error from the commanded ones."""
        self._gain_scales = (np.asarray(stiffness, float), np.asarray(damping, float))

    def set_motor_target(self, angles: NDArray[np.float64]) -> None:
        """Hold ``angles`` [rad] (after a reset): the motors' pending commands are this
        posture with the commanded gains and no feed-forward, and the next tick's target
        starts from it."""
        self._motor_target = np.asarray(angles, float).copy()
        self._queue.clear()
        self.applied_torques = np.zeros(len(self._motor_target))

    def actuate(
        self,
        command: JointCommand,
        steps: int,
        base_force_world: NDArray[np.float64] | None = None,
        observer: Observer | None = None,
    ) -> None:
        """Run ``steps`` physics steps with the motors on ``command``.

        The command stream the low level receives: at each physics step the target
        angle moves linearly from the last tick's to ``command.position``; it reaches the
        motors ``delay`` late. ``base_force_world`` [N] pushes the pelvis; ``observer``
        is called after each physics step.
        """
        kp = command.stiffness * self._gain_scales[0]
        kd = command.damping * self._gain_scales[1]
        start = self._motor_target
        if not self._queue:  # after a reset: the motors held the first target
            hold = JointCommand(start, np.zeros_like(start), kp, kd, np.zeros_like(start))
            self._queue.extend([hold] * self._queue.maxlen)  # type: ignore[operator]
        queue, motors = self._queue, self.motors
        applied = np.zeros(len(start))
        for step in range(1, steps + 1):
            target = start + (step / steps) * (command.position - start)
            queue.append(JointCommand(target, command.velocity, kp, kd, command.torque))
            q, qd = self._joint_state()
            driver = motors.driver(queue[0], q, qd)
            applied += driver
            self._apply_joint_torques(driver - motors.viscous_friction * qd)
            self.step(base_force_world)
            if observer is not None:
                observer(self, base_force_world)
        self._motor_target = command.position.copy()
        self.applied_torques = applied / steps
