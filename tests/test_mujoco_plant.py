"""The MuJoCo plant (:mod:`app.backends.mujoco_robot`): the same robot as PyBullet's on
another engine, with native armature and joint friction (:mod:`app.backends.mujoco_model`)
and the discs taken out of the URDF (:mod:`robots.native_armature`)."""

from __future__ import annotations

import dataclasses
import inspect
import xml.etree.ElementTree as ET
from collections.abc import Iterator

import numpy as np
import pytest
from test_joint_motors import ARMATURE, LINK_INERTIA, PENDULUM, analytic

from app.backends.joint_motors import JointMotors
from app.backends.mujoco_model import mujoco, urdf_spec
from app.backends.mujoco_robot import MujocoRobot
from app.backends.plant import Plant
from app.backends.pybullet_robot import GRAVITY, SimulatedRobot
from app.lowlevel import JointCommand
from conftest import cache_for_module
from planner.exceptions import ParameterError
from robots import get_robot
from robots.native_armature import rotor_discs, without_rotor_discs
from robots.rotor_inertia import disc_inertia
from robots.urdf_cache import derived_urdf

G1 = get_robot("g1")
STEP = G1.physics_time_step  # [s]


@pytest.fixture(scope="module")
def engines(tmp_path_factory: pytest.TempPathFactory) -> Iterator[dict[str, Plant]]:
    """G1 on each engine, built once for the module."""
    with cache_for_module(tmp_path_factory):
        plants: dict[str, Plant] = {"pybullet": SimulatedRobot(G1), "mujoco": MujocoRobot(G1)}
        yield plants
    for plant in plants.values():
        plant.close()


def test_g1_falls_freely_alike_on_both_engines(engines):
    """G1 dropped from 2 m at rest, no torque: after 0.3 s the pelvis has fallen as the
    1 ms semi-implicit Euler step gives, g dt^2 n (n+1) / 2, on both engines within 1 mm
    (measured: the same to 1e-9 m), and so within 1 mm of each other; g t^2 / 2 lies
    g t dt / 2 = 1.5 mm from it (the step's own error, either engine's)."""
    steps = 300
    drops = {}
    for name, plant in engines.items():
        plant.set_configuration(np.array([0.0, 0.0, 2.0]), [0, 0, 0, 1], G1.standing_posture)
        for _ in range(steps):
            plant.step()
        drops[name] = 2.0 - plant.base_pose()[0][2]
    euler = GRAVITY * STEP**2 * steps * (steps + 1) / 2
    time = steps * STEP
    for name, drop in drops.items():
        assert abs(drop - euler) < 1e-3, f"{name=} {drop=} {euler=}"
        assert abs(drop - GRAVITY * time**2 / 2) < GRAVITY * time * STEP / 2 + 1e-4, name
    assert abs(drops["mujoco"] - drops["pybullet"]) < 1e-3, drops


def test_a_push_on_the_pelvis_gives_its_impulse_and_stops(engines):
    """G1 in free fall, pushed on the pelvis with 100 N along x for 0.1 s, then let go for
    0.1 s: the CoM's horizontal velocity is the impulse over the mass on both engines
    (momentum: no other horizontal force), and stays so once the push has ended, within
    0.1 % (the step's momentum error while the unheld joints swing: measured 0.01 %)."""
    force, steps = np.array([100.0, 0.0, 0.0]), 100
    for name, plant in engines.items():
        plant.set_configuration(np.array([0.0, 0.0, 5.0]), [0, 0, 0, 1], G1.standing_posture)
        for _ in range(steps):
            plant.step(force)
        pushed = plant.com_state()[1]
        for _ in range(steps):
            plant.step()
        expected = force[0] * steps * STEP / plant.mass
        for velocity in (pushed, plant.com_state()[1]):
            assert velocity[0] == pytest.approx(expected, rel=1e-3), f"{name=} {velocity=}"
            assert abs(velocity[1]) < 1e-5, f"{name=} {velocity=}"


def standing_start(plant: Plant) -> JointCommand:
    """Put G1 in its standing posture with the soles on the ground and return the command
    that holds it: the description's gains, the ankles' 10x (their kp of 40 N m/rad
    holds the standing pendulum, m g c_z = 216 N m/rad, only with the controller's
    feed-forward; the PD alone lets it fall)."""
    posture = dict(G1.standing_posture)
    plant.set_configuration(np.array([0.0, 0.0, 1.0]), [0, 0, 0, 1], posture)
    lowest = min(plant.sole_position(foot)[2] for foot in ("left", "right"))
    plant.set_configuration(np.array([0.0, 0.0, 1.0 - lowest]), [0, 0, 0, 1], posture)
    plant.time = 0.0
    names = plant.model_joint_names
    target = np.array([posture.get(name, 0.0) for name in names])
    factor = np.array([10.0 if "ankle" in name else 1.0 for name in names])
    kp = factor * np.array([G1.joint_impedance[name].stiffness for name in names])
    kd = np.array([G1.joint_impedance[name].damping for name in names])
    plant.set_motor_target(target)
    return JointCommand(target, np.zeros_like(target), kp, kd, np.zeros_like(target))


def test_g1_stands_on_both_feet_on_mujoco(engines):
    """Under the drivers' law holding its standing posture, after 1 s of settling and over
    the next 0.2 s: the contact normal forces sum to m g within 1 % (measured 0.01 %),
    each foot carries between 40 % and 60 % of it, each CoP lies on its sole, and the
    pelvis has not moved more than 1 cm."""
    plant = engines["mujoco"]
    command = standing_start(plant)
    start, _ = plant.base_pose()
    plant.actuate(command, round(1.0 / STEP))
    weight = plant.mass * GRAVITY
    for _ in range(20):
        plant.actuate(command, 10)
        pressure = plant.foot_pressure()
        assert set(pressure) == {"left", "right"}, plant.time
        total = sum(force for _, force in pressure.values())
        assert abs(total - weight) < 0.01 * weight, f"{total=} {weight=} t={plant.time}"
        for foot, (cop, force) in pressure.items():
            assert 0.4 * weight < force < 0.6 * weight, f"{foot=} {force=}"
            sole, _ = plant.sole_frame(foot)
            sole_cop = cop - sole[:2]
            assert G1.sole.x_min < sole_cop[0] < G1.sole.x_max, f"{foot=} {sole_cop=}"
            assert abs(sole_cop[1]) < G1.sole.half_width, f"{foot=} {sole_cop=}"
    assert plant.feet_in_contact() == {"left", "right"}
    assert np.linalg.norm(plant.base_pose()[0] - start) < 0.01
    truth = plant.truth()
    assert truth.foot_forces["left"].normal_force == pressure["left"][1]


def single_joint_on_mujoco(armature: float, stiffness: float, damping: float) -> np.ndarray:
    """Angles [rad] of the hinge of tests/test_joint_motors.py on MuJoCo, every 1 ms for
    0.3 s, started 0.1 rad from its target under the driver's law, with ``armature`` as
    MuJoCo's joint armature (no disc, no gravity, the base fixed)."""
    spec = urdf_spec(PENDULUM.format(i=LINK_INERTIA), 0.001, {"hinge": armature}, {}, 0.0)
    model = spec.compile()
    data = mujoco.MjData(model)
    data.qpos[0] = 0.1
    motors = JointMotors(np.array([100.0]), [None])
    order = JointCommand(*(np.zeros(1) for _ in range(2)), np.array([stiffness]),
                         np.array([damping]), np.zeros(1))  # fmt: skip
    angles = []
    for _ in range(300):
        data.qfrc_applied[0] = motors.torques(order, data.qpos[:1], data.qvel[:1])[0]
        mujoco.mj_step(model, data)
        angles.append(float(data.qpos[0]))
    return np.array(angles)


def test_a_joint_with_native_armature_follows_the_analytic_response():
    """The hinge of tests/test_joint_motors.py (2 g m^2 about it, kp 20, kd 0.2) with G1's
    ankle armature as MuJoCo's joint armature follows the oscillator of inertia I + a
    within 3 % of the start error (the explicit 1 ms step's phase error, omega dt;
    measured 2.2 %, as PyBullet's disc); the oscillator without the armature is 10x
    further."""
    stiffness, damping = 20.0, 0.2
    simulated = single_joint_on_mujoco(ARMATURE, stiffness, damping)
    error = np.abs(simulated - analytic(LINK_INERTIA + ARMATURE, stiffness, damping)).max()
    assert error < 0.003, error
    without = analytic(LINK_INERTIA, stiffness, damping)
    assert np.abs(simulated - without).max() > 10 * error


def test_the_discs_come_out_of_the_physics_urdf_and_the_armature_goes_on_the_joints(engines):
    """Each actuated joint's disc is its armature about the axis, half across; the MuJoCo
    model's joints carry the armature and the motors' Coulomb friction; the masses are
    PyBullet's (the discs have none)."""
    discs = rotor_discs(G1)
    knee = discs["left_knee_link"][1]
    np.testing.assert_allclose(
        knee, disc_inertia(G1.motor_armature["left_knee_joint"], np.array([0, 1, 0])), atol=1e-9
    )
    text = derived_urdf(G1, merged=True).read_text(encoding="utf-8")
    bare = dataclasses.replace(G1, motor_armature={})
    expected = ET.fromstring(derived_urdf(bare, merged=True).read_text(encoding="utf-8"))
    taken_out = ET.fromstring(without_rotor_discs(text, G1))
    for mine, theirs in zip(taken_out.iter("inertia"), expected.iter("inertia"), strict=True):
        for key, value in theirs.attrib.items():
            assert float(mine.get(key, "nan")) == pytest.approx(float(value), abs=1e-9), key
    plant = engines["mujoco"]
    assert isinstance(plant, MujocoRobot)
    model = plant.model
    for index, name in enumerate(plant.model_joint_names):
        dof = model.jnt_dofadr[model.joint(name).id]
        assert model.dof_armature[dof] == pytest.approx(G1.motor_armature[name]), name
        assert model.dof_frictionloss[dof] == plant.motors.static_friction[index], name
    assert plant.mass == pytest.approx(engines["pybullet"].mass, abs=1e-6)


def test_the_mujoco_plant_has_the_pybullet_plants_interface(engines):
    """The same public methods (with the same parameters) and attributes, but PyBullet's
    own handles, so a backend can drive either; the same state set on both reads back
    the same truth (frames, quaternion order, velocities' frames, joint order), the same
    CoM and the same sole frames."""
    pybullet, mujoco_plant = engines["pybullet"], engines["mujoco"]
    engine_only = {"client", "body", "ground", "joint_indices", "link_count", "contact_points"}
    public = {name for name in dir(pybullet) if not name.startswith("_")} - engine_only
    public |= {name for name in vars(pybullet) if not name.startswith("_")} - engine_only
    missing = sorted(
        name for name in public if not hasattr(mujoco_plant, name) and name not in ("description",)
    )
    assert not missing, missing
    for name in public:
        method = getattr(SimulatedRobot, name, None)
        if callable(method):
            expected = inspect.signature(method).parameters
            assert list(inspect.signature(getattr(MujocoRobot, name)).parameters) == list(
                expected
            ), name
    assert list(inspect.signature(MujocoRobot).parameters) == list(
        inspect.signature(SimulatedRobot).parameters
    )
    rng = np.random.default_rng(3)
    angles = {n: float(rng.uniform(-0.3, 0.3)) for n in pybullet.joint_names}
    velocities = {n: float(rng.uniform(-1.0, 1.0)) for n in pybullet.joint_names}
    quaternion = np.array([0.1, -0.2, 0.3, 0.9]) / np.linalg.norm([0.1, -0.2, 0.3, 0.9])
    state = (np.array([0.1, 0.2, 1.5]), quaternion, angles, np.array([0.3, -0.1, 0.2]),
             np.array([0.5, -0.4, 0.7]), velocities)  # fmt: skip
    truths, com, soles = {}, {}, {}
    for name, plant in engines.items():
        plant.set_configuration(*state)
        plant.time = 0.0
        truths[name] = plant.truth()
        com[name] = plant.com_state()
        soles[name] = [plant.sole_frame(foot) for foot in ("left", "right")]
    a, b = truths["pybullet"], truths["mujoco"]
    for field in ("base_position", "base_orientation", "base_linear_velocity",
                  "base_angular_velocity", "joint_positions", "joint_velocities"):  # fmt: skip
        np.testing.assert_allclose(getattr(b, field), getattr(a, field), atol=1e-6, err_msg=field)
    for mine, theirs in zip(com["mujoco"], com["pybullet"], strict=True):
        np.testing.assert_allclose(mine, theirs, atol=1e-6)
    for (p1, r1), (p2, r2) in zip(soles["mujoco"], soles["pybullet"], strict=True):
        np.testing.assert_allclose(p1, p2, atol=1e-6)
        np.testing.assert_allclose(r1, r2, atol=1e-6)
    assert mujoco_plant.link_name(mujoco_plant.foot_links["left"]) == G1.left_ankle_link


def test_bad_model_input_names_the_field():
    """A joint that is not a hinge of the URDF, or a negative armature, is refused."""
    text = PENDULUM.format(i=LINK_INERTIA)
    with pytest.raises(ParameterError, match="armature"):
        urdf_spec(text, 0.001, {"elbow": 0.1}, {})
    with pytest.raises(ParameterError, match="frictionloss"):
        urdf_spec(text, 0.001, {}, {"hinge": -1.0})


def test_the_whole_body_controller_holds_g1_standing_on_mujoco(engines):
    """The full-robot backend on MuJoCo (``rsg run --model mujoco``): G1 stands 1 s under
    the whole-body controller with the test's DCM feedback (the ideal sensors), the feet
    carrying m g within 2 % at the end (a 10 ms tick's average, not a settled state)."""
    from app.backends.mujoco import MujocoBackend
    from app.reality import robot_reality
    from app.setup.build import build_backend
    from conftest import assert_stands_one_second

    backend, _, _ = build_backend("mujoco", None, "rsg", reality="ideal")
    try:
        assert isinstance(backend, MujocoBackend) and backend.name == "mujoco"
        assert isinstance(backend.sim, MujocoRobot)
        assert backend.reality == robot_reality(G1, "ideal", 0)
        assert_stands_one_second(backend)
    finally:
        backend.close()
