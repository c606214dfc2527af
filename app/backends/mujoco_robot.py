"""A biped in its own MuJoCo world: the same plant as PyBullet's, on another engine.

One :class:`MujocoRobot` owns one ``MjModel`` and ``MjData``: the physics URDF the
PyBullet plant loads, with native armature and the motors' Coulomb friction as joint
``frictionloss`` (:mod:`app.backends.mujoco_model`), its base free, on an infinite flat
ground. The command stream, the drivers' law (the viscous friction subtracted from the
torque, as on PyBullet: an explicit term, small beside the drivers' kd) and the sensors
are :class:`app.backends.plant.Plant`'s. Frames: MuJoCo's free joint holds the URDF
base frame's pose (quaternion w x y z), the velocity of its origin in the world and
its angular velocity in its own frame. The contacts and their forces after a step are
those MuJoCo solved in it (found at the state before it), as PyBullet's are.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
from numpy.typing import NDArray

from app.backends.joint_motors import JointMotors
from app.backends.mujoco_model import add_floating_base_and_ground, mujoco, urdf_spec
from app.backends.plant import Plant
from app.backends.sensors import Sensors
from app.lowlevel import FootForce, SimulatorTruth
from kinematics.robot_model import RobotModel, yaw_of
from robots.description import RobotDescription
from robots.native_armature import without_rotor_discs
from robots.urdf_cache import derived_urdf

FEET = ("left", "right")


def _xyzw(wxyz: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.array([wxyz[1], wxyz[2], wxyz[3], wxyz[0]])


class MujocoRobot(Plant):
    """The robot and the ground in one MuJoCo model.

    Attributes:
        model: MuJoCo's model (``MjModel``).
        data: MuJoCo's state (``MjData``).
        joint_names: Actuated (hinge) joint names, in MuJoCo's order.
        link_masses: Mass of each body [kg]; index 0 is the base.
        foot_links: Foot -> MuJoCo body id of its ankle link.
    """

    def __init__(
        self,
        description: RobotDescription,
        sensors: Sensors | None = None,
        delay: float = 0.0,
        urdf_text: str | None = None,
        ground_friction: float | None = None,
    ) -> None:
        """Args:
        description: The robot.
        sensors: The robot's sensors (None: exact readings).
        delay: How late [s] the low-level command reaches the motors (rounded to
            physics steps).
        urdf_text: The physics URDF's text, with the armature as discs as PyBullet
            loads it (None: the description's derived URDF).
        ground_friction: Friction of the ground and soles [-] (None: the description's).
        """
        self.description = description
        self.time_step = description.physics_time_step
        if urdf_text is None:
            urdf_text = derived_urdf(description, merged=True).read_text(encoding="utf-8")
        model = RobotModel(description)
        self.model_joint_names = list(model.joint_names)
        motors = [description.motors.get(name) for name in model.joint_names]
        self.motors = JointMotors(model.effort_limits, motors)
        spec = urdf_spec(
            without_rotor_discs(urdf_text, description),
            self.time_step,
            {n: description.motor_armature.get(n, 0.0) for n in self.model_joint_names},
            dict(zip(self.model_joint_names, self.motors.static_friction, strict=True)),
        )
        feet = {foot: description.ankle_link(foot) for foot in FEET}
        friction = description.ground_friction if ground_friction is None else ground_friction
        add_floating_base_and_ground(spec, feet, friction, description.sole_spinning_friction)
        self.model = spec.compile()
        self.data = mujoco.MjData(self.model)
        m = self.model
        hinges = [j for j in range(m.njnt) if m.jnt_type[j] == mujoco.mjtJoint.mjJNT_HINGE]
        self.joint_names = [m.joint(j).name for j in hinges]
        self._qpos = {m.joint(j).name: int(m.jnt_qposadr[j]) for j in hinges}
        self._dof = {m.joint(j).name: int(m.jnt_dofadr[j]) for j in hinges}
        self._model_qpos = np.array([self._qpos[n] for n in self.model_joint_names])
        self._model_dof = np.array([self._dof[n] for n in self.model_joint_names])
        self._base = int(m.jnt_bodyid[0])
        self.foot_links = {foot: int(m.body(link).id) for foot, link in feet.items()}
        self._ground = int(m.geom("ground").id)
        self.link_masses = np.array(m.body_mass[self._base :])
        self.mass = float(self.link_masses.sum())
        self._force = np.zeros(6)  # contact force and torque in the contact frame
        self.time = 0.0
        self._init_command_stream(delay)
        self.sensors = sensors or Sensors(description)

    # ----------------------------------------------------------------- state
    def set_configuration(
        self,
        base_position: NDArray[np.float64],
        base_quaternion_xyzw: Sequence[float],
        joint_angles: Mapping[str, float],
        base_linear_velocity: NDArray[np.float64] | None = None,
        base_angular_velocity: NDArray[np.float64] | None = None,
        joint_velocities: Mapping[str, float] | None = None,
    ) -> None:
        """Teleport the robot to a configuration of its URDF base frame, with no contact
        or solver warm start remembered from before.

        Args:
            base_position: Base frame origin [m].
            base_quaternion_xyzw: Base frame orientation.
            joint_angles: Joint name -> angle [rad] (missing: 0).
            base_linear_velocity: Velocity of the base frame origin [m/s].
            base_angular_velocity: Base angular velocity in the world [rad/s].
            joint_velocities: Joint name -> velocity [rad/s] (missing: 0).
        """
        m, d = self.model, self.data
        mujoco.mj_resetData(m, d)
        x, y, z, w = (float(v) for v in base_quaternion_xyzw)
        quaternion = np.array([w, x, y, z]) / np.linalg.norm([w, x, y, z])
        d.qpos[:3] = np.asarray(base_position, float)
        d.qpos[3:7] = quaternion
        rotation = np.zeros(9)
        mujoco.mju_quat2Mat(rotation, quaternion)
        if base_linear_velocity is not None:
            d.qvel[:3] = np.asarray(base_linear_velocity, float)
        if base_angular_velocity is not None:
            d.qvel[3:6] = rotation.reshape(3, 3).T @ np.asarray(base_angular_velocity, float)
        velocities = joint_velocities or {}
        for name in self.joint_names:
            d.qpos[self._qpos[name]] = joint_angles.get(name, 0.0)
            d.qvel[self._dof[name]] = velocities.get(name, 0.0)
        mujoco.mj_kinematics(m, d)

    def base_pose(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and quaternion (x, y, z, w) of the URDF base frame."""
        return self.data.qpos[:3].copy(), _xyzw(self.data.qpos[3:7])

    def joint_angles(self) -> dict[str, float]:
        """Joint name -> measured angle [rad]."""
        return {name: float(self.data.qpos[self._qpos[name]]) for name in self.joint_names}

    def com_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Whole-body CoM position [m] and velocity [m/s] in the world, shape (3,) each."""
        m, d = self.model, self.data
        mujoco.mj_kinematics(m, d)
        mujoco.mj_comPos(m, d)
        jacobian = np.zeros((3, m.nv))
        mujoco.mj_jacSubtreeCom(m, d, jacobian, self._base)
        return d.subtree_com[self._base].copy(), jacobian @ d.qvel

    def _ground_contacts(self) -> list[tuple[int, int]]:
        """(contact index, robot body id) of each contact with the ground of the last step."""
        d, body_of = self.data, self.model.geom_bodyid
        found = []
        for index in range(d.ncon):
            geom = d.contact.geom[index]
            if geom[0] == self._ground:
                found.append((index, int(body_of[geom[1]])))
            elif geom[1] == self._ground:
                found.append((index, int(body_of[geom[0]])))
        return found

    def ground_contacts(self) -> set[int]:
        """MuJoCo body ids of the links touching the ground."""
        return {body for _, body in self._ground_contacts()}

    def link_name(self, link: int) -> str:
        """URDF name of MuJoCo body ``link``."""
        return str(self.model.body(link).name)

    def foot_pressure(self) -> dict[str, tuple[NDArray[np.float64], float]]:
        """Foot -> (CoP on the ground [m], shape (2,), normal force [N]) of its contacts
        (``mj_contactForce``: the normal force of each, at its point). Feet without
        contact are absent."""
        sums: dict[int, NDArray[np.float64]] = {}
        for index, body in self._ground_contacts():
            mujoco.mj_contactForce(self.model, self.data, index, self._force)
            normal = self._force[0]
            point = self.data.contact.pos[index]
            entry = sums.setdefault(body, np.zeros(3))
            entry += (normal * point[0], normal * point[1], normal)
        result = {}
        for foot, link in self.foot_links.items():
            total = sums.get(link)
            if total is not None and total[2] > 1e-6:
                result[foot] = (total[:2] / total[2], float(total[2]))
        return result

    def sole_frame(
        self, foot: str, forward_kinematics: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s sole frame; without
        ``forward_kinematics`` the transforms MuJoCo last computed (the step's start or the
        last query; reading them never changes the run)."""
        if forward_kinematics:
            mujoco.mj_kinematics(self.model, self.data)
        link = self.foot_links[foot]
        rotation = self.data.xmat[link].reshape(3, 3).copy()
        origin = self.data.xpos[link] + rotation @ np.array(self.description.sole_offset)
        return origin, rotation

    def sole_yaw(self, foot: str) -> float:
        """Yaw [rad] of ``foot``'s sole about the world z axis (forward kinematics first)."""
        return yaw_of(self.sole_frame(foot)[1])

    def truth(self) -> SimulatorTruth:
        """The simulator's state (joints in the rigid-body model's order): for judging and
        logging only."""
        d = self.data
        forces = {
            foot: FootForce(force, cop) for foot, (cop, force) in self.foot_pressure().items()
        }
        return SimulatorTruth(
            time=self.time,
            base_position=d.qpos[:3].copy(),
            base_orientation=_xyzw(d.qpos[3:7]),
            base_linear_velocity=d.qvel[:3].copy(),
            base_angular_velocity=d.qvel[3:6].copy(),
            joint_positions=d.qpos[self._model_qpos],
            joint_velocities=d.qvel[self._model_dof],
            foot_forces=forces,
        )

    # ------------------------------------------------------- torque control
    def _joint_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Encoder angles [rad] and velocities [rad/s], the model's joint order."""
        return self.data.qpos[self._model_qpos], self.data.qvel[self._model_dof]

    def _apply_joint_torques(self, torques: NDArray[np.float64]) -> None:
        """Hold ``torques`` [N m] (model order) on the joints for the next physics step."""
        self.data.qfrc_applied[self._model_dof] = torques

    def step(self, base_force_world: NDArray[np.float64] | None = None) -> None:
        """One physics step (``time_step`` [s]) with a force [N] on the base CoM.

        The force is cleared after the step, as PyBullet does, so a push lasting several
        steps must be applied at every step. ``None`` (or a zero force) applies none.
        """
        pushed = base_force_world is not None and any(base_force_world)
        if pushed:
            self.data.xfrc_applied[self._base, :3] = base_force_world
        mujoco.mj_step(self.model, self.data)
        if pushed:
            self.data.xfrc_applied[self._base, :3] = 0.0
        self.time += self.time_step

    def close(self) -> None:
        """Release the model (idempotent)."""
        self.data = None  # type: ignore[assignment]
        self.model = None  # type: ignore[assignment]
