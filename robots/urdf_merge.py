"""Merge the links attached by fixed joints into their parents (a URDF for the physics).

:func:`lock_joints` first turns chosen revolute joints into fixed ones at a given
angle (the description's ``locked_joints`` at their standing angle), so that the
merge folds their links into their parents as well.

A fixed joint adds a link to PyBullet's Featherstone tree without a degree of
freedom, and every link costs time in each physics step (dynamics, and each
constraint row's response is computed over all the links). G1's derived URDF has
41 links of which 12 are fixed (head, logo, hands, IMU/camera frames, the added
sole and trunk frames): merging them gives 29 links, the same rigid bodies, and
-33 us per 1 ms step (430 -> 397 us, CPU time, measured mid-walk).

PyBullet's own ``URDF_MERGE_FIXED_LINKS`` cannot be used: with
``URDF_USE_INERTIA_FROM_FILE`` it drops the inertial origins of the merged links
(G1's CoM came out 3 cm lower). Here the merge is exact: masses add, the CoM is
the mass-weighted mean, the inertia tensors are moved with the parallel-axis
theorem, and the collision and visual shapes keep their place in the world.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from planner.exceptions import ParameterError

Transform = tuple[NDArray[np.float64], NDArray[np.float64]]  # (rotation 3x3, translation [m])
# The <inertia> attributes ixx, ixy, ixz, iyy, iyz, izz: the symmetric tensor's upper triangle.
_INERTIA_ENTRIES = {f"i{'xyz'[r]}{'xyz'[c]}": (r, c) for r in range(3) for c in range(r, 3)}


def lock_joints(root: ET.Element, angles: Mapping[str, float]) -> None:
    """Make, in place, each joint of ``angles`` a fixed joint at that angle [rad].

    The joint's rotation about its axis is folded into its origin, so the child
    link keeps the place it had at that angle.

    Raises:
        ParameterError: A name is not a revolute or continuous joint of the URDF.
    """
    joints = {joint.get("name"): joint for joint in root.findall("joint")}
    for name, angle in angles.items():
        joint = joints.get(name)
        if joint is None or joint.get("type") not in ("revolute", "continuous"):
            raise ParameterError("locked_joints", name, "revolute joints of the URDF")
        axis_element = joint.find("axis")
        axis_text = axis_element.get("xyz", "1 0 0") if axis_element is not None else "1 0 0"
        axis = np.array([float(v) for v in axis_text.split()])
        turn = Rotation.from_rotvec(angle * axis / np.linalg.norm(axis)).as_matrix()
        _set_origin(joint, _compose(_origin(joint), (turn, np.zeros(3))))
        joint.set("type", "fixed")
        for tag in ("axis", "limit", "dynamics", "mimic", "safety_controller", "calibration"):
            for element in joint.findall(tag):
                joint.remove(element)


def merge_fixed_links(root: ET.Element) -> None:
    """Merge, in place, every link attached by a fixed joint into its parent link."""
    while True:
        fixed = _leaf_fixed_joint(root)
        if fixed is None:
            return
        _merge_joint(root, fixed)


def _leaf_fixed_joint(root: ET.Element) -> ET.Element | None:
    """A fixed joint whose child has no fixed joint below it (None if there is none)."""
    fixed = [j for j in root.findall("joint") if j.get("type") == "fixed"]
    parents_of_fixed = {_link_of(j, "parent") for j in fixed}
    for joint in fixed:
        if _link_of(joint, "child") not in parents_of_fixed:
            return joint
    return None


def _merge_joint(root: ET.Element, joint: ET.Element) -> None:
    """Move the child link of fixed ``joint`` into its parent and remove both."""
    links = {link.get("name"): link for link in root.findall("link")}
    parent, child = links[_link_of(joint, "parent")], links[_link_of(joint, "child")]
    parent_from_child = _origin(joint)
    _merge_inertial(parent, child, parent_from_child)
    for tag in ("collision", "visual"):
        for element in child.findall(tag):
            _set_origin(element, _compose(parent_from_child, _origin(element)))
            parent.append(element)
    for other in root.findall("joint"):
        if _link_of(other, "parent") == child.get("name"):
            _child(other, "parent").set("link", _link_of(joint, "parent"))
            _set_origin(other, _compose(parent_from_child, _origin(other)))
    root.remove(joint)
    root.remove(child)


def _merge_inertial(parent: ET.Element, child: ET.Element, parent_from_child: Transform) -> None:
    """Parent's <inertial> := parent's and child's bodies as one (kept in its orientation)."""
    bodies = [
        _body(parent.find("inertial"), (np.eye(3), np.zeros(3))),
        _body(child.find("inertial"), parent_from_child),
    ]
    mass = sum(m for m, _, _ in bodies)
    if mass <= 0.0:
        return
    com = np.sum([m * c for m, c, _ in bodies], axis=0) / mass
    inertia = np.sum([i + _parallel_axis(m, c - com) for m, c, i in bodies], axis=0)
    inertial = parent.find("inertial")
    if inertial is None:
        inertial = ET.SubElement(parent, "inertial")
    frame = _origin(inertial)[0] if inertial.find("origin") is not None else np.eye(3)
    local = frame.T @ inertia @ frame  # in the parent's inertial orientation
    _set_origin(inertial, (frame, com))
    _child(inertial, "mass").set("value", f"{mass:.12g}")
    tensor = _child(inertial, "inertia")
    for key, (row, column) in _INERTIA_ENTRIES.items():
        tensor.set(key, f"{local[row, column]:.12g}")


def _parallel_axis(mass: float, offset: NDArray[np.float64]) -> NDArray[np.float64]:
    """Inertia [kg m^2] of a point ``mass`` [kg] at ``offset`` [m] from the reference point."""
    return mass * (np.dot(offset, offset) * np.eye(3) - np.outer(offset, offset))


def _body(
    inertial: ET.Element | None, frame: Transform
) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Mass [kg], CoM [m] and inertia about the CoM [kg m^2] in ``frame``'s parent."""
    if inertial is None:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    mass_element = inertial.find("mass")
    mass = float(mass_element.get("value", "0")) if mass_element is not None else 0.0
    rotation, com = _compose(frame, _origin(inertial))
    values = inertial.find("inertia")
    get = (lambda k: float(values.get(k, "0"))) if values is not None else (lambda k: 0.0)
    tensor = np.array(
        [
            [get("ixx"), get("ixy"), get("ixz")],
            [get("ixy"), get("iyy"), get("iyz")],
            [get("ixz"), get("iyz"), get("izz")],
        ]
    )
    return mass, com, rotation @ tensor @ rotation.T


def _origin(element: ET.Element) -> Transform:
    """The <origin> of ``element`` as (rotation, translation [m]); identity if absent."""
    origin = element.find("origin")
    xyz = origin.get("xyz", "0 0 0") if origin is not None else "0 0 0"
    rpy = origin.get("rpy", "0 0 0") if origin is not None else "0 0 0"
    rotation = Rotation.from_euler("xyz", [float(v) for v in rpy.split()]).as_matrix()
    return rotation, np.array([float(v) for v in xyz.split()])


def _set_origin(element: ET.Element, transform: Transform) -> None:
    """Write ``transform`` as the <origin> of ``element`` (URDF rpy: fixed-axis x, y, z)."""
    rotation, translation = transform
    rpy = Rotation.from_matrix(rotation).as_euler("xyz")
    origin = _child(element, "origin", first=True)
    origin.set("xyz", " ".join(f"{v:.12g}" for v in translation))
    origin.set("rpy", " ".join(f"{v:.12g}" for v in rpy))


def _compose(first: Transform, second: Transform) -> Transform:
    """``first`` then ``second`` (both parent-from-child)."""
    return first[0] @ second[0], first[0] @ second[1] + first[1]


def _child(element: ET.Element, tag: str, first: bool = False) -> ET.Element:
    """The ``tag`` child of ``element``, created (as first child if ``first``) when missing."""
    found = element.find(tag)
    if found is not None:
        return found
    created = ET.Element(tag)
    element.insert(0 if first else len(element), created)
    return created


def _link_of(joint: ET.Element, tag: str) -> str:
    """Link named by the <parent> or <child> element of ``joint``."""
    element = joint.find(tag)
    if element is None or element.get("link") is None:
        raise ValueError(f"joint {joint.get('name')} has no <{tag} link=...>")
    return str(element.get("link"))
