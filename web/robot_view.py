"""The full robot on the page: URDF meshes posed from the simulated configuration.

:class:`RobotView` loads the URDF with :class:`viser.extras.ViserUrdf` (meshes and one
frame per joint) and poses it each frame. ``ViserUrdf.update_cfg`` recomputes every
joint transform through yourdfpy's scene graph (about 12 ms for the G1, too slow
for 30 Hz next to the simulation); here only the moving joints are updated, with
their rotations computed in closed form (vectorised quaternions). Fixed joints keep
the transforms ViserUrdf set when loading.

This relies on ViserUrdf's joint-frame list (viser 1.1.1, pinned); on another
version without it, the view falls back to ``update_cfg``.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import viser
from numpy.typing import NDArray
from viser import transforms as tf
from viser.extras import ViserUrdf

Array = NDArray[np.float64]


def _quaternion_multiply(a: Array, b: Array) -> Array:
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


class RobotView:
    """The robot's meshes under scene node ``root`` [m, rad].

    Args:
        server: The viser server.
        urdf: Path of the URDF (absolute mesh paths, e.g. the derived URDF).
        root: Scene node of the robot's base (its pose is the base pose).
    """

    def __init__(self, server: viser.ViserServer, urdf: Path, root: str) -> None:
        self.base = server.scene.add_frame(root, show_axes=False)
        self.urdf = ViserUrdf(server, urdf, root_node_name=root)
        self.joint_names = self.urdf.get_actuated_joint_names()
        frames = getattr(self.urdf, "_joint_frames", None)
        joints = getattr(self.urdf, "_joint_map_values", None)
        self._moving: list[tuple[int, viser.FrameHandle]] = []
        origins, axes = [], []
        if frames is not None and joints is not None and len(frames) == len(joints):
            for joint, frame in zip(joints, frames, strict=True):
                if joint.type not in ("revolute", "continuous") or joint.mimic is not None:
                    if joint.type == "prismatic" or joint.mimic is not None:
                        self._moving = []
                        break  # not handled in closed form: use update_cfg
                    continue
                origin = np.eye(4) if joint.origin is None else np.asarray(joint.origin)
                origins.append(tf.SO3.from_matrix(origin[:3, :3]).wxyz)
                axis = np.asarray(joint.axis, dtype=float)
                axes.append(axis / np.linalg.norm(axis))
                self._moving.append((self.joint_names.index(joint.name), frame))
        self._origin_wxyz = np.array(origins).reshape(-1, 4)
        self._axes = np.array(axes).reshape(-1, 3)

    def update(self, base_position: Array, base_wxyz: Array, joints: dict[str, float]) -> None:
        """Pose the robot: base position [m], base quaternion (w, x, y, z), joint angles [rad]."""
        self.base.position = base_position
        self.base.wxyz = base_wxyz
        q = np.array([joints.get(name, 0.0) for name in self.joint_names])
        if not self._moving:
            self.urdf.update_cfg(q)
            return
        angles = q[[index for index, _ in self._moving]]
        motion = np.concatenate(
            [np.cos(angles / 2.0)[:, None], np.sin(angles / 2.0)[:, None] * self._axes], axis=1
        )
        wxyz = _quaternion_multiply(self._origin_wxyz, motion)
        for (_, frame), rotation in zip(self._moving, wxyz, strict=True):
            frame.wxyz = rotation
