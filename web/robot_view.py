"""The full robot on the page: URDF meshes posed from the simulated configuration.

:class:`RobotView` builds the robot's scene tree itself, with viser's public scene
API: one frame per URDF link, nested like the kinematic tree (viser names nodes by
path, ``/a/b`` is a child of ``/a``), each placed at its joint's origin when built,
and the link's visual meshes under it. Posing the robot then writes the base pose
and, for each moving joint, one quaternion: origin rotation times the rotation
about the joint axis (the translation of a revolute joint never changes). The
browser composes the tree, so every link is drawn where forward kinematics puts
it. viser sends a pose only when it changed. Each mesh is drawn decimated, within 2 mm
of the original (:func:`simplified`; under a pixel at the default view): a browser
without GPU is bound by vertices, and G1's 290k triangles become 89k.

(viser's ``ViserUrdf`` recomputes every transform through yourdfpy's scene graph in
``update_cfg``, about 12 ms a frame for the G1, and keeps its frames private.)
"""

from __future__ import annotations

import functools
from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import trimesh
import viser
import yourdfpy
from numpy.typing import NDArray
from viser import transforms as tf

from planner.exceptions import ParameterError

Array = NDArray[np.float64]
DEFAULT_COLOUR = (180, 180, 180)  # links without a material colour
# Software WebGL is bound by vertices (G1's 290k triangles: under 1 frame/s even in a
# small window): each mesh is drawn with the fewest faces, of these fractions, whose
# surface stays within MESH_TOLERANCE of the original's sampled vertices.
MESH_FRACTIONS = (0.05, 0.1, 0.2, 0.35, 0.5)
MESH_TOLERANCE = 0.002  # [m], at the 99th percentile of the sampled vertices
MESH_SAMPLES = 300  # vertices checked per mesh
MESH_MIN_FACES = 64  # smaller meshes are drawn as they are


def quaternion_multiply(a: Array, b: Array) -> Array:
    """Hamilton products of quaternions (w, x, y, z), row by row, shape (n, 4)."""
    aw, ax, ay, az = a.T
    bw, bx, by, bz = b.T
    return np.stack(
        [
            aw * bw - ax * bx - ay * by - az * bz,
            aw * bx + ax * bw + ay * bz - az * by,
            aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw,
        ],
        axis=1,
    )


@dataclass(frozen=True)
class _MovingJoint:
    name: str
    frame: viser.FrameHandle
    origin_wxyz: NDArray[np.floating]
    axis: NDArray[np.floating]


def _colour_of(visual: yourdfpy.Visual, materials: Mapping[str, Array]) -> tuple[int, int, int]:
    material = visual.material
    rgba = None
    if material is not None:
        if material.color is not None:
            rgba = material.color.rgba
        elif material.name in materials:
            rgba = materials[material.name]
    if rgba is None:
        return DEFAULT_COLOUR
    r, g, b = (int(round(255 * float(c))) for c in np.asarray(rgba)[:3])
    return (r, g, b)


def _visual_mesh(visual: yourdfpy.Visual, urdf: Path) -> trimesh.Trimesh | None:
    """The visual's geometry in its link frame [m], or None if it has none."""
    geometry = visual.geometry
    if geometry.mesh is not None:
        path = Path(geometry.mesh.filename)
        loaded = trimesh.load(path if path.is_absolute() else urdf.parent / path, force="mesh")
        if not isinstance(loaded, trimesh.Trimesh):
            return None
        mesh = loaded
        if geometry.mesh.scale is not None:
            mesh.apply_scale(geometry.mesh.scale)
    elif geometry.box is not None:
        mesh = trimesh.creation.box(extents=geometry.box.size)
    elif geometry.cylinder is not None:
        mesh = trimesh.creation.cylinder(geometry.cylinder.radius, geometry.cylinder.length)
    elif geometry.sphere is not None:
        mesh = trimesh.creation.icosphere(radius=geometry.sphere.radius)
    else:
        return None
    if visual.origin is not None:
        mesh.apply_transform(visual.origin)
    return mesh


def simplified(mesh: trimesh.Trimesh, tolerance: float = MESH_TOLERANCE) -> trimesh.Trimesh:
    """``mesh`` with the fewest faces (quadric decimation, :data:`MESH_FRACTIONS`) whose
    surface is within ``tolerance`` [m] of 99 % of the original's sampled vertices;
    ``mesh`` itself if no fraction is."""
    if len(mesh.faces) <= MESH_MIN_FACES:
        return mesh
    rng = np.random.default_rng(0)
    probe = mesh.vertices[rng.choice(len(mesh.vertices), min(MESH_SAMPLES, len(mesh.vertices)))]
    for fraction in MESH_FRACTIONS:
        reduced = mesh.simplify_quadric_decimation(
            face_count=max(MESH_MIN_FACES, int(fraction * len(mesh.faces)))
        )
        _, distance, _ = trimesh.proximity.closest_point(reduced, probe)
        if np.percentile(distance, 99) <= tolerance:
            return reduced
    return mesh


@functools.lru_cache(maxsize=4)
def _link_meshes(
    urdf: Path,
) -> dict[tuple[str, int], tuple[NDArray, NDArray, tuple[int, int, int]]]:
    """(link, visual index) -> (vertices [m], faces, colour) of the URDF's visuals, loaded
    once per URDF: every browser tab builds its own robot from them."""
    robot = yourdfpy.URDF.load(urdf, build_scene_graph=False, load_meshes=False).robot
    materials = {m.name: m.color.rgba for m in robot.materials if m.color is not None}
    meshes = {}
    for link in robot.links:
        for index, visual in enumerate(link.visuals):
            mesh = _visual_mesh(visual, urdf)
            if mesh is not None:
                mesh = simplified(mesh)
                meshes[(link.name, index)] = (
                    np.asarray(mesh.vertices, np.float32),
                    np.asarray(mesh.faces, np.uint32),
                    _colour_of(visual, materials),
                )
    return meshes


class RobotView:
    """The robot's meshes under scene node ``root`` [m, rad].

    Args:
        scene: The scene to draw in: a server's (every tab) or one client's.
        urdf: Path of the URDF (absolute mesh paths, e.g. the derived URDF).
        root: Scene node of the robot's base link (its pose is the base pose).

    Attributes:
        joint_names: Moving (revolute) joints, in URDF order.
        nodes: Every scene node of the robot by name: link frames and meshes.
        link_nodes: Scene node name of each URDF link.

    Raises:
        ParameterError: The URDF has a joint type other than fixed, revolute or
            continuous.
    """

    def __init__(self, scene: viser.SceneApi, urdf: Path, root: str) -> None:
        model = yourdfpy.URDF.load(urdf, build_scene_graph=False, load_meshes=False)
        robot = model.robot
        meshes = _link_meshes(urdf)
        children: dict[str, list[yourdfpy.Joint]] = {}
        for joint in robot.joints:
            children.setdefault(joint.parent, []).append(joint)
        child_links = {joint.child for joint in robot.joints}
        base = next(link.name for link in robot.links if link.name not in child_links)

        self.base = scene.add_frame(root, show_axes=False)
        self.nodes: dict[str, viser.SceneNodeHandle] = {root: self.base}
        self.link_nodes: dict[str, str] = {base: root}
        moving: list[_MovingJoint] = []
        pending = [base]
        while pending:
            link = pending.pop()
            for joint in children.get(link, []):
                if joint.type not in ("fixed", "revolute", "continuous"):
                    raise ParameterError(
                        f"joint {joint.name} type", joint.type, "fixed, revolute or continuous"
                    )
                origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin, float)
                wxyz = tf.SO3.from_matrix(origin[:3, :3]).wxyz
                name = f"{self.link_nodes[link]}/{joint.child}"
                frame = scene.add_frame(name, show_axes=False, position=origin[:3, 3], wxyz=wxyz)
                self.nodes[name] = frame
                self.link_nodes[joint.child] = name
                if joint.type != "fixed":
                    axis = np.asarray(joint.axis, dtype=float) / np.linalg.norm(joint.axis)
                    moving.append(_MovingJoint(joint.name, frame, wxyz, axis))
                pending.append(joint.child)
        for (link, index), (vertices, faces, colour) in meshes.items():
            mesh_name = f"{self.link_nodes[link]}/visual_{index}"
            self.nodes[mesh_name] = scene.add_mesh_simple(
                mesh_name, vertices, faces, color=colour, cast_shadow=False, receive_shadow=False
            )
        order = {joint.name: index for index, joint in enumerate(robot.joints)}
        moving.sort(key=lambda joint: order[joint.name])
        self._moving = moving
        self.joint_names = tuple(joint.name for joint in moving)
        self._origin_wxyz = np.array([joint.origin_wxyz for joint in moving]).reshape(-1, 4)
        self._axes = np.array([joint.axis for joint in moving]).reshape(-1, 3)

    @property
    def visible(self) -> bool:
        """Whether the robot is drawn."""
        return self.base.visible

    @visible.setter
    def visible(self, visible: bool) -> None:
        self.base.visible = visible

    def update(self, base_position: Array, base_wxyz: Array, joints: Mapping[str, float]) -> None:
        """Pose the robot: base position [m], base quaternion (w, x, y, z), joint angles [rad].

        Raises:
            ParameterError: ``joints`` lacks a moving joint of the URDF.
        """
        try:
            angles = np.array([joints[name] for name in self.joint_names], dtype=float)
        except KeyError as missing:
            raise ParameterError("joints", sorted(joints), f"every joint, {missing} too") from None
        self.base.position = base_position
        self.base.wxyz = base_wxyz
        half = 0.5 * angles
        motion = np.concatenate([np.cos(half)[:, None], np.sin(half)[:, None] * self._axes], axis=1)
        wxyz = quaternion_multiply(self._origin_wxyz, motion)
        for joint, rotation in zip(self._moving, wxyz, strict=True):
            joint.frame.wxyz = rotation
