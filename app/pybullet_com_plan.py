"""The CoP a position-controlled robot can realise for the planner's CoM plan.

The measured CoP of the robot is the LIPM's c - c''/omega^2 plus S Ldot / (m g),
where Ldot is the centroidal angular momentum rate of the whole-body motion itself
(:attr:`kinematics.whole_body_ik.WholeBodyIK.angular_momentum`). To keep the
planner's pivot (ZMP - S hdot / (m g)) while the motion produces Ldot, the CoP must
be pivot + S Ldot / (m g); the sole bounds it. See :mod:`app.pybullet_backend`.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray
from scipy.spatial import ConvexHull

from planner.hybrid_lipm import H_MATRIX
from planner.parameters import GRAVITY
from planner.types import PlannerOutput
from robots.description import SoleRectangle


def momentum_aware_pivot(
    zmp: NDArray[np.float64],
    angular_momentum_rate: NDArray[np.float64],
    motion_momentum_rate: NDArray[np.float64],
    mass: float,
    command: PlannerOutput,
    sole: SoleRectangle,
    cop_margin: float,
    ramped_double_support: bool = False,
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """ZMP and hdot for the CoM plan, given the motion's own angular momentum rate.

    Args:
        zmp: The planner's ZMP [m].
        angular_momentum_rate: The planner's hdot [N m].
        motion_momentum_rate: Ldot of the whole-body motion [N m].
        mass: Robot mass [kg].
        command: The planner's output (stance and previous footholds, DSP flag).
        sole: Sole rectangle around the ankle [m].
        cop_margin: Distance kept from the sole's edges [m].
        ramped_double_support: In a double support, clip to the hull of both soles
            (when the plan's ZMP moves along the window) rather than the new sole.

    Returns:
        (CoP the plan should use as its ZMP [m], Ldot to use as its hdot [N m]).
    """
    weight = mass * GRAVITY
    pivot = zmp - H_MATRIX @ angular_momentum_rate / weight
    wanted = pivot + H_MATRIX @ motion_momentum_rate / weight
    stance = np.asarray(command.stance.position, float)
    low = stance + np.array([sole.x_min + cop_margin, -sole.half_width + cop_margin])
    high = stance + np.array([sole.x_max - cop_margin, sole.half_width - cop_margin])
    if command.double_support and ramped_double_support:
        old = np.asarray(command.previous_stance.position, float)
        corners = np.array(
            [
                foot + np.array([x, y])
                for foot in (stance, old)
                for x in (sole.x_min + cop_margin, sole.x_max - cop_margin)
                for y in (-sole.half_width + cop_margin, sole.half_width - cop_margin)
            ]
        )
        return clip_to_hull(wanted, corners), motion_momentum_rate
    return np.clip(wanted, low, high), motion_momentum_rate


def clip_to_hull(point: NDArray[np.float64], corners: NDArray[np.float64]) -> NDArray[np.float64]:
    """``point`` if inside the convex hull of ``corners`` (n x 2), else its nearest hull point."""
    hull = ConvexHull(corners)
    if np.all(hull.equations[:, :2] @ point + hull.equations[:, 2] <= 1e-12):
        return point
    best, best_distance = point, np.inf
    for start, end in hull.simplices:
        a, b = corners[start], corners[end]
        edge = b - a
        fraction = float(np.clip((point - a) @ edge / (edge @ edge), 0.0, 1.0))
        candidate = a + fraction * edge
        distance = float(np.linalg.norm(point - candidate))
        if distance < best_distance:
            best, best_distance = candidate, distance
    return best
