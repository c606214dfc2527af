"""The simulated joint motors (:mod:`app.backends.joint_motors`): G1's PD law with feed-forward,
in the stable-PD form, within the effort limits."""

from __future__ import annotations

import dataclasses

import numpy as np
import pybullet
import pytest

from app.backends.base import InitialCondition
from app.backends.pybullet import PyBulletBackend
from app.backends.pybullet_robot import SimulatedRobot
from app.lowlevel import JointCommand
from app.stabilizer.controller import joint_impedance
from conftest import LEFT, RIGHT, cache_for_module, command, dcm_feedback_zmp
from robots import get_robot

G1 = get_robot("g1")
TICK = 0.01  # [s] control period of the hung-robot runs


pytestmark = pytest.mark.usefixtures("cache_in_tmp")


@pytest.fixture(scope="module")
def hung(tmp_path_factory):
    """G1 hung by its pelvis 1.2 m above the ground (a fixed constraint)."""
    with cache_for_module(tmp_path_factory):
        sim = SimulatedRobot(G1)
    sim.set_configuration(np.array([0.0, 0.0, 1.2]), [0, 0, 0, 1], {})
    position, orientation = sim.client.getBasePositionAndOrientation(sim.body)
    sim.client.createConstraint(
        sim.body, -1, -1, -1, pybullet.JOINT_FIXED, [0, 0, 0], [0, 0, 0], position,
        childFrameOrientation=orientation,
    )  # fmt: skip
    yield sim
    sim.close()


def posture(model):
    """G1's standing angles [rad] in the model's joint order."""
    return np.array([G1.standing_posture.get(name, 0.0) for name in model.joint_names])


def hang(sim, start_offsets, target):
    """Put the hung robot at the posture plus ``start_offsets`` [rad], at rest; returns
    the feed-forward torques and J^T f of the hanging force that hold ``target``
    still (gravity, by RNEA), and the PyBullet joint indices in the model's order."""
    model = sim.motors.model
    angles = posture(model) + start_offsets
    sim.set_configuration(
        np.array([0.0, 0.0, 1.2]), [0, 0, 0, 1], dict(zip(model.joint_names, angles, strict=True))
    )
    sim.set_motor_target(target)
    measured = sim.measure()
    q = np.concatenate([measured.base_position, measured.base_orientation, target])
    model.update(q, np.zeros(model.nv))
    gravity = model.inverse_dynamics(np.zeros(model.nv))
    hanging = np.zeros(model.nv)
    hanging[:6] = gravity[:6]  # the constraint carries the weight at the pelvis
    indices = [sim.joint_indices[sim.joint_names.index(name)] for name in model.joint_names]
    return gravity[6:], hanging, indices


def joint_errors(sim, indices, target):
    states = sim.client.getJointStates(sim.body, indices)
    return np.array([state[0] for state in states]) - target


def test_the_stable_pd_settles_where_the_explicit_law_at_the_same_gains_chatters(hung):
    """G1's ankle roll joint moves a light foot: kd dt / I is far above 2, where an
    explicit damping term overshoots every step. Started 0.1 rad off, with the
    G1's gains and gravity as feed-forward: the stable PD (Tan, Liu and Turk
    2011) settles (measured 0.04 deg after 0.25 s); the explicit law, evaluated at each
    2 ms physics step in this test, chatters between 3 and 15 deg (measured)."""
    sim = hung
    model = sim.motors.model
    stiffness, damping = joint_impedance(model, G1)
    roll = model.joint_names.index("left_ankle_roll_joint")
    target = posture(model)
    offsets = np.where(["ankle_roll" in name for name in model.joint_names], 0.1, 0.0)
    substeps = round(TICK / sim.time_step)

    # The premise: with the foot's inertia I about the joint, kd dt / I > 2.
    feedforward, hanging, indices = hang(sim, offsets, target)
    inertia = model.mass_matrix()[6 + roll, 6 + roll]
    assert damping[roll] * sim.time_step / inertia > 5.0

    stable = []
    order = JointCommand(target, np.zeros_like(target), stiffness, damping, feedforward)
    for _ in range(round(0.5 / TICK)):
        sim.actuate(
            order, sim.measure(), substeps, hanging,
            observer=lambda s, _: stable.append(joint_errors(s, indices, target)),
        )  # fmt: skip

    feedforward, hanging, indices = hang(sim, offsets, target)
    explicit = []
    limits = model.effort_limits
    for _ in range(round(0.5 / sim.time_step)):
        states = sim.client.getJointStates(sim.body, indices)
        q = np.array([state[0] for state in states])
        qd = np.array([state[1] for state in states])
        torque = np.clip(stiffness * (target - q) - damping * qd + feedforward, -limits, limits)
        sim.client.setJointMotorControlArray(
            sim.body, indices, pybullet.TORQUE_CONTROL, forces=torque.tolist()
        )
        sim.step()
        explicit.append(joint_errors(sim, indices, target))

    stable, explicit = np.degrees(stable), np.degrees(explicit)
    half = len(stable) // 2
    assert np.all(np.abs(np.diff(stable[:, roll])) < 1.0)  # no jump between steps
    assert np.abs(stable[half:]).max() < 0.5
    assert np.abs(explicit[half:, roll]).max() > 5.0


def test_torques_never_exceed_the_effort_limits(hung):
    """A target 1 rad from where every joint is: the motors' torques reach the limits
    and stay within them."""
    sim = hung
    model = sim.motors.model
    stiffness, damping = joint_impedance(model, G1)
    target = posture(model) + 1.0
    feedforward, hanging, _ = hang(sim, np.zeros(len(target)), target)
    torques = []
    compute = sim.motors.torques

    def recorded(*args):
        torques.append(compute(*args))
        return torques[-1]

    sim.motors.torques = recorded  # type: ignore[method-assign]
    try:
        order = JointCommand(target, np.zeros_like(target), stiffness, damping, feedforward)
        for _ in range(round(0.1 / TICK)):
            sim.actuate(order, sim.measure(), round(TICK / sim.time_step), hanging)
    finally:
        del sim.motors.torques
    torques = np.abs(np.array(torques))
    limits = model.effort_limits
    assert np.all(torques <= limits + 1e-9)
    saturated = np.isclose(torques, limits).any(axis=0)
    assert saturated.sum() >= len(limits) // 2, [
        name for name, hit in zip(model.joint_names, saturated, strict=True) if not hit
    ]


def standing_errors(backend, feedforward: bool, seconds: float = 1.0):
    """Joint errors [rad] (measured - commanded target) of G1 standing with the test's
    DCM feedback, each tick of the last half, and the controller's feed-forward torques
    [N m] of those ticks; the motors get the commands with their feed-forward torques
    or with none."""
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
            errors.append(backend.sim.measure().joint_positions - commands[-1].position)
            assert not backend.fall_status().fell
    finally:
        del backend.controller.tick
    half = len(errors) // 2
    return np.array(errors[half:]), np.array([order.torque for order in commands[half:]])


def test_the_feedforward_torques_hold_the_posture_the_pd_alone_lets_sag():
    """G1 standing: with the feed-forward (inverse dynamics with the planned contact
    wrenches) the joints stay on their targets (measured 0.002 deg rms); the PD alone
    holds the same load only by an error of tau_ff / kp (measured 0.27 deg rms, the
    knees 0.66 deg)."""
    backend = PyBulletBackend("g1")
    try:
        with_ff, _ = standing_errors(backend, True)
        without_ff, feedforward = standing_errors(backend, False)
    finally:
        backend.close()
    rms_with = np.sqrt(np.mean(with_ff**2))
    rms_without = np.sqrt(np.mean(without_ff**2))
    assert rms_with < 0.1 * rms_without, f"{rms_with=} {rms_without=}"
    # Without it the knees, which carry the weight, sag until kp e carries the load:
    # e = -tau_ff / kp, for the two knees together within 2 % (measured 1.4 %; the split
    # between them drifts by 10 % as the robot, standing on its PD alone, leans).
    knees = backend.controller.model.index_of(["left_knee_joint", "right_knee_joint"])
    sag = -feedforward.mean(axis=0)[knees] / backend.controller.stiffness[knees]
    assert np.all(np.abs(sag) > np.radians(0.3))
    np.testing.assert_allclose(without_ff.mean(axis=0)[knees].sum(), sag.sum(), rtol=0.02)
