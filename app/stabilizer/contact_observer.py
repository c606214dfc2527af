"""Contact forces of the feet from the joint torques: a generalized-momentum observer.

The Unitree G1 has no foot force sensors; its low level gives, per motor, the angle,
the velocity and an estimated torque. The external forces on the robot, here the
ground's on the feet, are what its momentum does not owe to the motors and gravity.
With the generalized momentum p = M(q) v, the floating-base dynamics

    M vdot + C v + g = S^T tau + sum_feet J_foot^T w_foot

give (with Mdot = C + C^T, which pinocchio's Coriolis matrix satisfies)

    pdot = S^T tau + C^T v - g + J^T w,

and the observer's residual r (shape (nv,)),

    r(t) = K (p(t) - p(0) - int_0^t (S^T tau + C^T v - g + r) ds),

is a first-order low pass of bandwidth K [1/s] of the external generalized force J^T w:
rdot = K (J^T w - r), with no acceleration measured (De Luca and Mattone, "Sensorless
robot collision detection and isolation", ICRA 2005; for the feet of a legged robot,
Bledt et al., "Contact model fusion for event-based locomotion in unstructured
terrains", ICRA 2018).

Discrete form, at the period dt of the calls: the integral advances by the trapezoid of
C^T v - g at the last and the current sample, the torques applied over the period and
the last residual; the gain is (1 - exp(-K dt)) / dt instead of K, the exact
zero-order-hold discretisation of the low pass, so the residual reaches 1 - 1/e of a
step at 1/K at any dt (with K itself, forward Euler, it would reach 50 % after one
10 ms period at K = 50 /s instead of 39 %, and diverge beyond K dt = 2).

Each foot's wrench (force [N] and moment [N m] at its ankle frame's origin, world axes)
comes from the residual's rows of its leg's joints, which no other contact moves:
J_leg^T w = r_leg, J_leg the foot Jacobian's columns of those joints (6 x 6 on G1 and
Talos), solved by least squares with small singular values cut (near a straight knee
the leg carries a force along itself with no joint torque: that part is not observable).
The base's linear rows give the total external force (in the base frame: rotated to the
world), a check on the sum of the feet.

What the observer cannot tell from a contact: any joint torque it is not given (the
motors' friction, when ``tau_est`` leaves it out; a joint at its limit) and any error of
the model's masses, both read as forces on the feet; and a change faster than 1/K.

M(q) v (by RNEA), C, g and the Jacobians are computed in the observer's own pinocchio
``Data``: the shared ``model.data`` (the controller's state) is not touched.
"""

from __future__ import annotations

from collections.abc import Mapping

import numpy as np
import pinocchio
from numpy.typing import NDArray

from kinematics.robot_model import RobotModel
from planner.exceptions import ParameterError

# Singular values of a leg's Jacobian below this fraction of its largest are cut in the
# least-squares solve: only a leg near straight has one (G1 standing: 5 % of the largest).
RCOND = 1e-3  # [-]


class ContactForceObserver:
    """Estimated contact wrench of each foot from joint torques (module docstring).

    Args:
        model: The robot's rigid-body model (its ``data`` is left untouched).
        legs: Foot -> positions of its leg's joints in ``model.joint_names``.
        bandwidth: The observer's gain K [1/s]: its residual follows the external
            force as a first-order lag of time constant 1 / K.

    Raises:
        ParameterError: ``bandwidth`` not a finite number > 0, or a leg not a chain of
            joints ending at its foot.
    """

    def __init__(
        self, model: RobotModel, legs: Mapping[str, NDArray[np.intp]], bandwidth: float = 50.0
    ) -> None:
        if isinstance(bandwidth, bool) or not (
            isinstance(bandwidth, int | float) and np.isfinite(bandwidth) and bandwidth > 0.0
        ):
            raise ParameterError("bandwidth", bandwidth, "a finite number > 0 [1/s]")
        self.model = model
        self.bandwidth = float(bandwidth)
        pin_model = model.model
        self._data = pin_model.createData()  # ours: model.data is the controller's state
        self._legs = {foot: np.asarray(index, dtype=np.intp) for foot, index in legs.items()}
        self._rows = {foot: 6 + index for foot, index in self._legs.items()}  # rows in v
        self._frames = {foot: self._ankle_frame(foot) for foot in self._legs}
        nv = int(pin_model.nv)
        self._nv = nv
        self._zero = np.zeros(nv)
        self._momentum = np.zeros(nv)
        self._state_term = np.zeros(nv)
        self._residual = np.zeros(nv)
        self._base_rotation = np.eye(3)
        self._wrenches = {foot: np.zeros(6) for foot in self._legs}
        self._started = False

    def _ankle_frame(self, foot: str) -> int:
        """pinocchio frame of ``foot``'s ankle link: the body after its leg's last joint."""
        pin_model = self.model.model
        names = [self.model.joint_names[i] for i in self._legs[foot]]
        joints = [pin_model.getJointId(name) for name in names]
        # Depth-first numbering: the last joint of a chain has the largest id.
        last = max(joints, default=0)
        if not names or not set(joints) <= set(pin_model.supports[last]):
            raise ParameterError(f"legs[{foot}]", names, "the joints of one chain to the foot")
        for index, frame in enumerate(pin_model.frames):
            if frame.parentJoint == last and frame.type == pinocchio.FrameType.BODY:
                return index
        raise ParameterError(f"legs[{foot}]", names, "a chain ending at a link")

    def reset(self, q: NDArray[np.float64], v: NDArray[np.float64]) -> None:
        """Start at the state (q, v): p_0 = M(q) v, residual and wrenches zero."""
        self._momentum, self._state_term = self._dynamics(q, v)
        self._residual = np.zeros(self._nv)
        self._wrenches = {foot: np.zeros(6) for foot in self._legs}
        self._started = True

    def update(
        self,
        q: NDArray[np.float64],
        v: NDArray[np.float64],
        joint_torques: NDArray[np.float64],
        dt: float,
    ) -> dict[str, float]:
        """Advance the observer to the state (q, v), ``dt`` [s] after the last call.

        Args:
            q: Configuration, the model's layout.
            v: Velocity, the model's layout (base velocities in the base frame).
            joint_torques: Torques [N m] the motors applied over the last ``dt``, in
                ``model.joint_names`` order (on G1 the low level's estimated torques).
            dt: Time since the last call or :meth:`reset` [s].

        Returns:
            Foot -> estimated normal (world vertical) force [N], >= 0.

        Raises:
            ParameterError: Called before :meth:`reset`, or ``dt`` not > 0.
        """
        if not self._started:
            raise ParameterError("contact observer", "not reset", "reset() before update()")
        if not (np.isfinite(dt) and dt > 0.0):
            raise ParameterError("dt", dt, "a finite number > 0 [s]")
        momentum, state_term = self._dynamics(q, v)
        predicted = 0.5 * (self._state_term + state_term)  # trapezoid of C^T v - g
        predicted[6:] += joint_torques  # S^T tau
        gain = -np.expm1(-self.bandwidth * dt) / dt  # [1/s], K at small K dt
        self._residual += gain * (momentum - self._momentum - (predicted + self._residual) * dt)
        self._momentum, self._state_term = momentum, state_term

        data, pin_model = self._data, self.model.model
        pinocchio.computeJointJacobians(pin_model, data, q)  # and the placements at q
        self._base_rotation = np.asarray(data.oMi[1].rotation, float)
        forces = {}
        for foot, frame in self._frames.items():
            jacobian = pinocchio.getFrameJacobian(
                pin_model, data, frame, pinocchio.LOCAL_WORLD_ALIGNED
            )
            leg = jacobian[:, self._rows[foot]]
            wrench = np.linalg.lstsq(leg.T, self._residual[self._rows[foot]], rcond=RCOND)[0]
            self._wrenches[foot] = wrench
            forces[foot] = max(float(wrench[2]), 0.0)
        return forces

    def _dynamics(
        self, q: NDArray[np.float64], v: NDArray[np.float64]
    ) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
        """Generalized momentum M(q) v and C(q, v)^T v - g(q), shape (nv,) each."""
        pin_model, data = self.model.model, self._data
        gravity = pinocchio.computeGeneralizedGravity(pin_model, data, q)
        # RNEA at zero velocity with v as the acceleration: M(q) v + g(q), cheaper than crba.
        momentum = pinocchio.rnea(pin_model, data, q, self._zero, v) - gravity
        coriolis = pinocchio.computeCoriolisMatrix(pin_model, data, q, v)
        return momentum, coriolis.T @ v - gravity

    @property
    def wrenches(self) -> dict[str, NDArray[np.float64]]:
        """Foot -> last estimated wrench, shape (6,): force [N] and moment [N m] at its
        ankle frame's origin, world axes."""
        return {foot: wrench.copy() for foot, wrench in self._wrenches.items()}

    @property
    def total_vertical_force(self) -> float:
        """Vertical external force on the robot [N] from the base's linear rows (in the
        base frame in pinocchio's free-flyer, rotated to the world)."""
        return float(self._base_rotation[2] @ self._residual[:3])
