"""The contact force observer (:mod:`app.stabilizer.contact_observer`): G1's foot forces
from its joint torques against PyBullet's contact forces, and the observer's lag.

In PyBullet the joints are held by PyBullet's position servos (implicit, so stable on
G1's light ankles at the 2 ms physics step, where an explicit PD at kp 300, kd 10 is
not; they replace whatever motor ``SimulatedRobot`` leaves on the joints, so theirs is
the joints' only torque), and the observer is given the torques they report applying,
averaged over each control period, with the simulator's true base state.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from dataclasses import dataclass, field

import numpy as np
import pinocchio
import pytest
from numpy.typing import NDArray
from scipy.spatial.transform import Rotation

from app.backends.pybullet_robot import GRAVITY, SimulatedRobot
from app.stabilizer.contact_observer import ContactForceObserver
from conftest import LEFT, RIGHT, cache_for_module
from kinematics.native_output import native_output_silenced
from kinematics.robot_model import FEET, RobotModel
from kinematics.whole_body_ik import WholeBodyIK, leg_joints, sole_pose
from planner.exceptions import ParameterError
from robots import get_robot

with native_output_silenced():
    import pybullet

pytestmark = pytest.mark.usefixtures("cache_in_tmp")

PERIOD = 0.01  # [s] the controller's period, at which the observer runs
BANDWIDTH = 50.0  # [1/s] the observer's default
SETTLED = 5.0 / BANDWIDTH  # [s] after a reset the observer has converged (e^-5)
PYBULLET_DAMPING = 0.04  # [1/s] PyBullet's default damping of a multibody's velocities
SERVO_FORCE = 500.0  # [N m] the position servos' limit (above every torque here)


@dataclass
class G1:
    """G1 in PyBullet, its rigid-body model, its IK (for postures) and the observer."""

    sim: SimulatedRobot
    model: RobotModel
    ik: WholeBodyIK
    observer: ContactForceObserver
    ik_order: NDArray[np.intp]
    lagged: dict[str, float] = field(default_factory=dict)  # see Sample

    @property
    def weight(self) -> float:
        """m g [N]."""
        return self.sim.mass * GRAVITY


@dataclass(frozen=True)
class Sample:
    """One control period's end: the observer's output and PyBullet's truth."""

    time: float
    estimated: dict[str, float]  # foot -> normal force [N]
    measured: dict[str, float]  # foot -> PyBullet's normal force [N], mean over the period
    # foot -> ``measured`` through the observer's first-order lag (1/K), from 0 at its
    # reset: what the observer is to estimate (a contact's bounce lasts one period)
    lagged: dict[str, float]
    forces: dict[str, float]  # foot -> magnitude of its estimated force [N]
    total: float  # the observer's total vertical force [N]
    sole_heights: dict[str, float]  # [m]


Legs = dict[str, NDArray[np.intp]]


@pytest.fixture(scope="module")
def g1_model(tmp_path_factory: pytest.TempPathFactory) -> tuple[RobotModel, Legs]:
    """G1's rigid-body model and its legs' joints (positions in ``joint_names``)."""
    with cache_for_module(tmp_path_factory):
        description = get_robot("g1")
        model = RobotModel(description)
        legs = leg_joints(WholeBodyIK(description).robot.model)
    return model, {foot: model.index_of(legs[foot]) for foot in FEET}


@pytest.fixture(scope="module")
def g1(tmp_path_factory: pytest.TempPathFactory, g1_model: tuple[RobotModel, Legs]) -> Iterator[G1]:
    model, legs = g1_model
    with cache_for_module(tmp_path_factory):
        description = get_robot("g1")
        sim = SimulatedRobot(description)
        ik = WholeBodyIK(description)
    order = np.array([ik.joint_names.index(name) for name in model.joint_names], dtype=np.intp)
    yield G1(sim, model, ik, ContactForceObserver(model, legs), order)
    sim.close()


def posture(g1: G1, com_y: float = 0.0, right_lift: float = 0.0) -> NDArray[np.float64]:
    """Joint angles [rad] (model order) standing on LEFT and RIGHT with the CoM at
    (0, ``com_y``) and the right sole ``right_lift`` [m] up."""
    left = sole_pose(np.array([*LEFT.position, 0.0]))
    right = sole_pose(np.array([*RIGHT.position, right_lift]))
    angles = g1.ik.reset(left, right, np.array([0.0, com_y]))
    return np.asarray(angles, float)[g1.ik_order]


def true_state(sim: SimulatedRobot) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """The simulator's q and v in the model's layout (as the estimator's ``truth``)."""
    client = sim.client
    position, quaternion = sim.base_pose()
    inertial, _ = client.getBasePositionAndOrientation(sim.body)
    linear, angular = client.getBaseVelocity(sim.body)
    rotation = Rotation.from_quat(quaternion).as_matrix()
    # PyBullet's base velocity is that of the inertial frame's origin.
    linear = np.asarray(linear) + np.cross(angular, position - np.asarray(inertial))
    joints = client.getJointStates(sim.body, sim._model_indices)
    q = np.concatenate([position, quaternion, [s[0] for s in joints]])
    base_velocity = np.concatenate([rotation.T @ linear, rotation.T @ np.asarray(angular)])
    return q, np.concatenate([base_velocity, [s[1] for s in joints]])


def stand(
    g1: G1,
    angles: NDArray[np.float64],
    height: float = 0.0,
    spin: NDArray[np.float64] | None = None,
) -> None:
    """Place G1 at ``angles`` with the soles where the IK put them (``height`` [m] higher),
    still but for the base's angular velocity ``spin`` [rad/s] (world axes), and reset
    the observer there."""
    sim, ik = g1.sim, g1.ik
    base = np.asarray(ik.robot.get_T_world_fbase(), float)
    sim.set_configuration(
        base[:3, 3] + [0.0, 0.0, height],
        Rotation.from_matrix(base[:3, :3]).as_quat(),
        dict(zip(g1.model.joint_names, angles.tolist(), strict=True)),
        base_angular_velocity=spin,
    )
    g1.observer.reset(*true_state(sim))
    g1.lagged = dict.fromkeys(FEET, 0.0)


def hold(g1: G1, seconds: float, targets: Callable[[float], NDArray[np.float64]]) -> list[Sample]:
    """Servo the joints to ``targets(t)`` [rad] (t [s] since the start) for ``seconds``,
    the observer updated every :data:`PERIOD` with the torques the servos applied."""
    sim = g1.sim
    joints = sim._model_indices
    substeps = round(PERIOD / sim.time_step)
    start = sim.time
    lag = -np.expm1(-BANDWIDTH * PERIOD)  # the first-order lag's step over one period
    samples = []
    for _ in range(round(seconds / PERIOD)):
        torque = np.zeros(len(joints))
        measured = dict.fromkeys(FEET, 0.0)
        for _ in range(substeps):
            sim.client.setJointMotorControlArray(
                sim.body,
                joints,
                pybullet.POSITION_CONTROL,
                targetPositions=targets(sim.time - start).tolist(),
                forces=[SERVO_FORCE] * len(joints),
            )
            sim.step()
            # The servo's torque over the step just taken (PyBullet's report).
            torque += [s[3] for s in sim.client.getJointStates(sim.body, joints)]
            for foot, (_, force) in sim.foot_pressure().items():
                measured[foot] += force / substeps
        q, v = true_state(sim)
        estimated = g1.observer.update(q, v, torque / substeps, PERIOD)
        for foot in FEET:
            g1.lagged[foot] += lag * (measured[foot] - g1.lagged[foot])
        samples.append(
            Sample(
                sim.time - start,
                estimated,
                measured,
                dict(g1.lagged),
                {foot: float(np.linalg.norm(w[:3])) for foot, w in g1.observer.wrenches.items()},
                g1.observer.total_vertical_force,
                {foot: float(sim.sole_position(foot)[2]) for foot in FEET},
            )
        )
    return samples


def ramp(
    start: NDArray[np.float64], end: NDArray[np.float64], duration: float
) -> Callable[[float], NDArray[np.float64]]:
    """Targets moving from ``start`` to ``end`` in ``duration`` [s] (smoothstep), then held."""

    def targets(time: float) -> NDArray[np.float64]:
        x = min(time / duration, 1.0)
        return start + x * x * (3.0 - 2.0 * x) * (end - start)

    return targets


def worst_error(samples: list[Sample], foot: str) -> float:
    """Largest |estimated - lagged measured| normal force of ``foot`` [N] over ``samples``."""
    return max(abs(s.estimated[foot] - s.lagged[foot]) for s in samples)


# ---------------------------------------------------------------------- PyBullet
def test_standing_still_each_foot_carries_what_pybullet_measures(g1: G1) -> None:
    """Standing still for 1 s (after the observer's 5 time constants): the feet's
    estimates sum to m g within 5 %, and each is within 10 % of m g of PyBullet's
    normal force on that foot, at every control period."""
    angles = posture(g1)
    stand(g1, angles)
    samples = [s for s in hold(g1, 1.0 + SETTLED, lambda _: angles) if s.time > SETTLED]
    weight = g1.weight
    for sample in samples:
        assert sum(sample.estimated.values()) == pytest.approx(weight, rel=0.05)
        assert sample.total == pytest.approx(weight, rel=0.05)
        for foot in FEET:
            assert sample.measured[foot] > 0.3 * weight  # both feet carry the robot
            assert abs(sample.estimated[foot] - sample.measured[foot]) < 0.1 * weight


def test_the_estimated_split_follows_a_weight_shift(g1: G1) -> None:
    """The CoM moved 5 cm towards the left sole in 1.5 s, then held: at every control
    period the estimate of each foot stays within 10 % of m g of PyBullet's force seen
    through the observer's lag, and at the end, still, within 10 % of m g of PyBullet's
    force itself, the left foot carrying most of the weight."""
    start = posture(g1)
    stand(g1, start)
    hold(g1, SETTLED, lambda _: start)
    shifted = posture(g1, com_y=0.05)
    samples = hold(g1, 2.0, ramp(start, shifted, 1.5))
    weight = g1.weight
    for foot in FEET:
        assert worst_error(samples, foot) < 0.1 * weight
    last = samples[-1]
    assert last.measured["left"] > 0.6 * weight
    for foot in FEET:
        assert abs(last.estimated[foot] - last.measured[foot]) < 0.1 * weight


def test_a_foot_in_the_air_reads_nearly_nothing(g1: G1) -> None:
    """The CoM brought over the left sole, then the right sole lifted 3 cm: while the
    right foot touches nothing its estimate is below 5 % of m g, and the left foot's
    follows PyBullet's, seen through the observer's lag, within 10 % of m g throughout
    (the right sole lets go with a bounce or two, each shorter than the lag)."""
    start = posture(g1)
    stand(g1, start)
    hold(g1, SETTLED, lambda _: start)
    over_left = posture(g1, com_y=LEFT.position[1])
    samples = hold(g1, 1.7, ramp(start, over_left, 1.5))
    samples += hold(g1, 0.9, ramp(over_left, posture(g1, LEFT.position[1], 0.03), 0.6))
    weight = g1.weight
    airborne = [s for s in samples if s.measured["right"] == 0.0 and s.sole_heights["right"] > 0.01]
    assert len(airborne) >= 20  # the foot was up for 0.2 s at least
    assert max(s.estimated["right"] for s in airborne) < 0.05 * weight
    assert worst_error(samples, "left") < 0.1 * weight
    assert abs(samples[-1].estimated["left"] - samples[-1].measured["left"]) < 0.1 * weight


def test_tumbling_in_the_air_with_swinging_limbs_no_foot_feels_a_force(g1: G1) -> None:
    """G1 thrown 2 m above the ground turning head over heels at 1 turn/s, its legs and
    arms swinging at 2 Hz: the momentum changes only by gravity, the motors and the
    centrifugal and Coriolis terms of the turning body (C^T v), so no foot's estimated
    force, nor the total, reaches 5 % of m g."""
    angles = posture(g1)
    stand(g1, angles, height=2.0, spin=np.array([2.0 * np.pi, 0.0, 0.0]))
    client, body = g1.sim.client, g1.sim.body
    # PyBullet damps every link's velocity by default: no external force here.
    client.changeDynamics(body, -1, linearDamping=0.0, angularDamping=0.0)
    swing = np.zeros_like(angles)
    for name, amplitude in {"hip_pitch": 0.6, "knee": 0.6, "hip_roll": 0.3}.items():
        swing[g1.model.index_of([f"left_{name}_joint"])] = amplitude
        swing[g1.model.index_of([f"right_{name}_joint"])] = -amplitude
    swing[g1.model.index_of(["left_shoulder_pitch_joint", "right_shoulder_pitch_joint"])] = 1.0
    try:
        samples = hold(g1, 0.5, lambda t: angles + 0.5 * (1.0 - np.cos(4.0 * np.pi * t)) * swing)
    finally:
        damping = PYBULLET_DAMPING
        client.changeDynamics(body, -1, linearDamping=damping, angularDamping=damping)
    weight = g1.weight
    assert all(not any(s.measured.values()) for s in samples)  # in the air throughout
    for sample in samples:
        assert max(sample.forces.values()) < 0.05 * weight
        assert abs(sample.total) < 0.05 * weight


# -------------------------------------------------------------------- pure model
def equilibrium(model: RobotModel, left_share: float) -> tuple[
    NDArray[np.float64], NDArray[np.float64], dict[str, NDArray[np.float64]]
]:  # fmt: skip
    """A standing configuration of G1 held still by known foot wrenches: q, the joint
    torques that balance gravity and the wrenches, and foot -> wrench (ankle frame,
    world axes), the left foot carrying ``left_share`` of m g."""
    q = pinocchio.neutral(model.model)
    q[2] = 0.75
    for name, angle in get_robot("g1").standing_posture.items():
        if name in model.joint_names:
            q[7 + model.joint_names.index(name)] = angle
    model.update(q, np.zeros(model.nv))
    gravity = pinocchio.computeGeneralizedGravity(model.model, model.model.createData(), q)
    jacobians = {foot: model.foot_jacobian(foot) for foot in FEET}
    left = np.array([3.0, -2.0, left_share * model.mass * GRAVITY, 1.0, 2.0, 0.5])
    # The right wrench closes the base's 6 rows: the robot neither falls nor turns.
    base_rest = gravity[:6] - jacobians["left"][:, :6].T @ left
    right = np.linalg.solve(jacobians["right"][:, :6].T, base_rest)
    wrenches = {"left": left, "right": right}
    external = sum(jacobians[foot].T @ wrenches[foot] for foot in FEET)
    return q, (gravity - external)[6:], wrenches


@pytest.mark.parametrize(("bandwidth", "dt"), [(10.0, 0.002), (50.0, 0.002), (50.0, PERIOD)])
def test_a_step_of_contact_force_is_seen_through_a_first_order_lag(
    g1_model: tuple[RobotModel, Legs], bandwidth: float, dt: float
) -> None:
    """G1's model still, feet loaded from t = 0 with known wrenches (60 % of m g on the
    left) and motor torques balancing them: the estimates rise as 1 - exp(-K t), 63 %
    at 1/K within 20 %, and settle on the wrenches and their sum on m g."""
    model, legs = g1_model
    observer = ContactForceObserver(model, legs, bandwidth)
    q, torques, wrenches = equilibrium(model, 0.6)
    still = np.zeros(model.nv)
    observer.reset(q, still)
    times = dt * np.arange(round(6.0 / bandwidth / dt) + 1)
    rises = [0.0]  # the estimate's fraction of the left foot's force
    for _ in times[1:]:
        forces = observer.update(q, still, torques, dt)
        rises.append(forces["left"] / wrenches["left"][2])
    crossing = float(np.interp(1.0 - np.exp(-1.0), rises, times))  # rises increase
    assert crossing == pytest.approx(1.0 / bandwidth, rel=0.2)
    np.testing.assert_allclose(rises, 1.0 - np.exp(-bandwidth * times), atol=0.02)
    # After 6 time constants: the wrenches themselves, within exp(-6) of them.
    for foot in FEET:
        np.testing.assert_allclose(
            observer.wrenches[foot], wrenches[foot], atol=0.01 * model.mass * GRAVITY
        )
    assert observer.total_vertical_force == pytest.approx(model.mass * GRAVITY, rel=0.01)


@pytest.mark.parametrize("bandwidth", [0.0, -5.0, float("nan"), float("inf")])
def test_a_bandwidth_not_positive_and_finite_is_refused(
    g1_model: tuple[RobotModel, Legs], bandwidth: float
) -> None:
    with pytest.raises(ParameterError, match="bandwidth"):
        ContactForceObserver(*g1_model, bandwidth)
