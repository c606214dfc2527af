"""The robot is drawn where the simulation has it: the scene's transforms, composed
like the browser composes them, put the soles and the pelvis on the simulated ones."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import free_port

viser = pytest.importorskip("viser")
from viser import transforms as tf  # noqa: E402

WORLD_SHIFT = np.array([-0.4, 0.15, 0.0])  # [m] the page shifts /world to follow the robot
POSITION_TOLERANCE = 0.005  # [m]
ANGLE_TOLERANCE = np.radians(0.5)  # [rad]


def world_poses(nodes: dict) -> dict[str, np.ndarray]:
    """4x4 pose in the scene of every node, composed from the root through the parent
    names (viser: ``/a/b`` is a child of ``/a``), with each node's position and wxyz."""
    poses: dict[str, np.ndarray] = {}

    def pose(name: str) -> np.ndarray:
        if name not in poses:
            handle = nodes[name]
            local = np.eye(4)
            local[:3, :3] = tf.SO3(np.asarray(handle.wxyz, float)).as_matrix()
            local[:3, 3] = handle.position
            parent = name.rsplit("/", 1)[0]
            poses[name] = (pose(parent) if parent else np.eye(4)) @ local
        return poses[name]

    for name in nodes:
        pose(name)
    return poses


def rotation_angle(a: np.ndarray, b: np.ndarray) -> float:
    return float(np.arccos(np.clip((np.trace(a.T @ b) - 1.0) / 2.0, -1.0, 1.0)))


@pytest.fixture(scope="module")
def server():
    server = viser.ViserServer(host="127.0.0.1", port=free_port(), verbose=False)
    yield server
    server.stop()


@pytest.mark.parametrize("engine", ["pybullet", "mujoco"])
def test_drawn_soles_and_pelvis_are_the_simulated_ones(server, engine):
    """Standing, mid-swing of each foot and after a push, on either engine: every drawn
    sole within 5 mm and 0.5 deg of the engine's own sole frame, the pelvis within 5 mm
    of the simulated base, and the drawn stance foot's lowest vertex on the ground."""
    from app.runner import ClosedLoop
    from app.scenarios import Scenario
    from app.setup.build import build_backend
    from planner.types import Push
    from robots.urdf_cache import derived_urdf
    from web.robot_view import RobotView

    backend, config, initial = build_backend(engine, "g1", "rsg", reality="ideal")
    push = Push(1.5, np.array([0.0, 4.0]), 0.1)
    loop = ClosedLoop(backend, config, Scenario("walk", 3.0, (push,)), initial)
    world = server.scene.add_frame("/world", show_axes=False, position=WORLD_SHIFT)
    view = RobotView(server.scene, derived_urdf(backend.description), "/world/robot")
    assert len(view.joint_names) == 29
    nodes = {"/world": world, **view.nodes}
    ankle_meshes = {
        foot: [n for n in view.nodes if n.startswith(view.link_nodes[link] + "/visual")]
        for foot, link in (("left", "left_ankle_roll_link"), ("right", "right_ankle_roll_link"))
    }
    swing_heights = []
    swung: list[str] = []
    try:
        # start, the first foot mid-swing, the other mid-swing, pushed
        for wanted in (None, "first", "second", 1.65):
            if isinstance(wanted, float):
                while loop.time < wanted - 1e-9:
                    loop.tick()
            elif wanted is not None:  # until a sole that has not swung yet is 3 cm up
                while True:
                    loop.tick()
                    up = [f for f, p in backend.sole_positions().items() if p[2] > 0.03]
                    if up and up[0] not in swung:
                        swung.append(up[0])
                        break
            time = round(loop.time, 3)
            position, quaternion_xyzw, joints = backend.robot_configuration()
            x, y, z, w = quaternion_xyzw
            view.update(position, np.array([w, x, y, z]), joints)
            poses = world_poses(nodes)
            case = f"{engine} t={time} s"
            pelvis = poses[view.link_nodes["pelvis"]]
            np.testing.assert_allclose(
                pelvis[:3, 3], position + WORLD_SHIFT, atol=POSITION_TOLERANCE, err_msg=case
            )
            heights = {}
            for foot, frame in (("left", "left_foot"), ("right", "right_foot")):
                sole_position, sole_rotation = backend.sim.sole_frame(foot)
                drawn = poses[view.link_nodes[frame]]
                np.testing.assert_allclose(
                    drawn[:3, 3],
                    sole_position + WORLD_SHIFT,
                    atol=POSITION_TOLERANCE,
                    err_msg=f"{case} {foot} sole",
                )
                assert rotation_angle(drawn[:3, :3], sole_rotation) < ANGLE_TOLERANCE, case
                heights[foot] = sole_position[2]
                lowest = min(
                    float(np.min((poses[m][:3, :3] @ view.nodes[m].vertices.T)[2] + poses[m][2, 3]))
                    for m in ankle_meshes[foot]
                )
                if sole_position[2] < 0.005:  # on the ground: its drawn foot too
                    assert abs(lowest) < POSITION_TOLERANCE, f"{case} {foot}: lowest {lowest}"
            swing_heights.append(max(heights.values()))
    finally:
        backend.close()
        world.remove()
    assert swing_heights[1] > 0.02 and swing_heights[2] > 0.02, swing_heights  # mid-swing


def test_meshes_are_drawn_with_fewer_faces_within_the_tolerance():
    """Software WebGL is bound by vertices: a fine mesh is decimated, its surface within
    MESH_TOLERANCE of the original; no tolerance keeps the mesh as it is."""
    import trimesh

    from web.robot_view import MESH_TOLERANCE, simplified

    sphere = trimesh.creation.icosphere(subdivisions=5, radius=0.1)
    reduced = simplified(sphere)
    assert len(reduced.faces) <= 0.35 * len(sphere.faces)
    _, distance, _ = trimesh.proximity.closest_point(reduced, sphere.vertices)
    assert np.percentile(distance, 99) <= MESH_TOLERANCE
    assert simplified(sphere, tolerance=0.0) is sphere
