"""State estimation (:mod:`app.stabilizer.estimator`): the simulator's truth, and leg
odometry from the encoders, the IMU and the stance foot, measured against it."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial.transform import Rotation

from app.backends.pybullet_robot import SimulatedRobot
from app.runner import ClosedLoop
from app.scenarios import BUILT_IN
from app.setup.build import build_robot_backend
from app.stabilizer.estimator import StateEstimator
from kinematics.robot_model import RobotModel
from robots import get_robot

G1 = get_robot("g1")


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture(scope="module")
def tumbling(tmp_path_factory):
    """G1 in the air, turned, every joint off its posture and moving, after 3 physics
    steps: (the simulated robot, PyBullet's whole-body CoM and its velocity computed
    with forward kinematics of the current state, and ``SimulatedRobot.com_state``)."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))
        sim = SimulatedRobot(G1)
    rng = np.random.default_rng(22)
    names = sim.joint_names
    sim.set_configuration(
        np.array([0.1, 0.2, 1.5]),
        Rotation.from_rotvec([0.1, -0.2, 0.3]).as_quat(),
        {name: G1.standing_posture.get(name, 0.0) + rng.uniform(-0.3, 0.3) for name in names},
        np.array([0.3, -0.2, 0.1]),
        np.array([0.2, 0.1, -0.3]),
        {name: rng.uniform(-1.0, 1.0) for name in names},
    )
    for _ in range(3):
        sim.step()
    reported = sim.com_state()  # before anything computes forward kinematics
    client = sim.client
    base_position, _ = client.getBasePositionAndOrientation(sim.body)
    base_velocity, _ = client.getBaseVelocity(sim.body)
    links = client.getLinkStates(
        sim.body, list(range(sim.link_count)), computeLinkVelocity=1, computeForwardKinematics=1
    )
    positions = np.array([base_position] + [link[0] for link in links])
    velocities = np.array([base_velocity] + [link[6] for link in links])
    com = sim.link_masses @ positions / sim.mass
    com_velocity = sim.link_masses @ velocities / sim.mass
    yield sim, com, com_velocity, reported
    sim.close()


def test_truth_gives_the_simulators_com_and_base(tumbling):
    """The rigid-body model of the controller is the simulator's robot: from the
    measurement record, its CoM and CoM velocity are PyBullet's (within 1e-6)."""
    sim, com, com_velocity, _ = tumbling
    measurement = sim.measure()
    state = StateEstimator(RobotModel(G1), "truth").update(measurement, "left")
    np.testing.assert_allclose(state.com, com, atol=1e-6)
    np.testing.assert_allclose(state.com_velocity, com_velocity, atol=1e-6)
    np.testing.assert_array_equal(state.q[:3], measurement.base_position)
    rotation = Rotation.from_quat(measurement.base_orientation).as_matrix()
    np.testing.assert_allclose(rotation @ state.v[:3], measurement.base_linear_velocity)


def test_the_simulators_com_is_that_of_its_current_state(tumbling):
    """``SimulatedRobot.com_state`` (the physics log's CoM columns) is the CoM of the
    state after the last physics step, not a mix with the links of the step before."""
    _, com, com_velocity, (position, velocity) = tumbling
    np.testing.assert_allclose(position, com, atol=1e-6)
    np.testing.assert_allclose(velocity, com_velocity, atol=1e-6)


def test_leg_odometry_follows_the_truth_over_a_short_walk():
    """G1's first two steps of the nominal walk (controlled with the truth); an
    odometry estimator fed the same measurements and stance foot. Measured over
    three runs: base position within 1.1 mm (x, y) and 1.0 mm (z); base velocity
    0.02-0.4 cm/s rms horizontally, 1.0 cm/s vertically (spikes to 5 cm/s and 8 cm/s
    at the touchdowns, when the stance foot is not quite still). The runs differ:
    the backend is not bit-for-bit repeatable (see test_pybullet_backend)."""
    backend, config, initial = build_robot_backend("g1", "rsg")
    odometry = StateEstimator(RobotModel(G1), "odometry")
    measurements = []
    measure = backend.sim.measure

    def recorded():
        measurements.append(measure())
        return measurements[-1]

    backend.sim.measure = recorded  # type: ignore[method-assign]
    scenario = dataclasses.replace(BUILT_IN["walk"], duration=2.0)
    position_errors, velocity_errors = [], []
    try:
        loop = ClosedLoop(backend, config, scenario, initial)
        odometry.update(measurements[-1], initial.stance.foot)
        for _ in range(round(scenario.duration / loop.period)):
            out = loop.tick()
            truth = measurements[-1]
            estimate = odometry.update(truth, out.stance.foot)
            rotation = Rotation.from_quat(truth.base_orientation).as_matrix()
            position_errors.append(estimate.q[:3] - truth.base_position)
            velocity_errors.append(rotation @ estimate.v[:3] - truth.base_linear_velocity)
            assert not backend.fall_status().fell
        steps = len(loop.result().steps)
    finally:
        backend.close()
    assert steps == 2
    position_errors, velocity_errors = np.array(position_errors), np.array(velocity_errors)
    assert np.abs(position_errors).max() < 0.003
    rms = np.sqrt(np.mean(velocity_errors**2, axis=0))
    assert np.all(rms[:2] < 0.01) and rms[2] < 0.03, f"{rms=}"
