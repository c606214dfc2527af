"""A robot's physics URDF as a MuJoCo model: joints with armature and Coulomb friction.

MuJoCo reads the URDF the PyBullet plant loads (:func:`robots.urdf_cache.derived_urdf`,
merged), so that the engine is the only difference, with three changes of form:
MuJoCo's own options in a ``<mujoco>`` element (the meshes where the URDF names them,
visual shapes dropped), each motor's armature on its joint (MuJoCo's ``armature``)
instead of the URDF's discs (:mod:`robots.native_armature`), and each motor's Coulomb
friction as the joint's ``frictionloss``, a constraint the solver holds implicitly as
PyBullet's velocity motor does. The robot's shapes touch the ground only (PyBullet
loads a URDF without self-collision). The integrator is MuJoCo's semi-implicit Euler,
PyBullet's: the drivers' torques are explicit either way, and no passive damping is left
for an implicit one to treat.
"""

from __future__ import annotations

import xml.etree.ElementTree as ET
from collections.abc import Mapping

import numpy as np

from planner.exceptions import ParameterError

try:
    import mujoco
except ImportError as error:  # pragma: no cover - mujoco is a dependency
    raise ImportError("the MuJoCo plant needs mujoco: pip install mujoco==3.3.7") from error

GRAVITY = 9.81  # [m/s^2]
# Collision bits: a robot shape collides with what has conaffinity 1 (the ground), never
# with another robot shape (both conaffinity 0).
ROBOT_CONTYPE, ROBOT_CONAFFINITY = 1, 0
GROUND_CONTYPE, GROUND_CONAFFINITY = 0, 1
ROLLING_FRICTION = 0.0  # [m] no rolling resistance, as PyBullet's default
TORSION_CONDIM = 4  # normal, two tangents and the torsion about the normal


def urdf_spec(
    urdf_text: str,
    time_step: float,
    armature: Mapping[str, float],
    friction_loss: Mapping[str, float],
    gravity: float = GRAVITY,
) -> mujoco.MjSpec:
    """The URDF ``urdf_text`` as a MuJoCo model specification, its root fixed to the world.

    Args:
        urdf_text: The URDF (meshes as absolute paths, or relative to the working folder).
        time_step: The physics step [s].
        armature: Joint -> its armature [kg m^2] (joints absent: none).
        friction_loss: Joint -> its Coulomb friction [N m] (joints absent: none).
        gravity: Downward gravity [m/s^2].

    Raises:
        ParameterError: A joint of ``armature`` or ``friction_loss`` is not a hinge of the
            URDF, a value is negative, or MuJoCo cannot read the URDF.
    """
    root = ET.fromstring(urdf_text)
    options = ET.SubElement(root, "mujoco")
    ET.SubElement(options, "compiler", strippath="false", discardvisual="true")
    try:
        spec = mujoco.MjSpec.from_string(ET.tostring(root, encoding="unicode"))
    except ValueError as error:
        raise ParameterError("urdf_text", str(error), "a URDF MuJoCo can read") from error
    spec.option.timestep = time_step
    spec.option.integrator = mujoco.mjtIntegrator.mjINT_EULER
    spec.option.gravity = np.array([0.0, 0.0, -gravity])
    hinge = mujoco.mjtJoint.mjJNT_HINGE
    hinges = {joint.name: joint for joint in spec.joints if joint.type == hinge}
    for field, values in (("armature", armature), ("frictionloss", friction_loss)):
        for name, value in values.items():
            if name not in hinges:
                raise ParameterError(field, name, "a revolute joint of the URDF")
            if not (np.isfinite(value) and value >= 0.0):
                raise ParameterError(f"{field}[{name}]", value, "a number >= 0")
            setattr(hinges[name], field, float(value))
    return spec


def add_floating_base_and_ground(
    spec: mujoco.MjSpec,
    feet: Mapping[str, str],
    friction: float,
    spinning_friction: float,
) -> None:
    """Free the root body and put a flat ground at z = 0 under it, in place.

    Args:
        spec: The robot (:func:`urdf_spec`).
        feet: Foot -> its ankle link (its shapes get the soles' torsional friction).
        friction: Friction coefficient [-] of every shape on the ground.
        spinning_friction: Torsional friction of the soles [m]: each contact resists a
            turn about the normal with up to this times its normal force (0: none).

    Raises:
        ParameterError: An ankle link is not a body of ``spec``, or a friction is not
            physical.
    """
    if not (np.isfinite(friction) and friction > 0.0):
        raise ParameterError("ground_friction", friction, "a friction coefficient > 0")
    if not (np.isfinite(spinning_friction) and spinning_friction >= 0.0):
        raise ParameterError("sole_spinning_friction", spinning_friction, "a number >= 0 m")
    spec.worldbody.first_body().add_freejoint()
    ankles = set(feet.values())
    missing = sorted(ankles - {body.name for body in spec.bodies})
    if missing:
        raise ParameterError("ankle link", missing[0], "a link of the physics URDF")
    coefficients = np.array([friction, spinning_friction, ROLLING_FRICTION])
    for geom in spec.geoms:
        geom.contype, geom.conaffinity = ROBOT_CONTYPE, ROBOT_CONAFFINITY
        geom.friction = coefficients
        sole = geom.parent.name in ankles and spinning_friction > 0.0
        geom.condim = TORSION_CONDIM if sole else 3
    ground = spec.worldbody.add_geom()
    ground.name = "ground"
    ground.type = mujoco.mjtGeom.mjGEOM_PLANE
    ground.size = np.array([0.0, 0.0, 1.0])  # an infinite plane
    ground.contype, ground.conaffinity = GROUND_CONTYPE, GROUND_CONAFFINITY
    ground.friction = coefficients
