"""The joint motors in simulation: the low level's PD law with feed-forward torque.

A real G1 motor evaluates tau = kp (q* - q) + kd (qd* - qd) + tau_ff (:mod:`app.lowlevel`)
in its driver at a far higher rate than the simulator's step. Evaluated explicitly
once per physics step (2 ms on G1) the same law is not the same system: G1's ankle
roll joint moves 0.4 g m^2 of foot, and kd dt / I = 10 there, so the explicit damping
term overshoots and the joint chatters (measured: 9 deg on a hung, static leg).
The motors therefore use the stable PD form of Tan, Liu and Turk ("Stable
Proportional-Derivative Controllers", IEEE CG&A 2011): the PD terms act on the state
at the end of the step, predicted with the robot's own dynamics,

    (M + kd dt) qdd = tau_ff + J^T f - h - kp (q + dt qd - q*) - kd (qd - qd*),
    tau = kp (q* - q - dt qd) + kd (qd* - qd) - kd dt qdd + tau_ff,

with M, h = C qd + g taken once per control tick, and J^T f the contact forces
expected over the tick. The prediction needs those forces; the simulated motors
take the whole-body controller's planned contact wrenches, the forces its
feed-forward torques are computed for (a simulation-only input: a real motor runs
the PD law continuously and needs no prediction). Measured on G1 (kd 20 N m s/rad
on the hips): with the diagonal of M alone the standing robot's stance leg went
unstable; predicted with zero contact force, with the last physics step's contact
forces, or with rigid contacts of the feet on the ground, the walk fell within
eight steps (at each weight transfer the forces change within the tick); with the
planned wrenches it walks.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from app.lowlevel import JointCommand
from kinematics.robot_model import RobotModel


class JointMotors:
    """Stable PD motors of every actuated joint, in the robot model's joint order.

    Args:
        model: The robot's rigid-body model (the simulator's masses and joints).
        time_step: Physics step [s].
    """

    def __init__(self, model: RobotModel, time_step: float) -> None:
        self.model = model
        self.time_step = time_step
        self.effort_limits = model.effort_limits
        count = len(model.joint_names)
        self._stiffness = np.zeros(model.nv)
        self._damping = np.zeros(model.nv)
        self._inverse = np.eye(model.nv)
        self._bias = np.zeros(model.nv)
        self._base_velocity = np.zeros(6)
        self.command = JointCommand(*(np.zeros(count) for _ in range(5)))
        self._start = np.zeros(count)

    def prepare(
        self,
        command: JointCommand,
        previous_target: NDArray[np.float64],
        contact_force: NDArray[np.float64],
    ) -> None:
        """Take ``command`` for the next control tick.

        ``self.model`` must hold the state at the start of the tick. The target angle
        moves linearly from ``previous_target`` to ``command.position`` over the tick.

        Args:
            command: The controller's command.
            previous_target: The last tick's target angles [rad].
            contact_force: J^T f [N, N m], shape (nv,), of the contact forces
                expected over the tick (the controller's planned contact wrenches).
        """
        model = self.model
        self.command = command
        self._start = previous_target
        self._stiffness[6:] = command.stiffness
        self._damping[6:] = command.damping
        nv = model.nv
        damped = model.mass_matrix() + np.diag(self._damping) * self.time_step
        self._inverse = np.asarray(np.linalg.inv(damped), dtype=np.float64)
        feedforward = np.zeros(nv)
        feedforward[6:] = command.torque
        self._bias = feedforward + contact_force - model.inverse_dynamics(np.zeros(nv))
        self._base_velocity = model.v[:6].copy()

    def torques(
        self,
        fraction: float,
        joint_positions: NDArray[np.float64],
        joint_velocities: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """Motor torques [N m] at ``fraction`` (0-1] of the tick, clipped at the effort limits."""
        command, dt = self.command, self.time_step
        target = self._start + fraction * (command.position - self._start)
        velocity = np.concatenate([self._base_velocity, joint_velocities])
        error = np.zeros_like(velocity)
        error[6:] = target - joint_positions
        velocity_error = -velocity
        velocity_error[6:] += command.velocity
        pd = self._stiffness * (error - dt * velocity) + self._damping * velocity_error
        acceleration = self._inverse @ (pd + self._bias)
        torque = pd[6:] - command.damping * dt * acceleration[6:] + command.torque
        return np.minimum(np.maximum(torque, -self.effort_limits), self.effort_limits)
