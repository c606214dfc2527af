"""Derive simulation-ready URDFs from example-robot-data into a cache folder.

The installed URDFs cannot be used as they are: meshes are ``package://`` URIs
(pinocchio/placo cannot resolve them), placo's ``HumanoidRobot`` needs the frames
``left_foot``, ``right_foot`` and ``trunk``, and PyBullet gives 1 kg to every link
without ``<inertial>``. When the description asks for it (``sole_box_collision``),
the foot's collision shapes (G1: four 5 mm spheres, which chatter and bounce in
PyBullet at every touchdown) are replaced by one thin box spanning the sole
rectangle, bottom face on the sole plane. Each motor's armature is added to its
child link (:mod:`robots.rotor_inertia`). :func:`derived_urdf` writes a fixed copy to
``$RSG_CACHE_DIR/robots/<name>-<hash>/robot.urdf`` (default cache
``~/.cache/rsg``); with ``merged=True``, ``robot-merged.urdf``, the same robot
with the description's ``locked_joints`` welded at their standing angle and the
links of fixed joints merged into their parents (:mod:`robots.urdf_merge`), for
the physics only (the IK needs the frames). The
hash covers the source text and the derivation settings, so the same input always
gives the same file, and a new input a new folder.
"""

from __future__ import annotations

import hashlib
import importlib.metadata
import os
import tempfile
import xml.etree.ElementTree as ET
from pathlib import Path

from planner.exceptions import ParameterError, RsgError
from robots.description import RobotDescription
from robots.rotor_inertia import add_rotor_inertia
from robots.urdf_merge import lock_joints, merge_fixed_links

DISTRIBUTION = "example-robot-data"
PACKAGE_PREFIX = "package://"
DERIVATION_VERSION = "5"  # bump when the derivation below (or the merge) changes
TINY_MASS = 1e-6  # [kg] mass given to links without <inertial>
TINY_INERTIA = 1e-9  # [kg m^2]
FOOT_FRAMES = {"left": "left_foot", "right": "right_foot"}
TRUNK_FRAME = "trunk"


class RobotDataError(RsgError):
    """example-robot-data is missing or does not hold the requested file."""


def robots_share_dir() -> Path:
    """Folder ``.../share/example-robot-data/robots`` of the installed distribution.

    Raises:
        RobotDataError: The distribution is not installed or has no robots folder.
    """
    try:
        distribution = importlib.metadata.distribution(DISTRIBUTION)
    except importlib.metadata.PackageNotFoundError as error:
        raise RobotDataError(f"{DISTRIBUTION} is not installed") from error
    marker = f"share/{DISTRIBUTION}/robots/"
    for file in distribution.files or ():
        posix = file.as_posix()
        if marker in posix:
            prefix = posix[: posix.index(marker) + len(marker)]
            folder = Path(str(distribution.locate_file(prefix))).resolve()
            if folder.is_dir():
                return folder
    raise RobotDataError(f"{DISTRIBUTION} has no {marker} folder")


def cache_root() -> Path:
    """Root of the cache: ``$RSG_CACHE_DIR`` or ``~/.cache/rsg``."""
    configured = os.environ.get("RSG_CACHE_DIR")
    return Path(configured).expanduser() if configured else Path.home() / ".cache" / "rsg"


def _resolve_package_uri(uri: str, share_dir: Path) -> str:
    """Absolute path of a ``package://<pkg>/<rest>`` mesh URI.

    ``package://example-robot-data/robots/x`` maps to ``<share>/x``; any other
    ``package://<pkg>/rest`` is looked up as ``<share>/<pkg>/rest``.
    """
    body = uri[len(PACKAGE_PREFIX) :]
    package, _, rest = body.partition("/")
    if package == DISTRIBUTION and rest.startswith("robots/"):
        return str(share_dir / rest[len("robots/") :])
    return str(share_dir / package / rest)


def _add_fixed_frame(root: ET.Element, name: str, parent: str, xyz: tuple[float, ...]) -> None:
    """Append a massless link ``name`` fixed to ``parent`` at ``xyz`` [m]."""
    link = ET.SubElement(root, "link", {"name": name})
    _add_tiny_inertial(link)
    joint = ET.SubElement(root, "joint", {"name": f"{name}_frame_joint", "type": "fixed"})
    ET.SubElement(joint, "origin", {"xyz": " ".join(f"{v:.9g}" for v in xyz), "rpy": "0 0 0"})
    ET.SubElement(joint, "parent", {"link": parent})
    ET.SubElement(joint, "child", {"link": name})


def _add_tiny_inertial(link: ET.Element) -> None:
    inertial = ET.SubElement(link, "inertial")
    ET.SubElement(inertial, "origin", {"xyz": "0 0 0", "rpy": "0 0 0"})
    ET.SubElement(inertial, "mass", {"value": f"{TINY_MASS:g}"})
    ET.SubElement(
        inertial,
        "inertia",
        {k: (f"{TINY_INERTIA:g}" if k[1] == k[2] else "0") for k in _INERTIA_KEYS},
    )


SOLE_BOX_THICKNESS = 0.01  # [m]


def _replace_sole_collision(root: ET.Element, description: RobotDescription, link: str) -> None:
    """Replace the collision shapes of ``link`` by a box under the sole rectangle."""
    element = next(e for e in root.iter("link") if e.get("name") == link)
    for collision in element.findall("collision"):
        element.remove(collision)
    sole, (x, y, z) = description.sole, description.sole_offset
    collision = ET.SubElement(element, "collision")
    center = (x + (sole.x_min + sole.x_max) / 2, y, z + SOLE_BOX_THICKNESS / 2)
    ET.SubElement(collision, "origin", xyz=" ".join(f"{v:g}" for v in center), rpy="0 0 0")
    geometry = ET.SubElement(collision, "geometry")
    size = (sole.x_max - sole.x_min, 2 * sole.half_width, SOLE_BOX_THICKNESS)
    ET.SubElement(geometry, "box", size=" ".join(f"{v:g}" for v in size))


_INERTIA_KEYS = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


def derive_urdf_text(description: RobotDescription, source_text: str, share_dir: Path) -> str:
    """The derived URDF text (pure function of its inputs).

    Raises:
        ParameterError: A link named in ``description`` is not in the URDF, or a
            frame to add already exists.
    """
    root = ET.fromstring(source_text)
    link_names = {link.get("name") for link in root.iter("link")}
    for field_name in ("base_link", "left_ankle_link", "right_ankle_link", "trunk_link"):
        link = getattr(description, field_name)
        if link not in link_names:
            raise ParameterError(field_name, link, f"a link of {description.urdf_source}")
    for frame in (*FOOT_FRAMES.values(), TRUNK_FRAME):
        if frame in link_names:
            raise ParameterError("urdf", frame, "a URDF without this frame (it is added)")

    for mesh in root.iter("mesh"):
        filename = mesh.get("filename", "")
        if filename.startswith(PACKAGE_PREFIX):
            mesh.set("filename", _resolve_package_uri(filename, share_dir))
    for link in root.iter("link"):
        if link.find("inertial") is None:
            _add_tiny_inertial(link)
    for foot, frame in FOOT_FRAMES.items():
        _add_fixed_frame(root, frame, description.ankle_link(foot), description.sole_offset)
        if description.sole_box_collision:
            _replace_sole_collision(root, description, description.ankle_link(foot))
    _add_fixed_frame(root, TRUNK_FRAME, description.trunk_link, (0.0, 0.0, 0.0))
    add_rotor_inertia(root, description.motor_armature)
    ET.indent(root, space="  ")
    return ET.tostring(root, encoding="unicode") + "\n"


def locked_angles(description: RobotDescription) -> dict[str, float]:
    """Locked joint -> the angle [rad] it is welded at (its standing angle)."""
    return {
        name: float(description.standing_posture.get(name, 0.0))
        for name in description.locked_joints
    }


def derived_urdf(description: RobotDescription, merged: bool = False) -> Path:
    """Path of the derived URDF of ``description``, created on first use.

    Args:
        description: The robot.
        merged: The variant for the physics: the description's locked joints
            welded at their standing angle, and fixed-joint links merged into
            their parents (fewer bodies; no sole/trunk frames).

    Raises:
        RobotDataError: The source URDF is not installed.
    """
    share_dir = robots_share_dir()
    source = share_dir / description.urdf_source
    if not source.is_file():
        raise RobotDataError(f"{source} does not exist")
    source_text = source.read_text(encoding="utf-8")
    settings = (
        description.left_ankle_link,
        description.right_ankle_link,
        description.trunk_link,
        repr(tuple(float(v) for v in description.sole_offset)),
        repr((description.sole, description.sole_box_collision)),
        repr(locked_angles(description)),
        repr(sorted(description.motor_armature.items())),
    )
    key = "\n".join((DERIVATION_VERSION, str(share_dir), *settings, source_text))
    digest = hashlib.sha256(key.encode("utf-8")).hexdigest()[:16]
    folder = cache_root() / "robots" / f"{description.name}-{digest}"
    target = folder / ("robot-merged.urdf" if merged else "robot.urdf")
    if target.is_file():
        return target
    text = derive_urdf_text(description, source_text, share_dir)
    if merged:
        root = ET.fromstring(text)
        lock_joints(root, locked_angles(description))
        merge_fixed_links(root)
        ET.indent(root, space="  ")
        text = ET.tostring(root, encoding="unicode") + "\n"
    folder.mkdir(parents=True, exist_ok=True)
    # Atomic write: concurrent processes may derive the same file at once.
    with tempfile.NamedTemporaryFile(
        "w", dir=folder, suffix=".tmp", delete=False, encoding="utf-8"
    ) as handle:
        handle.write(text)
    os.replace(handle.name, target)
    return target
