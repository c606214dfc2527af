"""The whole-body controller's tick (:mod:`app.stabilizer.controller`) on measurement
records made by hand: it needs no simulator, and what it commands holds the robot."""

from __future__ import annotations

import dataclasses
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from app.lowlevel import FootForce, ImuReading, JointCommand, RobotMeasurement
from app.stabilizer.centroidal import height_acceleration
from app.stabilizer.config import StabilizerConfig
from app.stabilizer.controller import WholeBodyController
from conftest import LEFT, RIGHT, command
from kinematics.robot_model import RobotModel
from kinematics.swing_foot import SwingTiming
from kinematics.whole_body_ik import sole_pose
from planner.parameters import GRAVITY
from robots import get_robot

G1 = get_robot("g1")
ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


# G1 with foot force sensors: the hand-made readings say which foot carries what.
G1_SENSED = dataclasses.replace(G1, foot_force_sensors=True)


def standing() -> tuple[WholeBodyController, RobotMeasurement]:
    """A controller reset on G1's two feet, and what the robot senses standing still
    where the IK put it, each foot carrying half the weight under its ankle."""
    controller = WholeBodyController(G1_SENSED, SwingTiming(), 0.01, StabilizerConfig())
    soles = {
        "left": sole_pose(np.array([*LEFT.position, 0.0])),
        "right": sole_pose(np.array([*RIGHT.position, 0.0])),
    }
    angles = controller.reset(soles, "left", np.zeros(2))
    base = np.asarray(controller.ik.robot.get_T_world_fbase(), float)
    half = controller.mass * GRAVITY / 2
    measurement = RobotMeasurement(
        time=0.0,
        joint_positions=angles,
        joint_velocities=np.zeros(len(angles)),
        joint_torques=np.zeros(len(angles)),
        imu=ImuReading(
            Rotation.from_matrix(base[:3, :3]).as_quat(),
            np.zeros(3),
            base[:3, :3].T @ np.array([0.0, 0.0, GRAVITY]),
        ),
        foot_forces={
            "left": FootForce(half, LEFT.position),
            "right": FootForce(half, RIGHT.position),
        },
    )
    return controller, measurement


def lifted(measurement: RobotMeasurement, height: float) -> RobotMeasurement:
    """``measurement`` with the legs' joints bent so that the left sole is ``height`` [m]
    above the right (the left knee and hip pitch bent, the base as it was)."""
    controller, _ = standing()
    model = controller.model
    joints = model.index_of(["left_hip_pitch_joint", "left_knee_joint", "left_ankle_pitch_joint"])
    angles = measurement.joint_positions.copy()
    for scale in np.linspace(0.0, 1.0, 400):
        trial = measurement.joint_positions.copy()
        trial[joints] += scale * np.array([-0.6, 1.2, -0.6])
        q = np.concatenate([np.zeros(3), measurement.imu.orientation, trial])
        soles = model.sole_positions_at(q)
        if soles["left"][2] - soles["right"][2] >= height:
            angles = trial
            break
    return dataclasses.replace(measurement, joint_positions=angles)


def test_a_tick_on_a_hand_made_measurement_holds_the_robot_up():
    """Standing, CoM over the middle of the feet: the command has one entry per joint,
    the contact forces the feed-forward is computed for carry m g (and the height loop's
    m zdd for the stood CoM's height error, a fraction of a millimetre), and with them
    the floating base is in equilibrium (the base rows of the dynamics balance)."""
    controller, measurement = standing()
    order = controller.tick(measurement, command(0.0, np.zeros(2)))
    count = len(controller.model.joint_names)
    assert isinstance(order, JointCommand)
    for field in dataclasses.fields(order):
        value = getattr(order, field.name)
        assert value.shape == (count,) and np.all(np.isfinite(value)), field.name
    np.testing.assert_allclose(order.position, measurement.joint_positions, atol=1e-3)
    assert np.all(order.stiffness > 0.0) and np.all(order.damping > 0.0)

    contact = controller.expected_contact_force
    rotation = Rotation.from_quat(measurement.imu.orientation).as_matrix()
    force_in_world = rotation @ contact[:3]  # the base's linear rows: the net force
    target = min(pose[2] for pose in controller.sole_targets.values()) + G1.com_height
    assert controller.state is not None
    lift = height_acceleration(
        controller.config.height_frequency, target - controller.state.com[2], 0.0
    )
    assert abs(lift) < 0.01 * GRAVITY
    assert force_in_world[2] == pytest.approx(controller.mass * (GRAVITY + lift), rel=1e-6)
    np.testing.assert_allclose(force_in_world[:2], 0.0, atol=1e-3 * controller.mass * GRAVITY)
    # Newton-Euler of the floating base at rest: gravity's base rows = the contacts'.
    model = RobotModel(G1)
    model.update(controller.state.q, np.zeros(model.nv))
    gravity = model.inverse_dynamics(np.zeros(model.nv))
    np.testing.assert_allclose(contact[:3], gravity[:3], atol=0.01 * controller.mass * GRAVITY)
    np.testing.assert_allclose(contact[3:6], gravity[3:6], atol=0.5)  # [N m]
    # The legs carry the weight symmetrically: each knee's torque is the other's.
    knees = controller.model.index_of(["left_knee_joint", "right_knee_joint"])
    assert abs(order.torque[knees[0]]) > 5.0
    assert order.torque[knees[0]] == pytest.approx(order.torque[knees[1]], rel=0.05)


def test_the_swing_sole_reaches_a_catching_foothold_moved_late_by_its_step_time():
    """A catching step: 0.3 s before the planned touchdown the foothold moves 0.6 m further
    ahead. The controller's swing trajectory is over it and on the ground at the step time
    (at a 2 m/s speed bound it was still 11 cm short and 6 cm up)."""
    controller, _ = standing()
    swing, landing, dt = controller.swing, 0.6, 0.01
    swing.start(np.array([0.0, -0.1]))
    for k in range(1, round(landing / dt) + 1):
        time = k * dt
        target = np.array([0.2, -0.1]) if time < landing - 0.3 else np.array([0.8, -0.1])
        position = swing.update(time, target, dt, landing_time=landing)
    assert np.linalg.norm(position[:2] - target) < 0.005
    assert position[2] == pytest.approx(0.0, abs=0.003)


def test_the_feet_wrenches_are_bounded_by_the_ankles_effort_limits():
    """The wrench distribution is given each robot's ankle roll and pitch effort limits
    from its URDF (G1 35 and 35 N m, Talos 100 and 160 N m)."""
    controller, _ = standing()
    assert controller.limits.ankle_torque == (35.0, 35.0)
    talos = WholeBodyController(get_robot("talos"), SwingTiming(), 0.01, StabilizerConfig())
    assert talos.limits.ankle_torque == (100.0, 160.0)


def test_a_landed_support_whose_load_dips_keeps_its_wrench():
    """Double support, the planned CoP on the left sole: once the left foot has touched
    down, a tick on which it carries nothing (a bounce, a CoM far from it) still gives it
    a wrench that its leg presses with, while its sole is on the ground; lifted 2 cm, it
    gets none, and the right foot carries the weight alone. A foot that has swung is not
    pressed down before it touches the ground again."""
    weight = G1.total_mass * GRAVITY
    on_left = {"left": FootForce(0.0, LEFT.position), "right": FootForce(weight, RIGHT.position)}
    for lift, pressed in ((0.0, True), (0.02, False)):
        controller, measurement = standing()
        controller.tick(measurement, command(0.0, np.zeros(2)))  # both feet loaded
        later = dataclasses.replace(lifted(measurement, lift), time=0.01, foot_forces=on_left)
        controller.tick(later, command(0.01, LEFT.position, since_step=0.01))
        forces = controller.planned_forces
        if pressed:
            assert forces.get("left", 0.0) > 0.5 * weight, forces
        else:
            assert "left" not in forces and forces["right"] > 0.0, forces
    # A foot that swung has to touch down again: at the step onto the right foot, which
    # carries nothing yet, only the left is given the weight.
    controller, measurement = standing()
    controller.tick(measurement, command(0.0, np.zeros(2)))
    swinging = {"left": FootForce(weight, LEFT.position), "right": FootForce(0.0, RIGHT.position)}
    single = dataclasses.replace(measurement, time=0.01, foot_forces=swinging)
    controller.tick(single, command(0.01, LEFT.position, since_step=0.3))
    step = dataclasses.replace(single, time=0.02)
    controller.tick(step, command(0.02, RIGHT.position, RIGHT, LEFT, since_step=0.0))
    assert list(controller.planned_forces) == ["left"], controller.planned_forces


def test_the_controller_reads_only_what_the_robot_senses():
    """The measurement record has the robot's sensors and nothing of the simulator's
    truth (no base position or velocity), and the controller ticks on it: the truth is
    absent, not ignored."""
    fields = {field.name for field in dataclasses.fields(RobotMeasurement)}
    assert fields == {
        "time", "joint_positions", "joint_velocities", "joint_torques", "imu", "foot_forces"
    }  # fmt: skip
    controller, measurement = standing()
    order = controller.tick(measurement, command(0.0, np.zeros(2)))
    assert np.all(np.isfinite(order.torque))
    # A G1 has no foot sensors: the loads come from the joint torques.
    plain = WholeBodyController(G1, SwingTiming(), 0.01, StabilizerConfig())
    assert plain.observer is not None and controller.observer is None


TICK_WITHOUT_PYBULLET = """
import sys
for name in ("pybullet", "pybullet_data", "pybullet_utils", "pybullet_utils.bullet_client"):
    sys.modules[name] = None  # any import of PyBullet fails
sys.path.insert(0, "tests")
from test_controller import standing
from conftest import command
import numpy as np
controller, measurement = standing()
order = controller.tick(measurement, command(0.0, np.zeros(2)))
print(len(order.torque), float(controller.expected_contact_force[2]))
"""


def test_the_controller_runs_without_pybullet():
    """The controller's modules import nothing of PyBullet: the tick runs in a process
    where importing PyBullet fails."""
    result = subprocess.run(
        [sys.executable, "-c", TICK_WITHOUT_PYBULLET],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert result.returncode == 0, result.stderr[-2000:]
    joints, vertical = result.stdout.split()[-2:]
    assert int(joints) == 29 - len(G1.locked_joints)
    assert float(vertical) > 0.0


def test_the_legs_are_compliant_around_a_touchdown_and_stiff_between():
    """After a step onto the right foot, the right leg keeps landing_compliance of its
    gains for 0.05 s; the swing leg (left) over the last 0.1 s before its planned landing
    (0.8 s after the step); the other joints, the legs in mid-swing and at the start of
    the walk (no landing) keep theirs."""
    controller, measurement = standing()
    share = controller.config.landing_compliance
    assert share < 1.0
    legs = {foot: controller._legs[foot] for foot in ("left", "right")}
    others = np.ones(len(controller.stiffness), bool)
    others[np.concatenate(list(legs.values()))] = False
    cases = [  # (time [s], planner command, legs expected soft)
        (0.0, command(0.0, np.zeros(2)), ()),  # the walk's start on the left foot
        (0.01, command(0.01, RIGHT.position, RIGHT, LEFT), ("right",)),  # it stepped
        (0.04, command(0.04, RIGHT.position, RIGHT, LEFT, since_step=0.03), ("right",)),
        (0.05, command(0.05, RIGHT.position, RIGHT, LEFT, since_step=0.04), ()),
        (0.3, command(0.3, RIGHT.position, RIGHT, LEFT, since_step=0.29), ()),
        (0.76, command(0.76, RIGHT.position, RIGHT, LEFT, since_step=0.75), ("left",)),
    ]
    for time, planned, soft in cases:
        order = controller.tick(dataclasses.replace(measurement, time=time), planned)
        for foot, joints in legs.items():
            scale = share if foot in soft else 1.0
            np.testing.assert_allclose(
                order.stiffness[joints], scale * controller.stiffness[joints], err_msg=str(time)
            )
            np.testing.assert_allclose(order.damping[joints], scale * controller.damping[joints])
        np.testing.assert_array_equal(order.stiffness[others], controller.stiffness[others])
    stiff = WholeBodyController(
        G1_SENSED, SwingTiming(), 0.01, StabilizerConfig(landing_compliance=1.0)
    )
    assert stiff._impedance(command(0.0, np.zeros(2)), "left", "right")[0] is stiff.stiffness
