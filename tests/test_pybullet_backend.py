"""The PyBullet backend: masses, standing, the LIPM it realises, stepping, falls,
determinism and the physics log."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from app.backends.base import InitialCondition
from app.backends.pybullet import PyBulletBackend
from app.reality import robot_reality
from conftest import LEFT, RIGHT, cache_for_module, command, dcm_feedback_zmp
from planner.exceptions import ParameterError
from planner.parameters import GRAVITY
from planner.types import Foothold, StepEvent
from robots import get_robot

STANDING = InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2))
G1 = get_robot("g1")
IDEAL = robot_reality(G1, "ideal", 0)


pytestmark = pytest.mark.usefixtures("cache_in_tmp")


@pytest.fixture(scope="module")
def backend(tmp_path_factory):
    """One G1 for the module's tests, with exact sensors (the stabilizer's physics is
    what they check; the sensors' noise is app/backends/sensors.py's); each test resets
    it."""
    with cache_for_module(tmp_path_factory):
        instance = PyBulletBackend(G1, reality=IDEAL)
    yield instance
    instance.close()


def stand(backend, state, seconds, push=None, feedback=True):
    """Run ``seconds`` of double support on LEFT and RIGHT from the measured ``state``
    with ``push(time)`` [N] on the pelvis; stops at a fall. The ZMP comes from the
    test's DCM feedback towards the origin (the planner's part), or stays at the
    origin without ``feedback``. Returns the last measured state."""
    for tick in range(round(seconds / backend.control_period)):
        time = tick * backend.control_period
        zmp = np.zeros(2)
        if feedback:
            zmp = dcm_feedback_zmp(state, np.zeros(2), backend.description.pendulum_height)
        force = push(time) if push else np.zeros(2)
        state = backend.step(command(time, zmp), force)
        if backend.fall_status().fell:
            break
    return state


def total_cop(backend):
    """Measured CoP of both feet [m] and their total normal force [N]."""
    pressure = backend.foot_pressure()
    total = sum(force for _, force in pressure.values())
    return sum(point * force for point, force in pressure.values()) / total, total


def test_mass_in_pybullet_equals_the_urdf_mass(backend):
    assert backend.mass == pytest.approx(33.3, abs=0.1)
    assert backend.com_height == pytest.approx(0.66)  # drawn there; the planner's is taller
    assert backend.description.pendulum_height == pytest.approx(0.66 + 0.10)
    # The controller's rigid-body model is the simulator's robot.
    assert backend.controller.mass == pytest.approx(backend.mass, abs=1e-6)


def test_g1_stands_still_and_its_feet_carry_the_weight_under_the_com(backend):
    """With the planner's part played by a DCM feedback: after 2 s the CoM is where it
    started and still, both feet carry m g, and their CoP is under the CoM."""
    start = backend.reset(STANDING)
    state = stand(backend, start, 2.0)
    assert not backend.fall_status().fell
    assert state.time == pytest.approx(2.0)
    assert np.linalg.norm(state.com_position - start.com_position) < 0.005
    assert np.linalg.norm(state.com_velocity) < 0.005
    assert backend.feet_in_contact() == {"left", "right"}
    cop, total = total_cop(backend)
    assert total == pytest.approx(backend.mass * GRAVITY, rel=0.02)
    assert np.linalg.norm(cop - state.com_position) < 0.005
    assert {"control", "physics", "estimation", "total"} <= set(backend.timing_report())


def test_under_a_constant_push_the_measured_cop_follows_the_planned_one(backend):
    """20 N forward on the pelvis: the DCM feedback moves the planned CoP ahead of the
    CoM to hold it (moment balance: by about F z / (m g), z the push's height); the
    feet's measured CoP follows it within 8 mm (measured 5.3 mm: the ankles' Coulomb
    friction, 1.2 N m against m g = 327 N, holds the CoP up to 4 mm off) through the
    feed-forward ankle torques, while the planned CoP moves by about 8 cm (the CoM filter
    takes part of a constant push for a CoM offset: in the LIPM the two are one)."""
    state = backend.reset(STANDING)

    def push(time):
        return np.array([20.0, 0.0])

    state = stand(backend, state, 2.0, push)
    assert not backend.fall_status().fell
    cop, total = total_cop(backend)
    planned = backend.planned_cop
    assert planned[0] > 0.07
    assert np.linalg.norm(cop - planned) < 0.008, f"{cop=} {planned=}"
    assert total == pytest.approx(backend.mass * GRAVITY, rel=0.02)


@pytest.fixture(scope="module")
def talos(tmp_path_factory):
    """Talos, whose ankles have force-torque sensors, with exact sensors."""
    with cache_for_module(tmp_path_factory):
        talos = get_robot("talos")
        instance = PyBulletBackend(talos, reality=robot_reality(talos, "ideal", 0))
    yield instance
    instance.close()


@pytest.mark.parametrize("offset", [(0.01, 0.0), (0.0, 0.01)])
def test_with_a_constant_zmp_the_com_diverges_as_the_lipm(talos, offset):
    """The stabilizer realises the planner's pendulum, c_z + h_r tall: with the ZMP held
    at the origin and the CoM starting 1 cm off it at rest, the LIPM from the CoM state
    at 0.1 s (once the feet's contacts have formed) is c(t) = c1 cosh(omega dt) + v1
    sinh(omega dt) / omega; by 0.5 s Talos's CoM has moved away from the ZMP by 0.15 to 1.6
    times the pendulum's growth (measured 1.15 forward, 0.24 sideways: under the plain
    motor law the legs' stiff joint loops, not the feed-forward, share the weight between
    two feet on the ground, and the sideways CoP stays nearer the CoM). On Talos: its
    ankle sensors measure how the weight is shared between the feet. G1 has none, and
    the joint torques do not show it: its motors' Coulomb friction holds up to 13 N of
    the split out of them, so a G1 in double support stands with the CoP under its CoM
    (docs/full-robot.md, "The honest plant")."""
    backend = talos
    offset = np.array(offset)
    axis = int(np.argmax(np.abs(offset)))
    half = backend.description.foot_spacing / 2
    feet = (Foothold("left", np.array([0.0, half])), Foothold("right", np.array([0.0, -half])))
    state = backend.reset(InitialCondition(*feet, offset, np.zeros(2)))
    settled = None
    for tick in range(round(0.5 / backend.control_period)):
        state = backend.step(command(tick * backend.control_period, np.zeros(2)), np.zeros(2))
        if settled is None and state.time >= 0.1 - 1e-9:
            settled = (state.time, *(x[:2] for x in backend.sim.com_state()))
    assert not backend.fall_status().fell
    omega = np.sqrt(GRAVITY / backend.description.pendulum_height)
    time, position, velocity = settled
    elapsed = state.time - time
    predicted = position * np.cosh(omega * elapsed) + velocity * np.sinh(omega * elapsed) / omega
    growth = predicted[axis] - position[axis]
    final = backend.sim.com_state()[0][:2]
    assert growth > 0.005
    ratio = (final[axis] - position[axis]) / growth
    assert 0.15 < ratio < 1.6, ratio


def test_base_configuration_is_the_urdf_pelvis_frame(backend):
    backend.reset(STANDING)
    position, quaternion, joints = backend.robot_configuration()
    ik_base = backend.controller.ik.robot.get_T_world_fbase()
    assert np.allclose(position, ik_base[:3, 3], atol=1e-6)
    assert np.isclose(abs(quaternion[3]), 1.0, atol=1e-6)
    assert set(joints) == set(backend.controller.ik.joint_names)


def test_strong_push_without_stepping_is_detected_as_a_fall(backend):
    """40 N s sideways is far more than G1 can take on its feet without a step."""
    state = backend.reset(STANDING)

    def push(time):
        return np.array([0.0, 400.0]) if 0.2 <= time < 0.3 else np.zeros(2)

    stand(backend, state, 1.5, push)
    status = backend.fall_status()
    assert status.fell and status.reason


def test_swing_foot_lands_on_a_target_moved_during_the_swing(backend):
    """The next step moves from (0.08, -0.115) to (0.1, -0.13) m at 0.3 s: the swing
    sole lands there, on the ground, by the planned step at 0.8 s, and stays there in
    the double support."""
    over_left = LEFT.position.copy()
    state = backend.reset(InitialCondition(LEFT, RIGHT, over_left, np.zeros(2)))
    moved = np.array([0.1, -0.13])
    for tick in range(round(0.8 / backend.control_period)):
        time = tick * backend.control_period
        target = np.array([0.08, -0.115]) if time < 0.3 else moved
        zmp = dcm_feedback_zmp(state, over_left, backend.description.pendulum_height)
        out = command(time, zmp, next_step=Foothold("right", target), since_step=time)
        state = backend.step(out, np.zeros(2))
        assert not backend.fall_status().fell
    landed = Foothold("right", moved)
    assert "right" in backend.feet_in_contact()
    event = StepEvent(0.8, "right", landed.position, False, False)
    for tick in range(10):  # the double support after the step
        time = 0.8 + tick * backend.control_period
        zmp = dcm_feedback_zmp(state, over_left, backend.description.pendulum_height)
        out = command(
            time,
            zmp,
            stance=landed,
            swing=LEFT,
            since_step=time - 0.8,
            step=event if tick == 0 else None,
        )
        state = backend.step(out, np.zeros(2))
        sole = backend.sole_positions()["right"]
        assert np.linalg.norm(sole[:2] - landed.position) < 0.01, f"{time=} {sole=}"
        assert abs(sole[2]) < 0.005, f"{time=} {sole=}"
    assert not backend.fall_status().fell


def test_an_unreachable_stance_foot_is_reached_for_not_a_failure(backend):
    """Feet 1.5 m apart in double support are far out of the legs' reach: the IK, its
    tasks soft, commands a posture towards them, every joint target finite and within its
    limits, and nothing is reported as failed (with the support soles as hard tasks
    placo's QP had no solution)."""
    backend.reset(STANDING)
    ik = backend.controller.ik
    far = Foothold("left", np.array([1.5, 0.1]))
    backend.step(command(0.0, np.zeros(2), stance=far, since_step=0.0), np.zeros(2))
    angles = ik.joint_angles()
    assert np.all(np.isfinite(angles))
    for name, angle in zip(ik.joint_names, angles, strict=True):
        lower, upper = ik.robot.get_joint_limits(name)
        assert lower - 1e-9 <= angle <= upper + 1e-9, (name, angle)
    assert backend.controller.failure is None
    backend.reset(STANDING)


def test_an_ik_without_solution_is_a_fall_not_a_crash(backend, monkeypatch):
    """If placo's QP has no solution (seen only with hard tasks, which the IK no longer
    has), the backend holds its joint targets and reports a fall with the reason."""
    from kinematics.whole_body_ik import IkInfeasibleError

    def no_solution(*args, **kwargs):
        raise IkInfeasibleError("both", np.zeros(2), "Infeasible QP")

    backend.reset(STANDING)
    monkeypatch.setattr(backend.controller.ik, "solve", no_solution)
    backend.step(command(0.0, np.zeros(2)), np.zeros(2))
    status = backend.fall_status()
    assert status.fell and "IK infeasible" in status.reason, status
    monkeypatch.undo()
    backend.reset(STANDING)
    assert not backend.fall_status().fell


def test_a_wrench_distribution_without_solution_is_a_fall_not_a_crash(backend, monkeypatch):
    """If the distribution QP finds no wrenches (seen only with the robot thrown about
    by a push far beyond what it recovers), the backend reports a fall with the reason."""
    from app.stabilizer import controller
    from app.stabilizer.wrench_distribution import WrenchDistributionError

    def no_solution(contacts, force, cop, limits):
        raise WrenchDistributionError(len(contacts), force, cop)

    backend.reset(STANDING)
    monkeypatch.setattr(controller, "distribute_wrench", no_solution)
    backend.step(command(0.0, np.zeros(2)), np.zeros(2))
    status = backend.fall_status()
    assert status.fell and "wrench distribution" in status.reason, status
    monkeypatch.undo()
    backend.reset(STANDING)
    assert not backend.fall_status().fell


def test_a_failed_ik_solve_is_a_project_error_with_its_data():
    """placo's QP without an answer (here for a NaN CoM target: its tasks are soft, so
    targets out of reach have one) is an IkInfeasibleError carrying the support and the
    target, and the IK's configuration is left as it was."""
    from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, sole_pose

    ik = WholeBodyIK(get_robot("g1"))
    left, right = sole_pose(np.array([0.0, 0.1, 0.0])), sole_pose(np.array([0.0, -0.1, 0.0]))
    ik.reset(left, right, np.zeros(2))
    before = ik.joint_angles()
    with pytest.raises(IkInfeasibleError) as caught:
        ik.solve(np.array([np.nan, 0.0]), left, right, "both", 0.01)
    assert caught.value.support == "both"
    assert np.isnan(caught.value.com_target[0])
    np.testing.assert_array_equal(ik.joint_angles(), before)


@pytest.mark.parametrize(
    ("options", "field"),
    [
        ({"landing_depth": -0.001}, "landing_depth"),
        ({"friction": "high"}, "friction"),
        ({"estimator": "kalman"}, "backend option"),  # the controller always estimates
        ({"cop_feedback": (0.0, 2.0)}, "backend option"),  # an option of the old backend
        ({"control_period": 0.02}, "control_period"),
        ({"control_period": 0.0055}, "control_period/physics_time_step"),  # 5.5 physics steps
    ],
)
def test_backend_options_are_checked_before_the_robot_is_loaded(options, field):
    robot = dataclasses.replace(get_robot("g1"), backend_options=options)
    with pytest.raises(ParameterError) as error:
        PyBulletBackend(robot)
    assert error.value.field == field


# ------------------------------------------------------ determinism and the log
def pushed_run(logged: bool):
    """1 s of standing with 60 N forward and 30 N sideways from 0.3 to 0.4 s, on a new
    backend; returns the final CoM state and the physics log (or None)."""
    from app.backends.physics_log import PhysicsLog

    instance = PyBulletBackend(G1, reality=IDEAL)
    try:
        state = instance.reset(STANDING)
        if logged:
            instance.physics_log = PhysicsLog()

        def push(time):
            return np.array([60.0, 30.0]) if 0.3 <= time < 0.4 else np.zeros(2)

        stand(instance, state, 1.0, push)
        final = np.concatenate(instance.sim.com_state())
        return final, instance.physics_log, instance.mass, instance.sim.time_step
    finally:
        instance.close()


@pytest.fixture(scope="module")
def pushed_runs(tmp_path_factory):
    with cache_for_module(tmp_path_factory):
        return [pushed_run(False), pushed_run(False), pushed_run(True)]


def test_same_commands_give_the_same_result(pushed_runs):
    """Bit for bit (the QPs' answers are polished: planner/qp.py)."""
    first, second, _ = pushed_runs
    assert np.linalg.norm(first[0][3:5]) > 0.01  # the push moved the robot
    np.testing.assert_array_equal(first[0], second[0])


def test_a_reset_backend_runs_as_a_new_one_after_a_fall(pushed_runs, tmp_path_factory):
    """A bisection runs many pushes on one backend: after a fall and a reset the same run
    ends bit for bit as on a new backend (the contact points the fall left behind once
    warm-started the next run's contacts, and a push that G1 recovered on a new backend
    was lost after earlier trials)."""
    with cache_for_module(tmp_path_factory):
        instance = PyBulletBackend(G1, reality=IDEAL)
    try:
        state = instance.reset(STANDING)
        stand(instance, state, 1.5, lambda t: np.array([0.0, 400.0]) * (0.2 <= t < 0.3))
        assert instance.fall_status().fell

        state = instance.reset(STANDING)
        push = lambda t: np.array([60.0, 30.0]) if 0.3 <= t < 0.4 else np.zeros(2)  # noqa: E731
        stand(instance, state, 1.0, push)
        final = np.concatenate(instance.sim.com_state())
    finally:
        instance.close()
    np.testing.assert_array_equal(final, pushed_runs[0][0])


def test_the_physics_log_observes_without_changing_the_run(pushed_runs):
    """A run with the log ends in the state of the same run without it, bit for bit."""
    plain, _, logged = pushed_runs
    np.testing.assert_array_equal(plain[0], logged[0])


def test_the_physics_log_records_every_step_consistently(pushed_runs, tmp_path):
    """One row per physics step (2 ms on G1); before the push the feet carry the weight
    on average (vertical equilibrium); the CoM velocity is the derivative of the CoM;
    the push is logged while it acts and its impulse is the one applied."""
    from app.backends.physics_log import COLUMNS

    _, log, mass, step = pushed_runs[2]
    path = log.write(tmp_path / "physics.csv")
    header, *lines = path.read_text().splitlines()
    assert tuple(header.split(",")) == COLUMNS
    rows = np.array([[float(v) for v in line.split(",")] for line in lines])
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    assert len(rows) == round(1.0 / step)
    assert np.allclose(np.diff(column["t"]), step)
    quiet = column["t"] < 0.3
    support = column["left_fz"][quiet] + column["right_fz"][quiet]
    assert support.mean() == pytest.approx(mass * GRAVITY, rel=0.02)
    derivative = np.gradient(column["com_x"], column["t"])
    assert np.abs(derivative[5:-5] - column["com_vx"][5:-5]).max() < 0.02
    assert column["push_fx"].sum() * step == pytest.approx(6.0, rel=1e-6)
    assert column["push_fy"].sum() * step == pytest.approx(3.0, rel=1e-6)
    assert np.all(column["left_sole_z"] > -0.005)
    # The controller's plan next to the ground's: the distributed forces carry the weight
    # (and the height loop's correction for a CoM within a millimetre of its target);
    # before the push each foot's measured force follows its planned one, and while the
    # push moves the planned CoP by centimetres, the net CoP follows it.
    planned = column["left_fz_planned"] + column["right_fz_planned"]
    assert planned[quiet].mean() == pytest.approx(mass * GRAVITY, rel=5e-3)
    for foot in ("left", "right"):
        gap = np.abs(column[f"{foot}_fz"] - column[f"{foot}_fz_planned"])[quiet]
        assert gap.mean() < 0.03 * mass * GRAVITY, foot
    total = column["left_fz"] + column["right_fz"]
    net_cop = [
        sum(column[f"{f}_fz"] * np.nan_to_num(column[f"{f}_cop_{a}"]) for f in ("left", "right"))
        / total
        for a in "xy"
    ]
    distance = np.hypot(net_cop[0] - column["planned_cop_x"], net_cop[1] - column["planned_cop_y"])
    pushed = (column["t"] >= 0.3) & (column["t"] < 0.6)
    assert np.abs(column["planned_cop_x"][pushed]).max() > 0.03  # [m]
    assert distance[pushed].mean() < 0.01  # [m] the ankles' friction (see above)


def test_the_physics_log_records_where_the_soles_were_sent(tmp_path):
    """``rsg run --physics-log`` on G1's walk: the swing sole's target lifts to the swing
    height and travels a stride; each sole follows its target, within millimetres while
    it carries load (less closely in the 0.05 s its leg lands compliant) and within
    centimetres in the air."""
    from app.backends.physics_log import COLUMNS
    from app.cli import main

    argv = ["run", "--scenario", "walk", "--duration", "1.0", "--physics-log", "--quiet",
            "--reality", "ideal"]  # fmt: skip
    main([*argv, "--out", str(tmp_path)])
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert not summary["fell"]
    header, *lines = (tmp_path / "physics.csv").read_text().splitlines()
    assert tuple(header.split(",")) == COLUMNS
    rows = np.array([[float(v) for v in line.split(",")] for line in lines])
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    loaded_force = 0.05 * summary["mass"] * GRAVITY  # [N] the controller's contact threshold
    for foot in ("left", "right"):
        target = np.stack([column[f"{foot}_sole_target_{a}"] for a in "xyz"], axis=1)
        sole = np.stack([column[f"{foot}_sole_{a}"] for a in "xyz"], axis=1)
        assert np.isfinite(target).all(), foot
        gap = np.linalg.norm(sole[:, :2] - target[:, :2], axis=1)
        loaded = column[f"{foot}_fz"] > loaded_force
        assert loaded.any() and (~loaded).any(), foot  # each foot stands and swings
        assert gap[loaded].mean() < 0.008 and gap[loaded].max() < 0.02, foot  # [m]
        assert gap[~loaded].mean() < 0.02, foot  # [m]
    # The foot that has swung a whole step (the other has just lifted off by 1.0 s).
    swing = max(("left", "right"), key=lambda foot: np.ptp(column[f"{foot}_sole_target_x"]))
    assert np.ptp(column[f"{swing}_sole_target_x"]) > 0.15  # a stride, [m]
    apex = get_robot("g1").swing_height  # [m] the swing profile's top
    assert column[f"{swing}_sole_target_z"].max() == pytest.approx(apex, abs=0.001)


def test_the_physics_plot_draws_the_logs_forces_and_cops(pushed_runs, tmp_path):
    """physics.png: each foot's measured and planned normal force, the feet's net CoP
    (their forces' weighted mean) against the planned CoP, and each sole's tilt and yaw in
    degrees, at the log's times."""
    from app.backends.physics_log import COLUMNS
    from app.results.physics_plot import plot_physics

    rows = np.array(pushed_runs[2][1].rows)
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    figure = plot_physics(rows, tmp_path / "physics.png")
    assert (tmp_path / "physics.png").read_bytes()[:4] == b"\x89PNG"
    forces, cop_x, cop_y, angles = figure.axes
    lines = {line.get_label(): line for line in forces.lines}
    for foot in ("left", "right"):
        np.testing.assert_array_equal(lines[f"{foot}, measured"].get_xdata(), column["t"])
        np.testing.assert_array_equal(lines[f"{foot}, measured"].get_ydata(), column[f"{foot}_fz"])
        planned = lines[f"{foot}, planned"].get_ydata()
        np.testing.assert_array_equal(planned, column[f"{foot}_fz_planned"])
    total = column["left_fz"] + column["right_fz"]
    assert np.all(total > 0.0)  # standing: the net CoP is defined at every step
    for axes, axis in ((cop_x, "x"), (cop_y, "y")):
        measured, planned = axes.lines
        moments = sum(
            column[f"{f}_fz"] * np.nan_to_num(column[f"{f}_cop_{axis}"]) for f in ("left", "right")
        )
        np.testing.assert_allclose(measured.get_ydata(), moments / total)
        np.testing.assert_array_equal(planned.get_ydata(), column[f"planned_cop_{axis}"])
    lines = {line.get_label(): line for line in angles.lines}
    for foot in ("left", "right"):
        for angle in ("tilt", "yaw"):
            line = lines[f"{foot}, {angle}"]
            np.testing.assert_array_equal(line.get_xdata(), column["t"])
            np.testing.assert_allclose(line.get_ydata(), np.degrees(column[f"{foot}_sole_{angle}"]))


def test_the_physics_log_shows_a_loaded_sole_on_its_edge(backend):
    """The soles' angles in the log against the ground's CoP. Standing (after 0.1 s of
    settling from the reset), both soles are flat and head along x. Pushed sideways with
    400 N for 0.1 s, G1 falls over its feet, which roll onto their edges: wherever a sole
    carrying load is tilted by 3-10 deg, its CoP is within 5 mm of the edge of the sole's
    contact rectangle (a rigid sole tilted on flat ground touches it only along an edge;
    the rectangle is taken flat, which up to 10 deg shortens it by less than 2 mm)."""
    from app.backends.physics_log import COLUMNS, PhysicsLog

    state = backend.reset(STANDING)
    backend.physics_log = PhysicsLog()
    try:
        stand(backend, state, 1.5, lambda t: np.array([0.0, 400.0]) * (0.2 <= t < 0.3))
        rows = np.array(backend.physics_log.rows)
    finally:
        backend.physics_log = None
    assert backend.fall_status().fell
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    sole = backend.description.sole
    loaded = 0.05 * backend.mass * GRAVITY  # [N] the controller's contact threshold
    on_edge = 0
    for foot in ("left", "right"):
        tilt, yaw = column[f"{foot}_sole_tilt"], column[f"{foot}_sole_yaw"]
        carrying = column[f"{foot}_fz"] > loaded
        before = carrying & (column["t"] >= 0.1) & (column["t"] < 0.2)  # standing, settled
        assert before.sum() >= 45, foot  # [physics steps]
        assert np.degrees(tilt[before]).max() < 0.5, foot
        assert np.degrees(np.abs(yaw[before])).max() < 0.5, foot
        tilted = carrying & (tilt > np.radians(3.0)) & (tilt < np.radians(10.0))
        on_edge += int(tilted.sum())
        dx = column[f"{foot}_cop_x"][tilted] - column[f"{foot}_sole_x"][tilted]
        dy = column[f"{foot}_cop_y"][tilted] - column[f"{foot}_sole_y"][tilted]
        c, s = np.cos(yaw[tilted]), np.sin(yaw[tilted])
        x, y = c * dx + s * dy, -s * dx + c * dy  # the CoP in the sole's frame [m]
        to_edge = np.min(
            np.abs([x - sole.x_min, x - sole.x_max, y - sole.half_width, y + sole.half_width]),
            axis=0,
        )
        assert np.all(to_edge < 0.005), (foot, to_edge.max(initial=0.0))
    assert on_edge > 20  # the fall rolls the soles onto their edges


def test_the_physics_log_writes_each_soles_tilt_and_yaw():
    """The angles written for a sole turned 20 deg to the left about the vertical and then
    rolled 10 deg about its own forward axis: tilt 10 deg, yaw 20 deg (a sole's yaw is
    its forward axis's heading from the world's x, counter-clockwise seen from above)."""
    from app.backends.physics_log import COLUMNS, PhysicsLog
    from kinematics.whole_body_ik import yaw_rotation

    roll = np.radians(10.0)
    rolled = np.array(
        [[1.0, 0.0, 0.0], [0.0, np.cos(roll), -np.sin(roll)], [0.0, np.sin(roll), np.cos(roll)]]
    )
    turned = {"left": yaw_rotation(np.radians(20.0)) @ rolled, "right": np.eye(3)}

    class Ground:  # what the log reads of the simulator, with known sole frames
        time = 0.5

        def com_state(self):
            return np.zeros(3), np.zeros(3)

        def foot_pressure(self):
            return {}

        def sole_frame(self, foot, forward_kinematics=True):
            return np.zeros(3), turned[foot]

    log = PhysicsLog()
    log.record(Ground(), None)
    row = dict(zip(COLUMNS, log.rows[0], strict=True))
    assert np.degrees(row["left_sole_tilt"]) == pytest.approx(10.0)
    assert np.degrees(row["left_sole_yaw"]) == pytest.approx(20.0)
    assert row["right_sole_tilt"] == pytest.approx(0.0) and row["right_sole_yaw"] == 0.0
