"""The CoP a position-controlled robot can realise for the planner's CoM plan.

Two parts. :func:`momentum_aware_pivot`: the measured CoP of the robot is the
LIPM's c - c''/omega^2 plus S Ldot / (m g), where Ldot is the centroidal angular
momentum rate of the whole-body motion itself
(:attr:`kinematics.whole_body_ik.WholeBodyIK.angular_momentum`). To keep the
planner's pivot (ZMP - S hdot / (m g)) while the motion produces Ldot, the CoP must
be pivot + S Ldot / (m g); the sole bounds it. See :mod:`app.pybullet_backend`.

:func:`cop_admittance_zmp`, the CoM admittance of Caron et al. (2019) written for a
CoM plan: when the measured CoP p_m lags the plan's p_d, the joints are realising a
different CoM acceleration than planned (c'' = omega^2 (c - p)). Integrating the
plan with p_d + A (p_d - p_m) changes its acceleration by -A omega^2 (p_d - p_m),
so the IK's CoM target moves the way that brings p_m to p_d.

Measured on G1 (``rsg run --scenario walk --duration 12 --push 2.75:8,0``): without
it, the CoP under the stance foot went bang-bang between heel and toe (the plan
asked for 0.51-0.59 m, the foot pressed at 0.484 or 0.654 m), the forward DCM
error swung +-4 cm every step, and all 16 steps after the push were adjusted (one
every 0.6 s) until the end; with A = 0.3, one adjusted step and the walk is
nominal again. On 32 pushes (``rsg grid``: 4, 6, 8 and 10 N s in 8 directions,
0.1 s at mid single support) the robot survived 19 and fully recovered 10, against 16 and 6
without (A = 0.2 and 0.5: 16 and 9). A 180 s walk still has no adjusted step.
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


ADMITTANCE_LIMIT = 0.1  # bound on the CoP shift of the admittance [m]


def cop_admittance_zmp(
    zmp: NDArray[np.float64],
    planned_cop: NDArray[np.float64],
    measured_cop: NDArray[np.float64] | None,
    gain: float,
) -> NDArray[np.float64]:
    """The ZMP to integrate the CoM plan with, given the CoP measured over the last tick.

    Args:
        zmp: The plan's CoP for this tick [m].
        planned_cop: The plan's CoP over the last tick [m] (what ``measured_cop``
            should have been).
        measured_cop: CoP of the ground reaction at the end of the last tick [m]
            (None: the feet are hardly loaded; no correction).
        gain: Admittance A [-].

    Returns:
        ``zmp + A (planned_cop - measured_cop)``, the shift bounded by
        :data:`ADMITTANCE_LIMIT` per axis.
    """
    if measured_cop is None or gain == 0.0:
        return zmp
    shift = gain * (np.asarray(planned_cop, float) - np.asarray(measured_cop, float))
    return zmp + np.clip(shift, -ADMITTANCE_LIMIT, ADMITTANCE_LIMIT)
