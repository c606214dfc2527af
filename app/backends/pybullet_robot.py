"""A biped in its own PyBullet world: loading, its sensors and its joint motors.

One :class:`SimulatedRobot` owns one ``BulletClient`` in DIRECT mode (several can
coexist in a process), a flat ground with friction (200 km wide: no run reaches its
edge, :data:`GROUND_HALF_SIZE`), and the robot loaded from the derived URDF with
the URDF's inertias, its fixed-joint links merged into their parents
(:mod:`robots.urdf_merge`: 29 bodies instead of 41, 8 % less CPU time per physics
step; a ground contact of the head is reported as one of ``torso_link``).
The joints are torque-driven by :class:`app.backends.joint_motors.JointMotors`, the G1
driver's law on the low-level command alone, at every physics step
(:meth:`app.backends.plant.Plant.actuate`, shared with the MuJoCo plant); PyBullet's own
joint motors hold only the motors' Coulomb friction (``VELOCITY_CONTROL`` to zero
velocity with that force). :meth:`measure` gives what the robot senses
(:mod:`app.backends.sensors`), :meth:`truth` the simulator's state (:mod:`app.lowlevel`).
Frames: PyBullet's base pose is the base link's *inertial* frame;
:meth:`base_pose` converts it to the URDF base frame.
"""

from __future__ import annotations

import tempfile
from collections.abc import Mapping, Sequence
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from app.backends.joint_motors import JointMotors
from app.backends.plant import Plant
from app.backends.sensors import Sensors
from app.lowlevel import FootForce, SimulatorTruth
from kinematics.native_output import native_output_silenced
from kinematics.robot_model import RobotModel, yaw_of
from robots.description import RobotDescription
from robots.urdf_cache import derived_urdf

with native_output_silenced():  # pybullet prints its build time when first imported
    import pybullet
    import pybullet_data
    from pybullet_utils.bullet_client import BulletClient

GRAVITY = 9.81  # [m/s^2]
# PyBullet's plane.urdf is a 200 m box (its top at z = 0), scaled here so that no run
# reaches its edge: 0.12 m/s for a week or 0.5 m/s for two days stays on it. The
# box, not GEOM_PLANE, keeps the soles' box-box contact algorithm.
GROUND_SCALE = 1000.0  # [-]
GROUND_HALF_SIZE = 100.0 * GROUND_SCALE  # [m] the ground spans |x|, |y| <= this


class SimulatedRobot(Plant):
    """The robot and the ground in one PyBullet client.

    Attributes:
        joint_names: Actuated (revolute) joint names, in PyBullet index order.
        link_masses: Mass of each body part [kg]; index 0 is the base.
        mass: Total mass [kg].
        foot_links: Foot -> PyBullet link index of its ankle link.
        time_step: PyBullet's fixed time step [s] (the description's).
        time: Simulated time [s].
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
        urdf_text: The physics URDF's text (None: the description's derived URDF).
        ground_friction: Friction coefficient of the soles on the ground [-] (None: the
            description's).
        """
        self.description = description
        self.time_step = description.physics_time_step
        with native_output_silenced():  # pybullet prints "argv[0]=" at connect
            self.client = BulletClient(connection_mode=pybullet.DIRECT)
        client = self.client
        client.setGravity(0.0, 0.0, -GRAVITY)
        client.setPhysicsEngineParameter(
            fixedTimeStep=description.physics_time_step,
            numSolverIterations=description.solver_iterations,
            deterministicOverlappingPairs=1,
        )
        client.setAdditionalSearchPath(pybullet_data.getDataPath())
        self.ground = client.loadURDF("plane.urdf", useFixedBase=True, globalScaling=GROUND_SCALE)
        friction = description.ground_friction if ground_friction is None else ground_friction
        client.changeDynamics(self.ground, -1, lateralFriction=friction)
        flags = pybullet.URDF_USE_INERTIA_FROM_FILE
        urdf = derived_urdf(description, merged=True)
        if urdf_text is None:
            self.body = client.loadURDF(str(urdf), [0, 0, 1], flags=flags)
        else:  # a model error: loaded from a file of its own, deleted once read
            with tempfile.TemporaryDirectory(dir=urdf.parent) as folder:
                path = Path(folder) / urdf.name
                path.write_text(urdf_text, encoding="utf-8")
                self.body = client.loadURDF(str(path), [0, 0, 1], flags=flags)

        self.joint_indices: list[int] = []
        self.joint_names: list[str] = []
        link_index = {client.getBodyInfo(self.body)[0].decode(): -1}
        for index in range(client.getNumJoints(self.body)):
            info = client.getJointInfo(self.body, index)
            link_index[info[12].decode()] = index
            if info[2] == pybullet.JOINT_REVOLUTE:
                self.joint_indices.append(index)
                self.joint_names.append(info[1].decode())
            client.setJointMotorControl2(self.body, index, pybullet.VELOCITY_CONTROL, force=0.0)
        self._link_names = {index: name for name, index in link_index.items()}
        self.foot_links = {
            foot: link_index[description.ankle_link(foot)] for foot in ("left", "right")
        }
        for link in self.foot_links.values():
            client.changeDynamics(
                self.body,
                link,
                lateralFriction=1.0,  # PyBullet multiplies the two: the pair's is the ground's
                spinningFriction=description.sole_spinning_friction,
                frictionAnchor=1,
            )
        self.link_count = client.getNumJoints(self.body)
        for link in range(-1, self.link_count):  # PyBullet's default damping of 0.04 on every link
            client.changeDynamics(self.body, link, linearDamping=0.0, angularDamping=0.0)
        self.link_masses = np.array(
            [client.getDynamicsInfo(self.body, link)[0] for link in range(-1, self.link_count)]
        )
        self.mass = float(self.link_masses.sum())
        base_info = client.getDynamicsInfo(self.body, -1)
        self._base_inertial = (base_info[3], base_info[4])
        # The module functions with the client id: BulletClient's per-call
        # attribute lookup (a functools.partial each time) costs ~1 us per call.
        self._client_id = client._client
        self._set_motors = pybullet.setJointMotorControlArray
        self._step_simulation = pybullet.stepSimulation
        self._contacts: tuple | None = None  # contact points of the current state
        self.time = 0.0
        model = RobotModel(description)
        # The low-level interface orders joints as the rigid-body model does.
        self._model_indices = [
            self.joint_indices[self.joint_names.index(name)] for name in model.joint_names
        ]
        self.model_joint_names = list(model.joint_names)
        self.motors = JointMotors(
            model.effort_limits, [description.motors.get(name) for name in model.joint_names]
        )
        count = len(self._model_indices)
        client.setJointMotorControlArray(
            self.body,
            self._model_indices,
            pybullet.VELOCITY_CONTROL,
            targetVelocities=[0.0] * count,
            forces=self.motors.static_friction.tolist(),
        )
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
        remembered from before (a run after it goes as on a new world).

        Args:
            base_position: Base frame origin [m].
            base_quaternion_xyzw: Base frame orientation.
            joint_angles: Joint name -> angle [rad] (missing: 0).
            base_linear_velocity: Velocity of the base frame origin [m/s].
            base_angular_velocity: Base angular velocity in the world [rad/s].
            joint_velocities: Joint name -> velocity [rad/s] (missing: 0).
        """
        # Clear the contact points of the last run first: they warm-start the solver and
        # anchor friction, and a run after a reset went otherwise than on a new world.
        self.client.resetBasePositionAndOrientation(self.body, [0.0, 0.0, 100.0], [0, 0, 0, 1])
        self.client.performCollisionDetection()
        position, orientation = self.client.multiplyTransforms(
            list(base_position), list(base_quaternion_xyzw), *self._base_inertial
        )
        self.client.resetBasePositionAndOrientation(self.body, position, orientation)
        linear = np.zeros(3) if base_linear_velocity is None else base_linear_velocity
        angular = np.zeros(3) if base_angular_velocity is None else base_angular_velocity
        # PyBullet's base velocity is that of the inertial frame origin.
        offset = np.array(position) - np.asarray(base_position, float)
        linear = np.asarray(linear, float) + np.cross(angular, offset)
        self.client.resetBaseVelocity(self.body, list(linear), list(angular))
        self._contacts = None
        velocities = joint_velocities or {}
        for name, index in zip(self.joint_names, self.joint_indices, strict=True):
            self.client.resetJointState(
                self.body, index, joint_angles.get(name, 0.0), velocities.get(name, 0.0)
            )

    def base_pose(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Position [m] and quaternion (x, y, z, w) of the URDF base frame."""
        position, orientation = self.client.getBasePositionAndOrientation(self.body)
        inverse = self.client.invertTransform(*self._base_inertial)
        frame_position, frame_orientation = self.client.multiplyTransforms(
            position, orientation, *inverse
        )
        return np.array(frame_position), np.array(frame_orientation)

    def joint_angles(self) -> dict[str, float]:
        """Joint name -> measured angle [rad]."""
        states = self.client.getJointStates(self.body, self.joint_indices)
        return {name: state[0] for name, state in zip(self.joint_names, states, strict=True)}

    def com_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Whole-body CoM position [m] and velocity [m/s] in the world, shape (3,) each."""
        base_position, _ = self.client.getBasePositionAndOrientation(self.body)
        base_velocity, _ = self.client.getBaseVelocity(self.body)
        # Forward kinematics of the current state: PyBullet's cached link states are
        # those of the step before.
        states = self.client.getLinkStates(
            self.body, list(range(self.link_count)), computeLinkVelocity=1,
            computeForwardKinematics=1,
        )  # fmt: skip
        positions = np.array([base_position] + [state[0] for state in states])
        velocities = np.array([base_velocity] + [state[6] for state in states])
        com = self.link_masses @ positions / self.mass
        com_velocity = self.link_masses @ velocities / self.mass
        return com, com_velocity

    def ground_contacts(self) -> set[int]:
        """PyBullet link indices touching the ground (-1: the base)."""
        return {point[3] for point in self.contact_points()}

    def contact_points(self) -> tuple:
        """PyBullet's contact points between the robot and the ground, fetched once per
        physics state (the fall check and the CoP measurement of a tick share them)."""
        if self._contacts is None:
            self._contacts = self.client.getContactPoints(bodyA=self.body, bodyB=self.ground)
        return self._contacts

    def foot_pressure(self) -> dict[str, tuple[NDArray[np.float64], float]]:
        """Foot -> (CoP on the ground [m], shape (2,), normal force [N]) of its contacts.

        Feet without contact are absent.
        """
        sums: dict[int, list[float]] = {}
        for point in self.contact_points():
            entry = sums.setdefault(point[3], [0.0, 0.0, 0.0])
            force = point[9]
            entry[0] += force * point[6][0]
            entry[1] += force * point[6][1]
            entry[2] += force
        result = {}
        for foot, link in self.foot_links.items():
            total = sums.get(link, [0.0, 0.0, 0.0])
            if total[2] > 1e-6:
                result[foot] = (np.array(total[:2]) / total[2], total[2])
        return result

    def link_name(self, link: int) -> str:
        """URDF name of PyBullet link index ``link`` (-1: the base)."""
        return self._link_names.get(link, str(link))

    def _foot_frame(
        self, foot: str, forward_kinematics: bool
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s ankle link frame.

        ``forward_kinematics``: update the link transforms from the joint state
        first. PyBullet then also refreshes the bodies' collision transforms, which
        changes the next step's contact solution slightly: an observer that must
        not perturb the run (the physics log) passes False and reads the
        transforms of the last step.
        """
        state = self.client.getLinkState(
            self.body, self.foot_links[foot], computeForwardKinematics=int(forward_kinematics)
        )
        rotation = np.array(self.client.getMatrixFromQuaternion(state[5])).reshape(3, 3)
        return np.array(state[4]), rotation

    def sole_frame(
        self, foot: str, forward_kinematics: bool = True
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s sole frame
        (``forward_kinematics``: see :meth:`_foot_frame`)."""
        origin, rotation = self._foot_frame(foot, forward_kinematics)
        return origin + rotation @ np.array(self.description.sole_offset), rotation

    def sole_yaw(self, foot: str) -> float:
        """Yaw [rad] of ``foot``'s sole about the world z axis (forward kinematics first)."""
        _, rotation = self._foot_frame(foot, True)
        return yaw_of(rotation)

    # ------------------------------------------------------- torque control
    def truth(self) -> SimulatorTruth:
        """The simulator's state (joints in the rigid-body model's order,
        :class:`kinematics.robot_model.RobotModel`): for judging and logging only."""
        states = self.client.getJointStates(self.body, self._model_indices)
        position, quaternion = self.base_pose()
        inertial_position, _ = self.client.getBasePositionAndOrientation(self.body)
        linear, angular = self.client.getBaseVelocity(self.body)
        rotation = np.array(self.client.getMatrixFromQuaternion(quaternion)).reshape(3, 3)
        # PyBullet's base velocity is that of the inertial frame origin.
        origin_velocity = np.array(linear) + np.cross(
            angular, position - np.array(inertial_position)
        )
        forces = {
            foot: FootForce(force, cop) for foot, (cop, force) in self.foot_pressure().items()
        }
        return SimulatorTruth(
            time=self.time,
            base_position=np.asarray(position, float),
            base_orientation=np.asarray(quaternion, float),
            base_linear_velocity=origin_velocity,
            base_angular_velocity=rotation.T @ np.asarray(angular, float),
            joint_positions=np.array([s[0] for s in states]),
            joint_velocities=np.array([s[1] for s in states]),
            foot_forces=forces,
        )

    def _joint_state(self) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Encoder angles [rad] and velocities [rad/s], the model's joint order."""
        states = pybullet.getJointStates(
            self.body, self._model_indices, physicsClientId=self._client_id
        )
        return np.array([s[0] for s in states]), np.array([s[1] for s in states])

    def _apply_joint_torques(self, torques: NDArray[np.float64]) -> None:
        """Hold ``torques`` [N m] (model order) on the joints for the next physics step."""
        self._set_motors(
            self.body,
            self._model_indices,
            pybullet.TORQUE_CONTROL,
            forces=torques.tolist(),
            physicsClientId=self._client_id,
        )

    def step(self, base_force_world: NDArray[np.float64] | None = None) -> None:
        """One physics step (``time_step`` [s]) with a force [N] on the base CoM.

        PyBullet clears external forces after each step, so a push lasting several
        steps must be applied at every step. ``None`` (or a zero force) applies none.
        """
        if base_force_world is not None and any(base_force_world):
            position, _ = self.client.getBasePositionAndOrientation(self.body)
            self.client.applyExternalForce(
                self.body, -1, list(base_force_world), position, pybullet.WORLD_FRAME
            )
        self._step_simulation(physicsClientId=self._client_id)
        self._contacts = None
        self.time += self.time_step

    def close(self) -> None:
        """Disconnect the PyBullet client (idempotent)."""
        if self.client is not None:
            try:
                self.client.disconnect()
            except pybullet.error:
                pass
            self.client = None  # type: ignore[assignment]
