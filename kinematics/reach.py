"""The legs' lateral reach: how far apart a robot can stand with both soles flat.

A step the planner may take outwards (``step_max`` y) is of use only if the robot can
then stand on both feet: in the double support that follows, both soles are flat on the
ground and the CoM is between them at its nominal height. The widest such stance is
set by the joints' ranges (on G1 the ankle roll's +-15 deg; on Talos the knees, straight
but for the IK's margin, with the hip and ankle rolls near their +-30 deg), and is found
here with the whole-body IK itself: the soles are moved
apart symmetrically from the nominal stance, the CoM kept midway, until the IK can no
longer hold them.
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, sole_pose
from planner.exceptions import ParameterError
from robots.description import RobotDescription

SOLE_TOLERANCE = 0.005  # [m] a sole this far from its target is not held
TILT_TOLERANCE = 0.01  # [rad] nor one turned this far from flat
COM_HEIGHT_TOLERANCE = 0.01  # [m] nor a CoM this far from its nominal height
ITERATIONS = 20  # IK solves per separation (10 ms each)
MAX_WIDTH = 3.0  # [m] no biped's legs reach further: the search ends there


def lateral_reach(description: RobotDescription, increment: float = 0.005) -> float:
    """Widest lateral distance between the soles [m] at which the whole-body IK holds
    both soles flat on the ground with the CoM midway (:func:`holds`), the soles spread
    ``increment`` at a time from the nominal stance.

    Args:
        description: The robot.
        increment: Separation added per trial [m].

    Raises:
        ParameterError: ``increment`` is not in (0, 0.05] m.
    """
    if not 0.0 < increment <= 0.05:
        raise ParameterError("increment", increment, "a number in (0, 0.05] m")
    ik = WholeBodyIK(description)
    width = description.foot_spacing
    ik.reset(*stance(width), np.zeros(2))
    while width + increment <= MAX_WIDTH and holds(ik, description, width + increment):
        width += increment
    return width


def holds(ik: WholeBodyIK, description: RobotDescription, width: float) -> bool:
    """Whether ``ik``, from its present state, holds the soles ``width`` [m] apart, flat on
    the ground (within 5 mm and 0.01 rad of their targets), with the CoM midway within
    1 cm of ``description.com_height``."""
    targets = stance(width)
    try:
        for _ in range(ITERATIONS):
            ik.solve(np.zeros(2), *targets, "both", 0.01)
    except IkInfeasibleError:
        return False
    soles = [ik.sole_world("left"), ik.sole_world("right")]
    sole_error = max(
        float(np.linalg.norm(pose[:3, 3] - target[:3, 3]))
        for pose, target in zip(soles, targets, strict=True)
    )
    tilt = max(float(np.arccos(np.clip(pose[2, 2], -1.0, 1.0))) for pose in soles)
    height_error = abs(float(ik.com_world()[2]) - description.com_height)
    return (
        sole_error <= SOLE_TOLERANCE
        and tilt <= TILT_TOLERANCE
        and height_error <= COM_HEIGHT_TOLERANCE
    )


def stance(width: float) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Left and right sole poses (4x4) ``width`` [m] apart about the origin, flat."""
    return (
        sole_pose(np.array([0.0, width / 2.0, 0.0])),
        sole_pose(np.array([0.0, -width / 2.0, 0.0])),
    )
