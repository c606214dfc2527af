"""The upper body as a bounded flywheel: joint offsets that carry an angular momentum.

The planner commands a rate of change of centroidal angular momentum hdot [N m].
A robot realises it by turning its upper body, and only so far: the torso and the
arms have a range of motion, so the angular momentum they can hold is bounded.
This module turns an angular momentum target h* [N m s] into joint velocities of
the upper-body joints (waist yaw, roll and pitch, shoulder pitch and roll on G1) and
integrates them into offsets added to the whole-body IK's joint targets.

Each call, with A the angular rows (x, y, z) of the centroidal momentum matrix
restricted to the upper-body joints (from the IK model at its current
configuration),

    qd = A^T (A A^T + lambda I)^-1 h* - offsets / return_time,

clipped so that every offset stays within ``max_offset`` of the standing posture
and within the joint limits. The second term brings the upper body back to its
posture once h* is zero again. The angular momentum of the offsets' motion,
A qd [N m s], is returned so the caller's CoM plan accounts for its rate like
that of any other motion (the CoP then stays where the planner put its ZMP while
the upper body supplies hdot).

Which part of hdot the upper body carries (:meth:`UpperBodyFlywheel.follow_rate`):
a flywheel cannot hold a steady rate (its angle would run away), and the planner's
hdot has one (its feedback on a steady DCM error, a few tenths of N m in nominal
walking). So the target is the band-passed integral of hdot,

    b' = (hdot - b) / T_r,      h*' = hdot - b - h* / T_r,      |h*| <= h_max,

with T_r = ``return_time``: the low-passed part b and whatever exceeds the bound
stay with the CoP (the caller's CoM plan keeps them as a CMP shift), the rest is
carried by the torso and the arms.

The upper body also takes back a share ``cancel`` of the high-passed angular momentum
of the rest of the motion (the legs' swing), about all three axes. About z the planner
commands nothing, so there the target is only that share: the waist and the arms turn
against a swinging leg, as in Kajita et al., "Resolved momentum control: humanoid motion
planning based on the linear and angular momentum" (IROS 2003), which keeps the whole
body's angular momentum about z near zero. Otherwise the stance sole's friction has to
hold the leg's yaw moment: after a fast outward step on G1 the stance foot turned 5 deg
about z and the swing sole landed 4.5 cm off its target
(docs/notes/2026-12-05-yaw-momentum.md).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError


class UpperBodyFlywheel:
    """Upper-body joint offsets that realise an angular momentum target.

    Args:
        robot: placo ``RobotWrapper`` of the IK model (its centroidal map and joint
            velocity indices are used).
        joints: Names of the upper-body joints that carry the momentum.
        posture: Standing angles of ``joints`` [rad], from which the offsets count.
        max_offset: Largest offset from the standing posture per joint [rad].
        return_time: T_r, time constant [s] of the band-pass on hdot and of the
            offsets' return to zero.
        max_momentum: h_max, bound on the carried angular momentum [N m s].
        cancel: c, fraction of the high-passed angular momentum of the rest of the
            motion (the legs' swing) the upper body takes back, about x, y and z (see
            :meth:`follow_rate`).
        damping: lambda of the damped pseudo-inverse [(kg m^2)^2].
    """

    def __init__(
        self,
        robot,  # noqa: ANN001 (placo.RobotWrapper)
        joints: Sequence[str],
        posture: NDArray[np.float64],
        max_offset: float = 0.4,
        return_time: float = 0.5,
        max_momentum: float = 1.0,
        cancel: float = 0.0,
        damping: float = 1e-4,
    ) -> None:
        if not joints:
            raise ParameterError("upper_body_joints", list(joints), "at least one joint")
        unknown = [name for name in joints if name not in list(robot.joint_names())]
        if unknown:
            raise ParameterError("upper_body_joints", unknown, "joints of the URDF")
        if not 0.0 < max_offset <= 1.5:
            raise ParameterError("max_offset", max_offset, "in (0, 1.5] rad")
        if not return_time > 0.0:
            raise ParameterError("return_time", return_time, "> 0 s")
        if not 0.0 < max_momentum <= 10.0:
            raise ParameterError("max_momentum", max_momentum, "in (0, 10] N m s")
        if not 0.0 <= cancel <= 1.0:
            raise ParameterError("cancel", cancel, "in [0, 1]")
        self.robot = robot
        self.joints = list(joints)
        self.max_offset = max_offset
        self.return_time = return_time
        self.max_momentum = max_momentum
        self.cancel = cancel
        self.damping = damping
        self._v_index = [robot.get_joint_v_offset(name) for name in self.joints]
        model = robot.model
        q_index = [model.joints[model.getJointId(name)].idx_q for name in self.joints]
        posture = np.asarray(posture, float)
        if posture.shape != (len(self.joints),):
            raise ParameterError("posture", posture.shape, f"one angle per joint, ({len(joints)},)")
        # Offset bounds [rad]: max_offset, within the joint limits.
        self._low = np.maximum(-max_offset, np.asarray(model.lowerPositionLimit)[q_index] - posture)
        self._high = np.minimum(max_offset, np.asarray(model.upperPositionLimit)[q_index] - posture)
        self.offsets = np.zeros(len(self.joints))
        self.momentum = np.zeros(3)  # of the offsets' last motion, x y z [N m s]
        self.target = np.zeros(2)  # h*, horizontal [N m s]
        self.steady_rate = np.zeros(2)  # b, the part of hdot left to the CoP [N m]
        self.steady_motion = np.zeros(3)  # low-passed momentum of the other motion [N m s]

    def reset(self) -> None:
        """Back to the standing posture, at rest."""
        self.offsets = np.zeros(len(self.joints))
        self.momentum = np.zeros(3)
        self.target = np.zeros(2)
        self.steady_rate = np.zeros(2)
        self.steady_motion = np.zeros(3)

    def follow_rate(
        self,
        rate: NDArray[np.float64],
        dt: float,
        motion_momentum: NDArray[np.float64] | None = None,
    ) -> NDArray[np.float64]:
        """Carry the band-passed part of a commanded hdot for ``dt``.

        Args:
            rate: Commanded horizontal hdot [N m], (2,).
            dt: Time step [s].
            motion_momentum: Angular momentum of the rest of the whole-body motion
                [N m s], (3,); with ``cancel`` > 0, that fraction of its
                high-passed part (time constant ``return_time``) is added with
                the opposite sign to what the upper body carries.

        Returns:
            The new offsets [rad] (see :meth:`update`); :attr:`target` is h*.
        """
        rate = np.asarray(rate, float)
        fraction = min(dt / self.return_time, 1.0)
        self.steady_rate += fraction * (rate - self.steady_rate)
        self.target += dt * (rate - self.steady_rate) - fraction * self.target
        np.clip(self.target, -self.max_momentum, self.max_momentum, out=self.target)
        wanted = np.array([*self.target, 0.0])  # hdot has no z part
        if self.cancel > 0.0 and motion_momentum is not None:
            motion = np.asarray(motion_momentum, float)
            self.steady_motion += fraction * (motion - self.steady_motion)
            wanted = np.clip(
                wanted - self.cancel * (motion - self.steady_motion),
                -self.max_momentum,
                self.max_momentum,
            )
        return self.update(wanted, dt)

    def update(self, target: NDArray[np.float64], dt: float) -> NDArray[np.float64]:
        """Move the offsets for ``dt`` toward carrying ``target``.

        Args:
            target: Angular momentum for the upper body [N m s], (3,): x, y, z.
            dt: Time step [s].

        Returns:
            The new offsets [rad], in :attr:`joints` order. :attr:`momentum` holds the
            angular momentum of the motion over ``dt`` [N m s].
        """
        if not dt > 0.0:
            raise ParameterError("dt", dt, "> 0 s")
        target = np.asarray(target, float)
        if target.shape != (3,):
            raise ParameterError("target", target.shape, "(3,): x, y, z [N m s]")
        centroidal = np.asarray(self.robot.centroidal_map(), float)
        a = centroidal[3:6, self._v_index]
        gram = a @ a.T + self.damping * np.eye(3)
        velocity = a.T @ np.linalg.solve(gram, target)
        velocity -= self.offsets / self.return_time
        new = np.clip(self.offsets + velocity * dt, self._low, self._high)
        self.momentum = a @ ((new - self.offsets) / dt)
        self.offsets = new
        return self.offsets
