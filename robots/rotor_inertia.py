"""Motor armature in a URDF: each motor's reflected rotor inertia on its child link.

A geared motor adds its rotor inertia times the gear ratio squared, the armature a
[kg m^2], to its joint: the joint's equation of motion gains ``a qdd`` (MuJoCo's
``armature``, pinocchio's ``rotorInertia`` times ``rotorGearRatio`` squared). URDF and
PyBullet have no such term (bullet3 issue #2249), so the derived URDF carries it as a
spinning disc on the child link: ``a`` about the joint axis and ``a / 2`` about the two
axes across it (a thin disc's ratio, which keeps the tensor physical; ``a`` about the
axis alone breaks the triangle inequality of a slender link's tensor and PyBullet's
integration diverges). For a joint whose parent does not turn this is the armature
exactly; otherwise the disc also turns with the parent, an error of ``a`` times the
parent's angular velocity along the axis, and ``a / 2`` across it
(docs/full-robot.md, "Motor armature").
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError

_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def _rpy_matrix(rpy: NDArray[np.float64]) -> NDArray[np.float64]:
    """URDF's fixed-axis roll-pitch-yaw rotation R = Rz(yaw) Ry(pitch) Rx(roll)."""
    (cr, cp, cy), (sr, sp, sy) = np.cos(rpy), np.sin(rpy)
    return np.array(
        [
            [cy * cp, cy * sp * sr - sy * cr, cy * sp * cr + sy * sr],
            [sy * cp, sy * sp * sr + cy * cr, sy * sp * cr - cy * sr],
            [-sp, cp * sr, cp * cr],
        ]
    )


def _vector(element: ET.Element | None, key: str, default: str) -> NDArray[np.float64]:
    text = default if element is None else element.get(key, default)
    return np.array([float(v) for v in text.split()])


def disc_inertia(armature: float, axis: NDArray[np.float64]) -> NDArray[np.float64]:
    """3x3 inertia [kg m^2] of a thin disc spinning about unit ``axis``: ``armature``
    about the axis, half of it across."""
    n = np.asarray(axis, float) / np.linalg.norm(axis)
    outer = np.outer(n, n)
    return armature * outer + 0.5 * armature * (np.eye(3) - outer)


def add_rotor_inertia(root: ET.Element, armature: Mapping[str, float]) -> None:
    """Add each joint's ``armature`` [kg m^2] to its child link's inertia, in place.

    Raises:
        ParameterError: A joint of ``armature`` is not a revolute joint of the URDF, or
            its armature is negative.
    """
    joints = {j.get("name"): j for j in root.findall("joint")}  # not transmissions' joints
    links = {link.get("name"): link for link in root.iter("link")}
    for name, value in armature.items():
        joint = joints.get(name)
        if joint is None or joint.get("type") not in ("revolute", "continuous"):
            raise ParameterError("motor_armature", name, "a revolute joint of the URDF")
        if not (np.isfinite(value) and value >= 0.0):
            raise ParameterError(f"motor_armature[{name}]", value, "a number >= 0 kg m^2")
        child = joint.find("child")
        assert child is not None  # a URDF joint has a child
        inertial = links[child.get("link")].find("inertial")
        if inertial is None:
            raise ParameterError("motor_armature", name, "a joint whose child link has mass")
        tensor = inertial.find("inertia")
        assert tensor is not None
        # The child link's frame is the joint's: the axis there, into the inertial frame.
        rotation = _rpy_matrix(_vector(inertial.find("origin"), "rpy", "0 0 0"))
        axis = rotation.T @ _vector(joint.find("axis"), "xyz", "1 0 0")
        added = disc_inertia(value, axis)
        index = {"x": 0, "y": 1, "z": 2}
        for key in _KEYS:
            row, column = index[key[1]], index[key[2]]
            tensor.set(key, f"{float(tensor.get(key, '0')) + added[row, column]:.9g}")
