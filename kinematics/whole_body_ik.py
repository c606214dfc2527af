"""Whole-body inverse kinematics of a biped with placo.

The IK keeps its own kinematic model (floating base + joints) in the world frame
of the simulation and moves it, once per control tick, so that:

* the stance soles follow their poses (soft, a hundred times the swing sole's weight);
* the swing sole follows its pose (soft, high weight);
* the CoM follows the target [m] (soft, high weight);
* the trunk and the pelvis stay upright with the feet's mean yaw (soft);
* the joints stay near the standing posture (soft, low weight), within limits;
* the knees stay bent by at least ``KNEE_MARGIN``: a straight knee is a singularity of
  the legs' Jacobian, where the QP's step flips between ticks (after a wide step on
  G1, a knee target jumped by up to 2.3 rad from one 10 ms tick to the next);
* the joints the plan does not move (neither a leg's, nor the flywheel's, nor locked:
  Talos's torso, arms and head) hold their standing angles (soft, the trunk's
  weight), so the IK does not swing the arms to move the CoM;
* the description's ``locked_joints`` stay at their standing angle (masked: the
  physics URDF has them welded, :mod:`robots.urdf_merge`);
* optionally (``upper_body=True``), the description's ``upper_body_joints`` follow
  their standing angles plus offsets given at each solve (soft, the trunk's
  weight, in place of the trunk orientation task): the upper body turns as a
  flywheel (:mod:`kinematics.upper_body`) while the CoM task keeps the CoM where
  the plan wants it.

Every task is soft and each step is damped as in the Levenberg-Marquardt method
(Sugihara, "Solvability-unconcerned inverse kinematics by the Levenberg-Marquardt
method", IEEE T-RO 2011), so that targets out of the legs' reach (a wide catching step,
a stance sole slipped outwards) give the nearest posture rather than a jump. The damping
weighs the joints' step in proportion to the feet's and the CoM's weighted squared error,
as there, but the error the last step left rather than the present one: what persists
from one solve to the next is the part out of reach, while targets that merely move (a
settling sole, the CoM) are tracked undamped (damped by the present error, a sole moving
1 cm a tick left the CoM height lagging, and it caught up in one 0.2 rad step). With the
stance soles as hard tasks, placo's linearised step at the legs' reach (the knees at
their margin, the ankle rolls at their limits) left the soles up to 37 cm off their targets
and moved joint targets by up to 92 deg in one tick; soft but undamped, joint targets
still jumped by radians a tick past the reach (docs/notes/2026-12-07-ik-at-the-legs-reach.md).

Its output is the joint target vector of the joint motors' PD law.
After each solve, :attr:`WholeBodyIK.angular_momentum` holds the centroidal
angular momentum of the motion from the previous solution to this one [N m s]
(the backend's CoM plan accounts for its rate: on G1 it shifts the CoP by up to
4-5 cm at swing lift-off).
The model is never reset from measurements: the closed loop goes through the CoM
target, which the caller computes from the measured state.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from typing import Any, Literal

import numpy as np
import pinocchio
import placo
from numpy.typing import NDArray

from kinematics.native_output import native_output_silenced
from planner.exceptions import ParameterError, RsgError
from robots.description import RobotDescription
from robots.urdf_cache import FOOT_FRAMES, TRUNK_FRAME, derived_urdf

Support = Literal["left", "right", "both"]


class IkInfeasibleError(RsgError):
    """placo's QP returned no joint motion (none within the joint limits, or NaN).

    Attributes:
        support: The feet the IK stood on.
        com_target: Horizontal CoM target of that solve [m].
        reason: placo's message.
    """

    def __init__(self, support: str, com_target: NDArray[np.float64], reason: str) -> None:
        self.support = support
        self.com_target = com_target
        self.reason = reason
        super().__init__(
            f"whole-body IK infeasible with support {support!r} and CoM target "
            f"{np.round(com_target, 3).tolist()} m: {reason}"
        )

    def __reduce__(self) -> tuple[Any, ...]:
        return (type(self), (self.support, self.com_target, self.reason))


FOOT_WEIGHT = 1000.0  # soft swing-foot task weight [-]
STANCE_WEIGHT = 1e5  # stance-foot task weight [-], above every other task's
COM_WEIGHT = 100.0  # CoM task weight [-]
TRUNK_WEIGHT = 10.0  # trunk and pelvis orientation weight [-]
POSTURE_WEIGHT = 1e-2  # joint posture regularisation weight [-]
# [-] the damping's weight per unit of the error left by the last step: the least of 1, 2 and
# 4 at which the joints do not chatter with the soles beyond the legs' reach (at 2, Talos's
# moved more than 5 deg in 9 ticks)
DAMPING_GAIN = 4.0
KNEE_MARGIN = 0.3  # [rad] least knee bend (0.2 rad still let a knee target flip)


def kinematic_urdf_text(description: RobotDescription) -> str:
    """The derived URDF without visual/collision geometry (fast to load for IK)."""
    root = ET.parse(derived_urdf(description)).getroot()
    for link in root.iter("link"):
        for tag in ("visual", "collision"):
            for element in link.findall(tag):
                link.remove(element)
    return ET.tostring(root, encoding="unicode")


def humanoid_robot(description: RobotDescription) -> Any:
    """placo's ``HumanoidRobot`` of the robot (kinematic URDF, no collisions).

    Its constructor's warnings about Sigmaban-only frames are silenced
    (:mod:`kinematics.native_output`).
    """
    text = kinematic_urdf_text(description)
    with native_output_silenced():
        return placo.HumanoidRobot("", placo.Flags.ignore_collisions, text)


def leg_joints(model: Any) -> dict[str, list[str]]:
    """The legs' joints of a pinocchio ``model``: ``"left"`` and ``"right"``, each leg's
    joints from the floating base to its sole's link; ``"chains"``, both legs; and
    ``"knees"``, the joint above each ankle's two (the two joints nearest the sole, as in
    :class:`kinematics.robot_model.RobotModel`)."""
    legs: dict[str, list[str]] = {}
    knees: list[str] = []
    for foot, frame in FOOT_FRAMES.items():
        joint = model.frames[model.getFrameId(frame)].parentJoint
        legs[foot] = [model.names[k] for k in model.supports[joint] if k > 1]
        knees.append(model.names[model.parents[model.parents[joint]]])
    return {**legs, "chains": [name for leg in legs.values() for name in leg], "knees": knees}


def yaw_rotation(yaw: float) -> NDArray[np.float64]:
    """Rotation matrix about the world z axis by ``yaw`` [rad]."""
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def sole_pose(position: NDArray[np.float64], yaw: float = 0.0) -> NDArray[np.float64]:
    """Homogeneous 4x4 pose of a flat sole at ``position`` (3,) [m] and ``yaw`` [rad]."""
    pose = np.eye(4)
    pose[:3, :3] = yaw_rotation(yaw)
    pose[:3, 3] = position
    return pose


class WholeBodyIK:
    """placo kinematics solver tracking feet, CoM, trunk and posture targets.

    Attributes:
        joint_names: Actuated joint names, in the order of :meth:`solve`'s output.
        robot: The placo model (its state is the last IK solution).
        angular_momentum: Centroidal angular momentum [N m s], shape (3,), of the
            motion of the last :meth:`solve` (finite difference over its ``dt``).
        held_joints: Joints held at their standing angles: neither a leg's, nor the
            flywheel's, nor locked.
    """

    def __init__(
        self,
        description: RobotDescription,
        upper_body: bool = False,
    ) -> None:
        """Build the model and the tasks.

        Args:
            description: The robot.
            upper_body: Replace the trunk orientation task by a joint task on the
                description's ``upper_body_joints``, fed by :meth:`solve`'s
                ``upper_body_offsets``.
        """
        self.description = description
        self.robot = humanoid_robot(description)
        self.joint_names: list[str] = list(self.robot.joint_names())
        model = self.robot.model  # each joint's angle in the configuration vector
        self._q_index = np.array([model.idx_qs[model.getJointId(n)] for n in self.joint_names])
        unknown = set(description.standing_posture) - set(self.joint_names)
        if unknown:
            raise ParameterError("standing_posture", sorted(unknown), "joints of the URDF")
        self.solver = placo.KinematicsSolver(self.robot)
        self.solver.mask_fbase(False)
        not_joints = sorted(set(description.locked_joints) - set(self.joint_names))
        if not_joints:
            raise ParameterError("locked_joints", not_joints, "joints of the URDF")
        for name in description.locked_joints:
            self.solver.mask_dof(name)
        self.solver.enable_joint_limits(True)
        self.solver.enable_velocity_limits(False)
        legs = leg_joints(self.robot.model)
        for knee in legs["knees"]:
            lower, upper = self.robot.get_joint_limits(knee)
            self.robot.set_joint_limits(knee, max(float(lower), KNEE_MARGIN), float(upper))

        self.foot_tasks = {
            foot: self.solver.add_frame_task(frame, np.eye(4))
            for foot, frame in FOOT_FRAMES.items()
        }
        self.com_task = self.solver.add_com_task(np.zeros(3))
        self.com_task.configure("com", "soft", COM_WEIGHT)
        self.upper_body_joints = list(description.upper_body_joints) if upper_body else []
        if upper_body and not self.upper_body_joints:
            raise ParameterError(
                "upper_body_joints", [], f"at least one joint in {description.name}'s description"
            )
        self.trunk_task = None
        self.upper_body_task = None
        if self.upper_body_joints:
            self.upper_body_task = self.solver.add_joints_task()
            self.upper_body_task.configure("upper_body", "soft", TRUNK_WEIGHT)
        else:
            self.trunk_task = self.solver.add_orientation_task(TRUNK_FRAME, np.eye(3))
            self.trunk_task.configure("trunk", "soft", TRUNK_WEIGHT)
        self.pelvis_task = self.solver.add_orientation_task(description.base_link, np.eye(3))
        self.pelvis_task.configure("pelvis", "soft", TRUNK_WEIGHT)
        standing = self.standing_posture()
        moved = set(legs["chains"]) | set(self.upper_body_joints) | set(description.locked_joints)
        self.held_joints = [name for name in self.joint_names if name not in moved]
        if self.held_joints:  # the solver owns the task; its targets never change
            held_task = self.solver.add_joints_task()
            held_task.set_joints({name: standing[name] for name in self.held_joints})
            held_task.configure("held", "soft", TRUNK_WEIGHT)
        # Levenberg-Marquardt damping: a joints task on the present angles (see solve)
        self.damping_task = self.solver.add_joints_task()
        self.damping_task.configure("damping", "soft", 0.0)
        self.posture_task = self.solver.add_joints_task()
        self.posture_task.set_joints(standing)
        self.posture_task.configure("posture", "soft", POSTURE_WEIGHT)
        self.upper_body_posture = np.array([standing[name] for name in self.upper_body_joints])
        self._support: Support | None = None
        self._residual = 0.0  # [-] task_error after the last solve
        self._previous_q: NDArray[np.float64] | None = None
        self.angular_momentum = np.zeros(3)

    def standing_posture(self) -> dict[str, float]:
        """Joint name -> standing angle [rad] for every actuated joint."""
        return {name: self.description.standing_posture.get(name, 0.0) for name in self.joint_names}

    def _configure_support(self, support: Support) -> None:
        if support == self._support:
            return
        for foot, task in self.foot_tasks.items():
            weight = _foot_weight(foot, support)
            task.configure(f"{foot}_foot", "soft", weight, weight)
        self._support = support

    def reset(
        self,
        left_sole: NDArray[np.float64],
        right_sole: NDArray[np.float64],
        com_xy: NDArray[np.float64],
        iterations: int = 50,
    ) -> NDArray[np.float64]:
        """Start from the standing posture and converge on the given targets.

        Args:
            left_sole: Left sole pose, 4x4 homogeneous [m].
            right_sole: Right sole pose, 4x4 homogeneous [m].
            com_xy: Horizontal CoM target [m], shape (2,).
            iterations: Solver iterations.

        Returns:
            Joint angles [rad] in :attr:`joint_names` order.
        """
        self.robot.reset()
        for name, angle in self.standing_posture().items():
            self.robot.set_joint(name, angle)
        base = np.eye(4)
        base[:3, 3] = [*np.asarray(com_xy, float), self.description.com_height + 0.1]
        self.robot.set_T_world_fbase(base)
        self.robot.update_kinematics()
        # Both feet at the swing sole's weight while converging from the initial guess.
        for foot, task in self.foot_tasks.items():
            task.configure(f"{foot}_foot", "soft", FOOT_WEIGHT, FOOT_WEIGHT)
        self._support = None
        self.angular_momentum = np.zeros(3)
        self._residual = 0.0
        self.damping_task.configure("damping", "soft", 0.0)  # converging from afar: undamped
        self.solver.dt = 0.01
        for _ in range(iterations):
            self._set_targets(com_xy, left_sole, right_sole)
            self.solver.solve(True)
            self.robot.update_kinematics()
        return self.joint_angles()

    def _set_targets(
        self,
        com_xy: NDArray[np.float64],
        left_sole: NDArray[np.float64],
        right_sole: NDArray[np.float64],
        upper_body_offsets: NDArray[np.float64] | None = None,
    ) -> None:
        self.foot_tasks["left"].T_world_frame = left_sole
        self.foot_tasks["right"].T_world_frame = right_sole
        self.com_task.target_world = np.array(
            [com_xy[0], com_xy[1], self.com_z_target(left_sole, right_sole)]
        )
        yaw = _mean_yaw(left_sole, right_sole)
        if self.trunk_task is not None:
            self.trunk_task.R_world_frame = yaw_rotation(yaw)
        if self.upper_body_task is not None:
            angles = self.upper_body_posture
            if upper_body_offsets is not None:
                angles = angles + np.asarray(upper_body_offsets, float)
            self.upper_body_task.set_joints(dict(zip(self.upper_body_joints, angles, strict=True)))
        self.pelvis_task.R_world_frame = yaw_rotation(yaw)

    def com_z_target(
        self, left_sole: NDArray[np.float64], right_sole: NDArray[np.float64]
    ) -> float:
        """CoM height target [m]: nominal height above the lower sole."""
        return min(left_sole[2, 3], right_sole[2, 3]) + self.description.com_height

    def solve(
        self,
        com_xy: NDArray[np.float64],
        left_sole: NDArray[np.float64],
        right_sole: NDArray[np.float64],
        support: Support,
        dt: float,
        upper_body_offsets: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """One IK step toward the targets.

        Args:
            com_xy: Horizontal CoM target in the world [m], shape (2,).
            left_sole: Left sole pose, 4x4 homogeneous [m].
            right_sole: Right sole pose, 4x4 homogeneous [m].
            support: Feet on the ground (their tasks weigh ``STANCE_WEIGHT``).
            dt: Time since the previous solve [s].
            upper_body_offsets: Offsets [rad] of :attr:`upper_body_joints` from
                their standing angles, used when ``upper_body`` is enabled.

        Returns:
            Joint angles [rad] in :attr:`joint_names` order.

        Raises:
            IkInfeasibleError: placo's QP returned no solution (the robot's
                configuration is left as before the call).
        """
        if support not in ("left", "right", "both"):
            raise ParameterError("support", support, "'left', 'right' or 'both'")
        self._configure_support(support)
        self.solver.dt = dt
        self._set_targets(com_xy, left_sole, right_sole, upper_body_offsets)
        previous = np.array(self.robot.state.q, dtype=float)
        self.damping_task.set_joints(dict(zip(self.joint_names, self.joint_angles(), strict=True)))
        self.damping_task.configure("damping", "soft", DAMPING_GAIN * self._residual)
        try:
            self.solver.solve(True)
        except RuntimeError as error:  # placo's QP: no motion within the limits, or NaN
            self.robot.state.q = previous
            self.robot.update_kinematics()
            raise IkInfeasibleError(support, np.asarray(com_xy, float), str(error)) from error
        self.robot.update_kinematics()
        self._residual = self.task_error(left_sole, right_sole, support)
        velocity = pinocchio.difference(self.robot.model, previous, self.robot.state.q) / dt
        self.angular_momentum = (np.asarray(self.robot.centroidal_map()) @ velocity)[3:6]
        return self.joint_angles()

    def task_error(
        self, left_sole: NDArray[np.float64], right_sole: NDArray[np.float64], support: Support
    ) -> float:
        """Weighted squared error of the feet's and the CoM's tasks at the present
        configuration, as the QP weighs them [-]."""
        error = COM_WEIGHT * float(np.sum((self.com_world() - self.com_task.target_world) ** 2))
        for foot, target in (("left", left_sole), ("right", right_sole)):
            weight = _foot_weight(foot, support)
            pose = self.sole_world(foot)
            rotation = pinocchio.log3(target[:3, :3].T @ pose[:3, :3])
            error += weight * float(
                np.sum((pose[:3, 3] - target[:3, 3]) ** 2) + np.sum(rotation**2)
            )
        return error

    def joint_angles(self) -> NDArray[np.float64]:
        """Current IK joint angles [rad] in :attr:`joint_names` order."""
        return np.asarray(self.robot.state.q, dtype=float)[self._q_index]

    def com_world(self) -> NDArray[np.float64]:
        """CoM of the IK model in the world [m], shape (3,)."""
        return np.asarray(self.robot.com_world(), dtype=float)

    def sole_world(self, foot: str) -> NDArray[np.float64]:
        """Pose 4x4 of the IK model's ``foot`` sole in the world [m]."""
        return np.asarray(self.robot.get_T_world_frame(FOOT_FRAMES[foot]), dtype=float)


def _foot_weight(foot: str, support: Support) -> float:
    """The weight [-] of ``foot``'s task when the IK stands on ``support``."""
    return STANCE_WEIGHT if support in (foot, "both") else FOOT_WEIGHT


def _mean_yaw(left_sole: NDArray[np.float64], right_sole: NDArray[np.float64]) -> float:
    """Yaw [rad] of the mean of the two soles' x axes."""
    axis = left_sole[:3, 0] + right_sole[:3, 0]
    return float(np.arctan2(axis[1], axis[0]))
