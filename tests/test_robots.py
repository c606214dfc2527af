"""Robot descriptions and the derived URDF."""

from __future__ import annotations

import dataclasses
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest

from planner.exceptions import ParameterError
from robots import available_robots, get_robot
from robots.urdf_cache import derive_urdf_text, derived_urdf, robots_share_dir
from robots.urdf_merge import lock_joints, merge_fixed_links


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path))


def test_registry_lists_g1_and_talos_and_rejects_unknown_names():
    assert {"g1", "talos"} <= set(available_robots())
    assert get_robot("talos").name == "talos"
    assert get_robot("g1").name == "g1"
    with pytest.raises(ParameterError) as error:
        get_robot("no_such_robot")
    assert "g1" in error.value.allowed


def test_description_validates_its_fields():
    g1 = get_robot("g1")
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, com_height=-1.0)
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, urdf_source="/abs/path.urdf")
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, left_ankle_link=g1.right_ankle_link)


@pytest.mark.parametrize("value", [-0.01, 0.2, float("nan")])
def test_sole_spinning_friction_is_validated(value):
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(get_robot("g1"), sole_spinning_friction=value)
    assert error.value.field == "sole_spinning_friction"


@pytest.mark.parametrize("value", [0.0, 0.01])
def test_soles_get_their_torsional_friction_in_pybullet(value):
    """The soles' spinning friction reaches PyBullet; the other links keep none."""
    from app.backends.pybullet_robot import SimulatedRobot

    robot = SimulatedRobot(dataclasses.replace(get_robot("g1"), sole_spinning_friction=value))
    try:
        dynamics = robot.client.getDynamicsInfo
        for link in robot.foot_links.values():
            assert dynamics(robot.body, link)[7] == pytest.approx(value)
        others = set(range(robot.link_count)) - set(robot.foot_links.values())
        assert all(dynamics(robot.body, link)[7] == 0.0 for link in others)
    finally:
        robot.close()


def test_derived_urdf_is_reproducible_and_has_the_frames(tmp_path):
    g1 = get_robot("g1")
    path = derived_urdf(g1)
    assert path.is_relative_to(tmp_path)
    first = path.read_text()
    path.unlink()
    assert derived_urdf(g1).read_text() == first
    source = (robots_share_dir() / g1.urdf_source).read_text()
    assert derive_urdf_text(g1, source, robots_share_dir()) == first

    root = ET.fromstring(first)
    links = {link.get("name"): link for link in root.iter("link")}
    for frame in ("left_foot", "right_foot", "trunk"):
        assert frame in links
    assert all(link.find("inertial") is not None for link in links.values())
    meshes = [mesh.get("filename") for mesh in root.iter("mesh")]
    assert meshes and not any(name.startswith("package://") for name in meshes)
    joints = {joint.find("child").get("link"): joint for joint in root.iter("joint")}
    assert joints["left_foot"].find("parent").get("link") == g1.left_ankle_link
    assert joints["left_foot"].find("origin").get("xyz") == "0 0 -0.035"


def test_urdf_mass_matches_description():
    g1 = get_robot("g1")
    root = ET.parse(derived_urdf(g1)).getroot()
    mass = sum(float(element.get("value")) for element in root.iter("mass"))
    assert mass == pytest.approx(g1.total_mass, abs=0.1)


SYNTHETIC_URDF = """<robot name="r">
  <link name="a"><inertial><origin xyz="0 0 0.1" rpy="0 0 0"/><mass value="2"/>
    <inertia ixx="0.1" ixy="0" ixz="0" iyy="0.2" iyz="0" izz="0.3"/></inertial></link>
  <link name="b"><inertial><origin xyz="0.2 0 0" rpy="0 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.02" iyz="0" izz="0.03"/></inertial>
    <collision><origin xyz="0.1 0 0" rpy="0 0 0"/><geometry><box size="1 1 1"/></geometry>
    </collision></link>
  <link name="c"/>
  <joint name="ab" type="fixed"><origin xyz="0 0.5 0" rpy="0 0 1.5707963267948966"/>
    <parent link="a"/><child link="b"/></joint>
  <joint name="bc" type="revolute"><origin xyz="0 0 1" rpy="0 0 0"/><axis xyz="1 0 0"/>
    <parent link="b"/><child link="c"/><limit lower="-1" upper="1" effort="1" velocity="1"/>
  </joint>
</robot>"""


C_LINK = """<link name="c"><inertial><origin xyz="0 0.3 0" rpy="0 0 0"/><mass value="1"/>
    <inertia ixx="0.01" ixy="0" ixz="0" iyy="0.01" iyz="0" izz="0.01"/></inertial></link>"""


def test_merging_a_fixed_link_keeps_mass_com_inertia_and_shapes_in_place():
    root = ET.fromstring(SYNTHETIC_URDF)
    merge_fixed_links(root)
    assert [link.get("name") for link in root.iter("link")] == ["a", "c"]
    inertial = root.find("link/inertial")
    assert float(inertial.find("mass").get("value")) == pytest.approx(3.0)
    # b's CoM: (0, 0.5, 0) + Rz(90 deg) (0.2, 0, 0) = (0, 0.7, 0).
    com = [float(v) for v in inertial.find("origin").get("xyz").split()]
    assert com == pytest.approx([0.0, 0.7 / 3, 0.2 / 3])
    tensor = inertial.find("inertia")
    # ixx: a 0.1 + 2 (y^2 + z^2) about the new CoM, b 0.02 (rotated) + 1 (...)
    ixx = 0.1 + 2 * ((0.7 / 3) ** 2 + (0.1 - 0.2 / 3) ** 2)
    ixx += 0.02 + 1 * ((0.7 - 0.7 / 3) ** 2 + (0.2 / 3) ** 2)
    assert float(tensor.get("ixx")) == pytest.approx(ixx)
    box = root.find("link/collision/origin")
    assert [float(v) for v in box.get("xyz").split()] == pytest.approx([0.0, 0.6, 0.0])
    joint = root.find("joint")
    assert joint.find("parent").get("link") == "a"
    assert [float(v) for v in joint.find("origin").get("xyz").split()] == pytest.approx(
        [0.0, 0.5, 1.0]
    )
    assert [float(v) for v in joint.find("origin").get("rpy").split()] == pytest.approx(
        [0.0, 0.0, 1.5707963267948966]
    )


def test_merged_g1_has_the_same_mass_and_com_in_pybullet_with_its_locked_joints_welded():
    """The physics URDF (locked joints welded at their standing angle, fixed links
    merged) has the free joints of the full URDF and, with the locked joints of the
    full one at their standing angles, the same mass and whole-body CoM."""
    import numpy as np
    import pybullet
    from pybullet_utils.bullet_client import BulletClient

    g1 = get_robot("g1")
    assert len(g1.locked_joints) == 10
    merged = ET.parse(derived_urdf(g1, merged=True)).getroot()
    assert not [joint for joint in merged.iter("joint") if joint.get("type") == "fixed"]
    coms = []
    for path in (derived_urdf(g1), derived_urdf(g1, merged=True)):
        client = BulletClient(connection_mode=pybullet.DIRECT)
        body = client.loadURDF(str(path), flags=pybullet.URDF_USE_INERTIA_FROM_FILE)
        joints = {}
        for index in range(client.getNumJoints(body)):
            info = client.getJointInfo(body, index)
            if info[2] == pybullet.JOINT_REVOLUTE:
                joints[info[1].decode()] = index
        free = sorted(set(joints) - set(g1.locked_joints))
        for number, name in enumerate(free):
            client.resetJointState(body, joints[name], 0.3 * np.sin(number))
        for name in set(joints) & set(g1.locked_joints):
            client.resetJointState(body, joints[name], g1.standing_posture.get(name, 0.0))
        links = range(client.getNumJoints(body))
        masses = [client.getDynamicsInfo(body, link)[0] for link in (-1, *links)]
        positions = [client.getBasePositionAndOrientation(body)[0]]
        positions += [state[0] for state in client.getLinkStates(body, list(links))]
        coms.append((sorted(joints), sum(masses), np.array(masses) @ np.array(positions)))
        client.disconnect()
    (names, mass, moment), (merged_names, merged_mass, merged_moment) = coms
    assert len(names) == 29
    assert merged_names == sorted(set(names) - set(g1.locked_joints))
    assert merged_mass == pytest.approx(mass, abs=1e-9)
    assert merged_moment / merged_mass == pytest.approx(moment / mass, abs=1e-6)


def test_locking_a_joint_welds_its_child_where_that_angle_puts_it():
    """bc (about x) locked at 0.5 rad, then merged: c's CoM lands where the joint at
    0.5 rad puts it."""
    import math

    root = ET.fromstring(SYNTHETIC_URDF.replace('<link name="c"/>', C_LINK))
    lock_joints(root, {"bc": 0.5})
    merge_fixed_links(root)
    assert [link.get("name") for link in root.iter("link")] == ["a"]
    inertial = root.find("link/inertial")
    assert float(inertial.find("mass").get("value")) == pytest.approx(4.0)
    com = np.array([float(v) for v in inertial.find("origin").get("xyz").split()])
    # a: 2 kg at (0, 0, 0.1); b: 1 kg at (0, 0.7, 0); c: 1 kg, its CoM in b's frame at
    # (0, 0.3 cos 0.5, 1 + 0.3 sin 0.5), and b is a's frame moved by (0, 0.5, 0) and
    # turned by 90 deg about z (b's y axis is a's -x).
    c_com = np.array([-0.3 * math.cos(0.5), 0.5, 1.0 + 0.3 * math.sin(0.5)])
    expected = (2 * np.array([0.0, 0.0, 0.1]) + np.array([0.0, 0.7, 0.0]) + c_com) / 4
    assert com == pytest.approx(expected)


def test_locking_names_only_revolute_joints():
    root = ET.fromstring(SYNTHETIC_URDF)
    with pytest.raises(ParameterError) as error:
        lock_joints(root, {"ab": 0.0})  # fixed already
    assert error.value.field == "locked_joints" and error.value.value == "ab"
    with pytest.raises(ParameterError):
        lock_joints(root, {"no_such_joint": 0.0})


def test_locked_joints_are_validated_against_the_upper_body_and_the_urdf():
    from kinematics.whole_body_ik import WholeBodyIK

    g1 = get_robot("g1")
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(g1, locked_joints=(g1.upper_body_joints[0],))
    assert error.value.field == "locked_joints"
    with pytest.raises(ParameterError):
        dataclasses.replace(g1, locked_joints=("a_joint", "a_joint"))
    with pytest.raises(ParameterError) as error:
        WholeBodyIK(dataclasses.replace(g1, locked_joints=("no_such_joint",)))
    assert error.value.value == ["no_such_joint"]


@pytest.mark.parametrize("value", [0.2, -0.2, float("nan")])
def test_dcm_inset_of_a_description_is_validated(value):
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(get_robot("g1"), dcm_inset=value)
    assert error.value.field == "dcm_inset"


def test_talos_description_validates_and_names_joints_of_its_urdf():
    talos = get_robot("talos")
    with pytest.raises(ParameterError):
        dataclasses.replace(talos, sole_offset=(0.0, 0.0, 0.107))
    root = ET.parse(derived_urdf(talos)).getroot()
    joints = {joint.get("name") for joint in root.findall("joint") if joint.get("type") != "fixed"}
    assert set(talos.standing_posture) <= joints


def test_talos_derived_urdf_has_sole_frames_under_the_ankles_and_resolved_meshes():
    talos = get_robot("talos")
    root = ET.parse(derived_urdf(talos)).getroot()
    links = {link.get("name"): link for link in root.iter("link")}
    assert {"left_foot", "right_foot", "trunk"} <= set(links)
    assert all(link.find("inertial") is not None for link in links.values())
    joints = {joint.find("child").get("link"): joint for joint in root.findall("joint")}
    for frame, ankle in (("left_foot", "leg_left_6_link"), ("right_foot", "leg_right_6_link")):
        assert joints[frame].find("parent").get("link") == ankle
        assert joints[frame].find("origin").get("xyz") == "0 0 -0.107"
    assert joints["trunk"].find("parent").get("link") == "torso_2_link"
    meshes = [mesh.get("filename") for mesh in root.iter("mesh")]
    assert meshes and not any(name.startswith("package://") for name in meshes)
    assert all(Path(name).is_file() for name in meshes)
    mass = sum(float(element.get("value")) for element in root.iter("mass"))
    assert mass == pytest.approx(talos.total_mass, abs=0.1)


def test_talos_mass_in_pybullet_and_placo_equals_the_urdf_mass():
    from app.backends.pybullet_robot import SimulatedRobot
    from kinematics.whole_body_ik import WholeBodyIK

    talos = get_robot("talos")
    robot = SimulatedRobot(talos)
    try:
        assert robot.mass == pytest.approx(talos.total_mass, abs=0.01)
        assert len(robot.joint_names) == 32
    finally:
        robot.close()
    assert WholeBodyIK(talos).robot.total_mass() == pytest.approx(talos.total_mass, abs=0.01)


@pytest.mark.parametrize("value", [0.0, 0.0004, 0.006, float("nan")])
def test_physics_time_step_is_validated(value):
    with pytest.raises(ParameterError) as error:
        dataclasses.replace(get_robot("g1"), physics_time_step=value)
    assert error.value.field == "physics_time_step"


@pytest.mark.parametrize("name", ["g1", "talos"])
def test_each_leg_is_the_chain_from_the_pelvis_to_its_ankle(name):
    """``kinematics.whole_body_ik.leg_joints`` per foot: six joints per leg, disjoint,
    moving only their own foot, and ending with the two joints nearest the sole (the
    ankle's)."""
    from kinematics.robot_model import RobotModel
    from kinematics.whole_body_ik import humanoid_robot, leg_joints

    description = get_robot(name)
    model = RobotModel(description)
    chains = leg_joints(humanoid_robot(description).model)
    legs = {foot: model.index_of(chains[foot]) for foot in ("left", "right")}
    assert all(len(leg) == 6 for leg in legs.values())
    assert not set(legs["left"]) & set(legs["right"])
    for foot, leg in legs.items():
        assert all(model.is_ankle(model.joint_names[i]) for i in leg[-2:])
        # Moving this leg's joints moves its own sole and not the other one.
        q = np.concatenate([[0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0], np.zeros(len(model.joint_names))])
        model.update(q, np.zeros(model.nv))
        before = {f: model.sole_frame(f)[0] for f in ("left", "right")}
        q[7 + leg] += 0.1
        model.update(q, np.zeros(model.nv))
        other = "right" if foot == "left" else "left"
        assert np.linalg.norm(model.sole_frame(foot)[0] - before[foot]) > 0.01
        np.testing.assert_allclose(model.sole_frame(other)[0], before[other], atol=1e-12)


def test_sole_positions_at_another_configuration_leave_the_state_alone():
    """``RobotModel.sole_positions_at(q)`` is forward kinematics at ``q``: the soles where
    :meth:`update` with ``q`` puts them, and the model's own state, its frames included,
    as it was."""
    from kinematics.robot_model import RobotModel

    model = RobotModel(get_robot("g1"))
    rng = np.random.default_rng(0)
    state = np.concatenate([[0.1, -0.2, 0.7, 0.0, 0.0, 0.0, 1.0], np.zeros(len(model.joint_names))])
    model.update(state, np.zeros(model.nv))
    before = {f: model.sole_frame(f)[0] for f in ("left", "right")}
    other = state.copy()
    other[7:] = rng.uniform(-0.3, 0.3, len(model.joint_names))
    other[3:7] = [0.0, np.sin(0.1), 0.0, np.cos(0.1)]  # pitched 0.2 rad
    moved = model.sole_positions_at(other)
    for foot in ("left", "right"):
        np.testing.assert_array_equal(model.sole_frame(foot)[0], before[foot])
    assert all(np.linalg.norm(moved[f] - before[f]) > 0.01 for f in ("left", "right"))
    model.update(other, np.zeros(model.nv))
    for foot in ("left", "right"):
        np.testing.assert_allclose(moved[foot], model.sole_frame(foot)[0], atol=1e-12)
