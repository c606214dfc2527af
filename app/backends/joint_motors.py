"""The joint motors in simulation: the G1 driver's law, nothing else.

A G1 motor driver evaluates, from the low-level command (:class:`app.lowlevel.JointCommand`)
and its own encoder,

    tau = kp (q* - q) + kd (qd* - qd) + tau_ff,

clipped at the motor's torque limit; the joint then also feels the motor's friction and
its armature (the armature is in the robot's inertia, :mod:`robots.rotor_inertia`). The
law is evaluated explicitly at every physics step, which must be short enough for it:
on G1, whose ankle links are light, 1 ms (docs/full-robot.md, "The honest plant").

The torque limit follows the motor's torque-speed curve (unitree_rl_lab's
``UnitreeActuator``): up to ``peak_torque`` while the joint turns slower than
``full_torque_speed``, falling linearly to zero at ``no_load_speed``; a torque that brakes
the joint may reach ``braking_torque``. Never above the URDF's effort limit. Friction is
Coulomb plus viscous, ``static_friction sign(qd) + viscous_friction qd``: the viscous part
is subtracted from the torque here, the Coulomb part is PyBullet's velocity motor with
that maximum force (an implicit friction, stable at any step, where a smooth sign
evaluated explicitly chatters on a light joint).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from app.lowlevel import JointCommand
from robots.description import MotorModel


class JointMotors:
    """The motors of every actuated joint, in one joint order.

    Args:
        effort_limits: The URDF's effort limits [N m] (a ceiling on every motor).
        motors: Each joint's motor model (None: the effort limit, no friction).
    """

    def __init__(self, effort_limits: NDArray[np.float64], motors: list[MotorModel | None]) -> None:
        limits = np.asarray(effort_limits, float)
        inf = np.full(len(limits), np.inf)

        def column(name: str, default: NDArray[np.float64]) -> NDArray[np.float64]:
            return np.array(
                [d if m is None else getattr(m, name) for m, d in zip(motors, default, strict=True)]
            )

        self.peak = np.minimum(column("peak_torque", limits), limits)
        self.braking = np.minimum(column("braking_torque", limits), limits)
        self.knee = column("full_torque_speed", inf)
        self.no_load = column("no_load_speed", inf)
        self.static_friction = column("static_friction", np.zeros(len(limits)))
        self.viscous_friction = column("viscous_friction", np.zeros(len(limits)))

    def clip(
        self, torque: NDArray[np.float64], velocities: NDArray[np.float64]
    ) -> NDArray[np.float64]:
        """``torque`` [N m] within the torque-speed curve at ``velocities`` [rad/s]."""
        limit = np.where(torque * velocities > 0.0, self.peak, self.braking)
        speed = np.abs(velocities)
        fast = speed > self.knee
        if np.any(fast):
            span = self.no_load[fast] - self.knee[fast]
            limit[fast] *= np.clip((self.no_load[fast] - speed[fast]) / span, 0.0, 1.0)
        return np.clip(torque, -limit, limit)

    def driver(
        self,
        command: JointCommand,
        positions: NDArray[np.float64],
        velocities: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """The drivers' torques [N m] for ``command`` at the encoder readings: the law
        within the torque-speed limit (what a motor's current gives, ``tau_est``)."""
        law = (
            command.stiffness * (command.position - positions)
            + command.damping * (command.velocity - velocities)
            + command.torque
        )
        return self.clip(law, velocities)

    def torques(
        self,
        command: JointCommand,
        positions: NDArray[np.float64],
        velocities: NDArray[np.float64],
    ) -> NDArray[np.float64]:
        """The joints' torques [N m]: the drivers' less the viscous friction (the Coulomb
        friction is the engine's, module docstring)."""
        return self.driver(command, positions, velocities) - self.viscous_friction * velocities
