"""The physics URDF for an engine with native joint armature: the rotor discs taken out.

The derived URDF carries each motor's armature as a massless disc on its child link
(:mod:`robots.rotor_inertia`), because PyBullet has no armature. An engine that has one
(MuJoCo's joint ``armature``) takes the armature on the joint and the links without
the discs, else the joint would feel it twice. The discs are found by deriving the
physics URDF with and without the description's armature: per link the difference of
the two inertia tensors, in the link's frame (the merge folds a locked joint's disc
into the link that carries it). A model error (:mod:`robots.model_error`) scales a
link's inertia with its mass, discs included, so a disc is taken out scaled by the
link's mass over its nominal mass: exact for any such error.
"""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError
from robots.description import RobotDescription
from robots.urdf_cache import derived_urdf
from robots.urdf_merge import _INERTIA_ENTRIES, _origin

RELATIVE_TOLERANCE = 1e-9  # [-] an inertia difference below this (of the tensor) is rounding


def _inertial(link: ET.Element) -> tuple[float, NDArray[np.float64], NDArray[np.float64]]:
    """Mass [kg], the inertia tensor about the CoM in the link's frame [kg m^2], and the
    rotation of the inertial frame in the link's frame."""
    inertial = link.find("inertial")
    if inertial is None:
        return 0.0, np.zeros((3, 3)), np.eye(3)
    mass_element = inertial.find("mass")
    mass = 0.0 if mass_element is None else float(mass_element.get("value", "0"))
    tensor = np.zeros((3, 3))
    values = inertial.find("inertia")
    for key, (row, column) in _INERTIA_ENTRIES.items():
        value = 0.0 if values is None else float(values.get(key, "0"))
        tensor[row, column] = tensor[column, row] = value
    rotation = _origin(inertial)[0]
    return mass, rotation @ tensor @ rotation.T, rotation


def _links(text: str) -> dict[str, ET.Element]:
    return {str(link.get("name")): link for link in ET.fromstring(text).iter("link")}


def rotor_discs(description: RobotDescription) -> dict[str, tuple[float, NDArray[np.float64]]]:
    """Link -> (its nominal mass [kg], the discs' inertia on it in its frame [kg m^2]) in
    the physics URDF (``derived_urdf(description, merged=True)``); links without discs
    are absent."""
    with_discs = _links(derived_urdf(description, merged=True).read_text(encoding="utf-8"))
    bare = dataclasses.replace(description, motor_armature={})
    without = _links(derived_urdf(bare, merged=True).read_text(encoding="utf-8"))
    discs = {}
    for name, link in with_discs.items():
        mass, tensor, _ = _inertial(link)
        difference = tensor - _inertial(without[name])[1]
        if np.abs(difference).max() > RELATIVE_TOLERANCE * max(np.abs(tensor).max(), 1e-12):
            discs[name] = (mass, difference)
    return discs


def without_rotor_discs(text: str, description: RobotDescription) -> str:
    """The physics URDF ``text`` (nominal or with a model error) without the discs of
    ``description``'s armature.

    Raises:
        ParameterError: A link that carries a disc is missing from ``text`` or has no mass.
    """
    root = ET.fromstring(text)
    links = {link.get("name"): link for link in root.iter("link")}
    for name, (nominal_mass, disc) in rotor_discs(description).items():
        link = links.get(name)
        mass, tensor, rotation = (0.0, None, None) if link is None else _inertial(link)
        if link is None or not mass > 0.0 or tensor is None or rotation is None:
            raise ParameterError("urdf_text", name, "a link with mass of the physics URDF")
        local = rotation.T @ (tensor - disc * (mass / nominal_mass)) @ rotation
        values = link.find("inertial/inertia")
        assert values is not None  # _inertial found a mass, so the link has an <inertial>
        for key, (row, column) in _INERTIA_ENTRIES.items():
            values.set(key, f"{local[row, column]:.12g}")
    return ET.tostring(root, encoding="unicode") + "\n"
