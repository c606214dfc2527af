"""The simulated joint motors (:mod:`app.backends.joint_motors`) and the motors' armature
(:mod:`robots.rotor_inertia`): the G1 driver's law on the command alone, within the
torque-speed curve, with the rotor inertia in the joint's dynamics."""

from __future__ import annotations

import xml.etree.ElementTree as ET

import numpy as np
import pybullet
import pytest
from pybullet_utils.bullet_client import BulletClient

from app.backends.base import InitialCondition
from app.backends.joint_motors import JointMotors
from app.backends.pybullet import PyBulletBackend
from app.lowlevel import JointCommand
from app.reality import robot_reality
from conftest import LEFT, RIGHT, command, dcm_feedback_zmp
from robots import get_robot
from robots.description import MotorModel
from robots.rotor_inertia import add_rotor_inertia, disc_inertia

pytestmark = pytest.mark.usefixtures("cache_in_tmp")

LINK_INERTIA = 0.002  # [kg m^2] about the joint axis (a light foot's order)
ARMATURE = 0.007  # [kg m^2] G1's ankle (two 5020 motors)

PENDULUM = """<robot name="one_joint">
  <link name="base"><inertial><mass value="1"/><inertia ixx="0.01" ixy="0" ixz="0"
    iyy="0.01" iyz="0" izz="0.01"/></inertial></link>
  <link name="arm"><inertial><origin xyz="0 0 0" rpy="0.3 0.2 0.1"/><mass value="1"/>
    <inertia ixx="{i}" ixy="0" ixz="0" iyy="{i}" iyz="0" izz="{i}"/></inertial></link>
  <joint name="hinge" type="revolute"><parent link="base"/><child link="arm"/>
    <axis xyz="0 1 0"/><limit effort="100" velocity="100" lower="-3" upper="3"/></joint>
</robot>
"""


def single_joint(tmp_path, armature: float, stiffness: float, damping: float) -> np.ndarray:
    """Angles [rad] of the hinge, every 1 ms for 0.3 s, started 0.1 rad from its target
    under the driver's law, with ``armature`` on it (no gravity, the base fixed)."""
    root = ET.fromstring(PENDULUM.format(i=LINK_INERTIA))
    add_rotor_inertia(root, {"hinge": armature})
    path = tmp_path / f"one_joint_{armature}.urdf"
    path.write_text(ET.tostring(root, encoding="unicode"))
    client = BulletClient(connection_mode=pybullet.DIRECT)
    try:
        client.setPhysicsEngineParameter(fixedTimeStep=0.001)
        body = client.loadURDF(
            str(path), useFixedBase=True, flags=pybullet.URDF_USE_INERTIA_FROM_FILE
        )
        client.setJointMotorControl2(body, 0, pybullet.VELOCITY_CONTROL, force=0.0)
        client.changeDynamics(body, 0, linearDamping=0.0, angularDamping=0.0)
        client.resetJointState(body, 0, 0.1, 0.0)
        motors = JointMotors(np.array([100.0]), [None])
        order = JointCommand(*(np.zeros(1) for _ in range(2)), np.array([stiffness]),
                             np.array([damping]), np.zeros(1))  # fmt: skip
        angles = []
        for _ in range(300):
            q, qd = client.getJointState(body, 0)[:2]
            torque = motors.torques(order, np.array([q]), np.array([qd]))
            client.setJointMotorControl2(body, 0, pybullet.TORQUE_CONTROL, force=float(torque[0]))
            client.stepSimulation()
            angles.append(client.getJointState(body, 0)[0])
        return np.array(angles)
    finally:
        client.disconnect()


def analytic(inertia: float, stiffness: float, damping: float) -> np.ndarray:
    """The damped oscillator I qdd = -kp q - kd qd from q = 0.1 rad at rest, every 1 ms."""
    time = 0.001 * np.arange(1, 301)
    omega = np.sqrt(stiffness / inertia)
    zeta = damping / (2.0 * np.sqrt(stiffness * inertia))
    damped = omega * np.sqrt(1.0 - zeta**2)
    decay = np.exp(-zeta * omega * time)
    return 0.1 * decay * (np.cos(damped * time) + zeta * omega / damped * np.sin(damped * time))


def test_a_joint_with_armature_follows_the_analytic_response(tmp_path):
    """One hinge, the link's inertia 2 g m^2 about it, under tau = kp e + kd e' with kp 20,
    kd 0.2 (underdamped, 47 rad/s): with G1's ankle armature added as a disc on the link
    the angle follows the oscillator of inertia I + a within 3 % of the start error (the
    explicit 1 ms step's phase error, omega dt; measured 2.2 %); the oscillator without
    the armature is 10x further (measured 22x)."""
    stiffness, damping = 20.0, 0.2
    simulated = single_joint(tmp_path, ARMATURE, stiffness, damping)
    with_armature = analytic(LINK_INERTIA + ARMATURE, stiffness, damping)
    without = analytic(LINK_INERTIA, stiffness, damping)
    error = np.abs(simulated - with_armature).max()
    assert error < 0.003, error
    assert np.abs(simulated - without).max() > 10 * error


def test_the_disc_keeps_the_tensor_physical():
    """The armature about the axis, half of it across (a thin disc): the eigenvalues
    satisfy the triangle inequality, and the axis is an eigenvector with the armature."""
    axis = np.array([0.3, -0.5, 0.8])
    tensor = disc_inertia(0.01, axis)
    values = np.linalg.eigvalsh(tensor)
    assert values[2] <= values[0] + values[1] + 1e-12
    unit = axis / np.linalg.norm(axis)
    np.testing.assert_allclose(tensor @ unit, 0.01 * unit)


def test_the_torque_speed_curve_bounds_the_driver():
    """unitree_rl_lab's curve for a 7520-14: 71 N m up to 22.63 rad/s, zero at 35.52; a
    braking torque up to 83.3 N m; the URDF limit a ceiling on all."""
    motor = MotorModel(71.0, 83.3, 22.63, 35.52)
    motors = JointMotors(np.array([88.0, 50.0]), [motor, motor])
    demand = np.array([500.0, 500.0])
    np.testing.assert_allclose(motors.clip(demand, np.array([10.0, 10.0])), [71.0, 50.0])
    np.testing.assert_allclose(motors.clip(demand, np.array([-10.0, -10.0])), [83.3, 50.0])
    halfway = (22.63 + 35.52) / 2
    np.testing.assert_allclose(motors.clip(demand, np.array([halfway, 0.0]))[0], 35.5)
    assert motors.clip(demand, np.array([40.0, 0.0]))[0] == 0.0


def test_the_motors_see_only_the_command():
    """The plant's actuation takes the low-level command, the number of physics steps,
    the push and an observer: nothing of the controller's plan or model."""
    import inspect

    from app.backends.pybullet_robot import SimulatedRobot

    parameters = list(inspect.signature(SimulatedRobot.actuate).parameters)
    assert parameters == ["self", "command", "steps", "base_force_world", "observer"]


def test_the_feedforward_torques_hold_the_posture_the_pd_alone_lets_sag():
    """G1 standing under the driver's law (the ideal sensors, so that the joints' errors
    are the motors'): with the feed-forward (floating-base inverse dynamics with the
    planned contact wrenches, and the friction's compensation) the joints stay on their
    targets (measured 0.009 deg rms); the PD alone holds the load only by an error of
    tau_ff / kp, less what the motors' Coulomb friction holds (the knees sag 0.51 deg,
    0.59 deg predicted, the friction's band 0.09 deg)."""
    g1 = get_robot("g1")
    backend = PyBulletBackend(g1, reality=robot_reality(g1, "ideal", 0))
    try:
        with_ff, _ = standing_errors(backend, True)
        without_ff, feedforward = standing_errors(backend, False)
    finally:
        backend.close()
    rms_with = np.sqrt(np.mean(with_ff**2))
    rms_without = np.sqrt(np.mean(without_ff**2))
    assert rms_with < 0.1 * rms_without, f"{rms_with=} {rms_without=}"
    knees = backend.controller.model.index_of(["left_knee_joint", "right_knee_joint"])
    stiffness = backend.controller.stiffness[knees]
    sag = -feedforward.mean(axis=0)[knees] / stiffness
    band = float(g1.motors["left_knee_joint"].static_friction / stiffness.min())
    assert np.all(np.abs(sag) > np.radians(0.3))
    np.testing.assert_allclose(without_ff.mean(axis=0)[knees], sag, atol=band + np.radians(0.02))


def standing_errors(backend, feedforward: bool, seconds: float = 1.0):
    """Joint errors [rad] (true angle - commanded target) of G1 standing with the test's
    DCM feedback, each tick of the last half, and the controller's feed-forward torques."""
    import dataclasses

    tick = backend.controller.tick
    commands = []

    def maybe_without_feedforward(measurement, planner_command):
        order = tick(measurement, planner_command)
        commands.append(order)
        if not feedforward:
            order = dataclasses.replace(order, torque=np.zeros_like(order.torque))
        return order

    backend.controller.tick = maybe_without_feedforward
    try:
        state = backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
        errors = []
        for step in range(round(seconds / backend.control_period)):
            zmp = dcm_feedback_zmp(state, np.zeros(2), backend.description.pendulum_height)
            state = backend.step(command(step * backend.control_period, zmp), np.zeros(2))
            errors.append(backend.sim.truth().joint_positions - commands[-1].position)
            assert not backend.fall_status().fell
    finally:
        del backend.controller.tick
    half = len(errors) // 2
    return np.array(errors[half:]), np.array([order.torque for order in commands[half:]])


def test_g1_motors_are_unitrees():
    """Every actuated G1 joint has its motor's armature and curve (none from the stable PD)."""
    g1 = get_robot("g1")
    actuated = [j for j in g1.joint_impedance if j not in g1.locked_joints]
    assert all(g1.motor_armature[j] > 0.003 for j in actuated)
    assert g1.motors["left_knee_joint"].peak_torque == 111.0
