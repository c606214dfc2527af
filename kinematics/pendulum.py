"""The height of the pendulum that a biped's whole-body motion makes of it.

With its feet on the ground, a biped moves its CoM by turning its legs: the body above
the CoM then moves faster than the legs below it, and its centroidal angular momentum
follows the CoM velocity, L = m h_r H cdot (H of (1)). Its rate m h_r H cddot moves the
pivot by h_r cddot / g, so the CoM moves as a point-mass pendulum c_z + h_r tall, not
c_z: slower to stop on a sole's edge than a LIPM at c_z would be; the planner's LIPM on a
robot is that tall (``RobotDescription.pendulum_height``). (Lee and
Goswami, "Reaction mass pendulum (RMP): an explicit model for centroidal angular
momentum of humanoid robots", ICRA 2007, for a body whose inertia turns with the
pendulum.)

h_r is measured here on the whole-body IK itself: the CoM is swayed along x and along y
with both soles fixed, and h_r is the least-squares slope of the angular momentum
against the CoM velocity, over the mass.
"""

from __future__ import annotations

import numpy as np

from kinematics.reach import stance
from kinematics.whole_body_ik import WholeBodyIK
from robots.description import RobotDescription

AMPLITUDE = 0.02  # [m] of the CoM's sway
PERIOD = 0.5  # [s] of the CoM's sway
DT = 0.01  # [s] between IK solves
CYCLES = 2  # sway periods the least-squares slope is fitted over


def rotational_height(description: RobotDescription) -> tuple[float, float]:
    """h_r [m] of the IK's sway along x and along y (soles ``foot_spacing`` apart)."""
    ik = WholeBodyIK(description, upper_body=bool(description.upper_body_joints))
    soles = stance(description.foot_spacing)
    heights = []
    for axis in (0, 1):
        ik.reset(*soles, np.zeros(2))
        previous = ik.com_world()[:2]
        velocities, momenta = [], []
        for k in range(1, round(CYCLES * PERIOD / DT) + 1):
            target = np.zeros(2)
            target[axis] = AMPLITUDE * np.sin(2.0 * np.pi * k * DT / PERIOD)
            ik.solve(target, *soles, "both", DT)
            com = ik.com_world()[:2]
            velocities.append((com - previous) / DT)
            momenta.append(ik.angular_momentum[:2].copy())
            previous = com
        # L = m h_r H cdot: L_y = m h_r cdot_x, L_x = -m h_r cdot_y
        v = np.array(velocities)[:, axis]
        moment = np.array(momenta)[:, 1 - axis] * (1.0 if axis == 0 else -1.0)
        heights.append(float(v @ moment / (v @ v)) / ik.robot.total_mass())
    return heights[0], heights[1]
