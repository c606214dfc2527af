"""A robot's model error: the physics' URDF with other masses than the controller's.

A real robot is not its model: its links weigh a little more or less, a battery or a
cover adds mass to the torso and moves its centre of mass. :func:`perturbed_urdf` writes
the physics' copy of a derived URDF with such errors (the controller keeps the nominal
one): each link's mass and inertia scaled, mass added to one link with its inertia
scaled in proportion, and that link's centre of mass moved.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping, Sequence

from planner.exceptions import ParameterError

_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def perturbed_text(
    text: str,
    mass_scales: Mapping[str, float],
    added_mass: tuple[str, float],
    com_offset: tuple[str, Sequence[float]],
) -> str:
    """The URDF ``text`` with model errors.

    Args:
        text: The nominal URDF.
        mass_scales: Link -> factor on its mass and inertia.
        added_mass: (link, mass [kg] added to it, its inertia scaled in proportion).
        com_offset: (link, offset [m] of its centre of mass in its frame, 3 values).

    Raises:
        ParameterError: A link is not in the URDF or a value is not physical.
    """
    root = ET.fromstring(text)
    links = {link.get("name"): link for link in root.iter("link")}
    for name in (*mass_scales, added_mass[0], com_offset[0]):
        if name not in links or links[name].find("inertial") is None:
            raise ParameterError("model error link", name, "a link of the URDF with mass")
    for name, scale in mass_scales.items():
        if not scale > 0.0:
            raise ParameterError(f"mass scale of {name}", scale, "a factor > 0")
        _scale(links[name], scale)
    link, extra = added_mass
    element = _inertial(links[link]).find("mass")
    mass = float("0" if element is None else element.get("value", "0"))
    if not mass + extra > 0.0:
        raise ParameterError(f"added mass of {link}", extra, f"more than -{mass:g} kg")
    _scale(links[link], (mass + extra) / mass)
    link, offset = com_offset
    origin = _inertial(links[link]).find("origin")
    if origin is None:
        origin = ET.SubElement(_inertial(links[link]), "origin", xyz="0 0 0", rpy="0 0 0")
    xyz = [float(v) + d for v, d in zip(origin.get("xyz", "0 0 0").split(), offset, strict=True)]
    origin.set("xyz", " ".join(f"{v:.9g}" for v in xyz))
    return ET.tostring(root, encoding="unicode") + "\n"


def _inertial(link: ET.Element) -> ET.Element:
    inertial = link.find("inertial")
    assert inertial is not None  # checked by the caller
    return inertial


def _scale(link: ET.Element, factor: float) -> None:
    """Scale a link's mass and inertia by ``factor`` (its density changes)."""
    inertial = _inertial(link)
    mass = inertial.find("mass")
    assert mass is not None
    mass.set("value", f"{float(mass.get('value', '0')) * factor:.9g}")
    tensor = inertial.find("inertia")
    if tensor is not None:
        for key in _INERTIA_KEYS:
            tensor.set(key, f"{float(tensor.get(key, '0')) * factor:.9g}")
