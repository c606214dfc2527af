"""The rigid-body model of the simulated robot, in pinocchio.

Built from the same derived URDF as the physics (locked joints welded, fixed links
merged: :func:`robots.urdf_cache.derived_urdf`), with a free-flyer base, so its
joints, masses and inertias are the simulator's. It gives what the controller
computes from a state: the configuration vectors in pinocchio's layout, the sole
frames, the centre of mass, the centroidal momentum, the mass matrix, the
nonlinear effects and the contact Jacobians.

Layout: q = (base position [m], base quaternion (x, y, z, w), joint angles [rad]),
v = (base linear velocity [m/s] and angular velocity [rad/s] in the base frame,
joint velocities [rad/s]); ``joint_names`` orders the joint part.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
import pinocchio
from numpy.typing import NDArray

from robots.description import RobotDescription
from robots.urdf_cache import derived_urdf

FEET = ("left", "right")


def yaw_of(rotation: NDArray[np.float64]) -> float:
    """Yaw [rad] of a frame with ``rotation`` (3x3): the heading of its x axis about the
    world's vertical, counter-clockwise from the world's x."""
    return float(np.arctan2(rotation[1, 0], rotation[0, 0]))


class RobotModel:
    """pinocchio model and data of the robot with a floating base.

    Attributes:
        model: The pinocchio model.
        data: Its data (updated by :meth:`update`).
        joint_names: Actuated joints in the order of ``q[7:]`` and ``v[6:]``.
        mass: Total mass [kg].
        sole_offset: Sole frame origin in the ankle link frame [m], shape (3,).
    """

    def __init__(self, description: RobotDescription) -> None:
        urdf = derived_urdf(description, merged=True)
        self.model = pinocchio.buildModelFromUrdf(str(urdf), pinocchio.JointModelFreeFlyer())
        self.data = self.model.createData()
        self._scratch = self.model.createData()  # for kinematics at other configurations
        self.joint_names = [self.model.names[i] for i in range(2, self.model.njoints)]
        self.mass = float(sum(inertia.mass for inertia in self.model.inertias))
        self.sole_offset = np.asarray(description.sole_offset, float)
        self._ankle_frames = {
            foot: self.model.getFrameId(description.ankle_link(foot)) for foot in FEET
        }
        self.effort_limits = np.asarray(self.model.effortLimit[6:], float).copy()
        # The two joints nearest each sole (ankle pitch and roll on G1 and Talos): (pitch, roll).
        self._ankle_pairs = []
        for frame in self._ankle_frames.values():
            joint = self.model.frames[frame].parentJoint
            self._ankle_pairs.append(
                (self.model.names[self.model.parents[joint]], self.model.names[joint])
            )
        self._ankle_joints = {name for pair in self._ankle_pairs for name in pair}
        self.q = pinocchio.neutral(self.model)
        self.v = np.zeros(self.model.nv)

    @property
    def nv(self) -> int:
        return int(self.model.nv)

    def is_ankle(self, joint: str) -> bool:
        """Whether ``joint`` is one of the two joints nearest a sole."""
        return joint in self._ankle_joints

    def ankle_effort_limits(self) -> tuple[float, float]:
        """Effort limits [N m] of the ankles' roll and pitch joints (the two nearest each
        sole), the smaller of the two feet's."""
        limit = dict(zip(self.joint_names, self.effort_limits.tolist(), strict=True))
        return (
            min(limit[roll] for _, roll in self._ankle_pairs),
            min(limit[pitch] for pitch, _ in self._ankle_pairs),
        )

    def index_of(self, names: Sequence[str]) -> NDArray[np.intp]:
        """Positions in ``joint_names`` of each of ``names``."""
        return np.array([self.joint_names.index(name) for name in names], dtype=np.intp)

    def update(self, q: NDArray[np.float64], v: NDArray[np.float64]) -> None:
        """Set the state and compute kinematics, frames, CoM and its velocity."""
        self.q, self.v = q, v
        model, data = self.model, self.data
        pinocchio.forwardKinematics(model, data, q, v)
        pinocchio.updateFramePlacements(model, data)
        pinocchio.centerOfMass(model, data, q, v, False)
        pinocchio.computeJointJacobians(model, data, q)

    @property
    def com(self) -> NDArray[np.float64]:
        """Centre of mass in the world [m], shape (3,) (after :meth:`update`)."""
        return np.asarray(self.data.com[0], float).copy()

    @property
    def com_velocity(self) -> NDArray[np.float64]:
        """CoM velocity in the world [m/s], shape (3,) (after :meth:`update`)."""
        return np.asarray(self.data.vcom[0], float).copy()

    def ankle_frame(self, foot: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s ankle link (after :meth:`update`)."""
        placement = self.data.oMf[self._ankle_frames[foot]]
        return np.asarray(placement.translation, float), np.asarray(placement.rotation, float)

    def sole_frame(self, foot: str) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """World position [m] and rotation of ``foot``'s sole frame (after :meth:`update`)."""
        origin, rotation = self.ankle_frame(foot)
        return origin + rotation @ self.sole_offset, rotation

    def sole_positions_at(self, q: NDArray[np.float64]) -> dict[str, NDArray[np.float64]]:
        """World position [m] of each foot's sole frame at the configuration ``q`` (the
        state of :meth:`update` is left as it is)."""
        data = self._scratch
        pinocchio.forwardKinematics(self.model, data, q)
        positions = {}
        for foot, frame in self._ankle_frames.items():
            placement = pinocchio.updateFramePlacement(self.model, data, frame)
            origin = np.asarray(placement.translation, float)
            rotation = np.asarray(placement.rotation, float)
            positions[foot] = origin + rotation @ self.sole_offset
        return positions

    def centroidal_angular_momentum(self) -> NDArray[np.float64]:
        """Angular momentum about the CoM [N m s], shape (3,), of the current state."""
        pinocchio.computeCentroidalMomentum(self.model, self.data, self.q, self.v)
        return np.asarray(self.data.hg.angular, float).copy()

    def mass_matrix(self) -> NDArray[np.float64]:
        """Joint-space inertia M(q) [kg m^2 / kg], shape (nv, nv), symmetric."""
        upper = pinocchio.crba(self.model, self.data, self.q)
        return np.triu(upper) + np.triu(upper, 1).T

    def inverse_dynamics(self, acceleration: NDArray[np.float64]) -> NDArray[np.float64]:
        """M(q) a + C(q, v) v + g(q) [N, N m], shape (nv,) (RNEA), base rows first."""
        return np.asarray(
            pinocchio.rnea(self.model, self.data, self.q, self.v, acceleration), float
        ).copy()

    def wrench_generalized_force(
        self, foot: str, point: NDArray[np.float64], wrench: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """J^T w [N, N m], shape (nv,): generalised force of a contact wrench on ``foot``.

        Args:
            foot: The foot the wrench acts on.
            point: Point where ``wrench`` is taken [m], shape (3,).
            wrench: Force [N] and moment about ``point`` [N m], world axes, shape (6,).
        """
        frame = self._ankle_frames[foot]
        jacobian = pinocchio.getFrameJacobian(
            self.model, self.data, frame, pinocchio.LOCAL_WORLD_ALIGNED
        )
        origin = self.data.oMf[frame].translation
        force = wrench[:3]
        arm = point - origin
        moment = wrench[3:] + np.array(
            [
                arm[1] * force[2] - arm[2] * force[1],
                arm[2] * force[0] - arm[0] * force[2],
                arm[0] * force[1] - arm[1] * force[0],
            ]
        )
        return jacobian.T @ np.concatenate([force, moment])

    def foot_jacobian(self, foot: str) -> NDArray[np.float64]:
        """6 x nv Jacobian of ``foot``'s ankle frame, world-aligned axes at its origin."""
        return np.asarray(
            pinocchio.getFrameJacobian(
                self.model, self.data, self._ankle_frames[foot], pinocchio.LOCAL_WORLD_ALIGNED
            ),
            float,
        )
