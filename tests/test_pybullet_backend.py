"""The PyBullet backend: masses, standing, stepping, falls, determinism."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from app.backend import InitialCondition
from app.pybullet_backend import CONTACT_WINDOW, SWING_FEEDBACK_LIMIT, PyBulletBackend
from app.pybullet_com_plan import ADMITTANCE_LIMIT, clip_to_hull, cop_admittance_zmp
from planner.exceptions import ParameterError
from planner.types import Foothold, PlannerOutput, StepEvent

LEFT = Foothold("left", np.array([0.0, 0.115]))
RIGHT = Foothold("right", np.array([0.0, -0.115]))


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


@pytest.fixture
def backend():
    instance = PyBulletBackend("g1")
    yield instance
    instance.close()


def command(
    time, zmp, stance=LEFT, swing=RIGHT, next_step=None, since_step=0.0, step=None
) -> PlannerOutput:
    zmp = np.asarray(zmp, float)
    return PlannerOutput(
        time=time,
        zmp=zmp,
        zmp_offset=np.zeros(2),
        window_center=zmp,
        angular_momentum_rate=np.zeros(2),
        angular_momentum_rate_feedback=np.zeros(2),
        stance=stance,
        previous_stance=swing,
        next_step=next_step or swing,
        next_step_time=time - since_step + 0.8,
        time_since_step=since_step,
        double_support=since_step < 0.1,
        dcm_error=np.zeros(2),
        lyapunov=0.0,
        lyapunov_at_step=0.0,
        com_reference=zmp,
        step=step,
    )


def stand(backend, seconds, push=None, zmp=(0.0, 0.0)):
    state = None
    for tick in range(round(seconds / backend.control_period)):
        time = tick * backend.control_period
        force = push(time) if push else np.zeros(2)
        state = backend.step(command(time, zmp), force)
        if backend.fall_status().fell:
            break
    return state


def test_mass_in_pybullet_equals_the_urdf_mass(backend):
    assert backend.mass == pytest.approx(33.3, abs=0.1)
    assert backend.com_height == pytest.approx(0.66)


def test_g1_stands_still_for_5_s_with_constant_commands(backend):
    start = backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    assert backend.feet_in_contact() == set() or backend.fall_status().fell is False
    state = stand(backend, 5.0)
    assert not backend.fall_status().fell
    assert state.time == pytest.approx(5.0)
    assert np.linalg.norm(state.com_position - start.com_position) < 0.01
    assert np.linalg.norm(state.com_velocity) < 0.01
    assert backend.feet_in_contact() == {"left", "right"}
    report = backend.timing_report()
    assert {"physics", "ik", "estimation", "planning", "total"} <= set(report)


def test_base_configuration_is_the_urdf_pelvis_frame(backend):
    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    position, quaternion, joints = backend.robot_configuration()
    ik_base = backend.ik.robot.get_T_world_fbase()
    assert np.allclose(position, ik_base[:3, 3], atol=1e-6)
    assert np.isclose(abs(quaternion[3]), 1.0, atol=1e-6)
    assert set(joints) == set(backend.ik.joint_names)


def test_strong_push_without_stepping_is_detected_as_a_fall(backend):
    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))

    def push(time):
        return np.array([0.0, 400.0]) if 0.5 <= time < 0.6 else np.zeros(2)

    stand(backend, 3.0, push)
    status = backend.fall_status()
    assert status.fell and status.reason


@pytest.mark.parametrize(
    "options",
    [
        {"transfer_lift": -0.001},
        {"transfer_lift": 0.05},
        {"transfer_ramp": 0.0},
        {"momentum_compensation": 1.5},
        {"momentum_filter": 0.0},
        {"cop_margin": 0.03},
        {"landing_clearance": -0.001},
        {"landing_clearance": 0.02},
        {"landing_correction": 2.0},
        {"cop_feedback": -1.0},
        {"cop_admittance": -0.1},
        {"cop_admittance": 3.0},
        {"stance_switch": "early"},
        {"swing_feedback": 1.5},
        {"swing_feedback": -0.1},
        {"swing_feedback_filter": 0.0},
        {"swing_level_feedback": 1.5},
        {"swing_level_feedback": -0.1},
    ],
)
def test_walking_options_are_validated(options):
    with pytest.raises(ParameterError):
        PyBulletBackend("g1", **options)


def test_old_foot_is_lifted_after_the_step_and_the_cop_plan_stays_on_the_sole(backend):
    backend.reset(InitialCondition(LEFT, RIGHT, np.array([0.0, 0.05]), np.zeros(2)))
    backend.transfer_lift, backend.momentum_compensation = 0.003, 1.0
    event = StepEvent(0.0, "right", RIGHT.position, False, False)
    lifts = []
    for tick in range(8):
        time = tick * backend.control_period
        out = command(time, RIGHT.position, stance=RIGHT, swing=LEFT, since_step=time)
        out = dataclasses.replace(out, step=event if tick == 0 else None)
        backend.step(out, np.zeros(2))
        lifts.append(backend.ik.sole_world("left")[2, 3])
        # A commanded pivot far outside the sole is clipped onto it.
        far = dataclasses.replace(out, zmp=RIGHT.position + np.array([0.0, -0.3]))
        zmp, _ = backend._momentum_aware_pivot(far, far.zmp, np.zeros(2))
        assert RIGHT.position[1] - 0.025 - 1e-9 <= zmp[1] <= RIGHT.position[1] + 0.025
    assert lifts[0] < lifts[-1] == pytest.approx(0.003, abs=5e-4)
    assert not backend.fall_status().fell


def test_the_measured_cop_carries_the_weight_under_the_com(backend):
    """Standing still: the ground reaction of both feet is m g, its CoP under the CoM."""
    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    state = stand(backend, 1.0)
    pressure = backend.foot_pressure()
    assert set(pressure) == {"left", "right"}
    total = sum(force for _, force in pressure.values())
    cop = sum(point * force for point, force in pressure.values()) / total
    assert total == pytest.approx(backend.mass * 9.81, rel=0.03)
    assert np.linalg.norm(cop - state.com_position) < 0.01


def test_cop_admittance_moves_the_plan_to_bring_the_measured_cop_to_the_planned_one():
    """c'' = omega^2 (c - p): a measured CoP behind the planned one (the joints
    accelerate the CoM forward more than planned) makes the plan accelerate less."""
    omega2, com = 9.81 / 0.66, np.array([0.02, 0.0])
    planned = np.array([0.03, 0.0])
    for measured, sign in (([0.0, 0.0], -1.0), ([0.06, 0.01], 1.0)):
        zmp = cop_admittance_zmp(planned, planned, np.array(measured), gain=0.3)
        change = omega2 * (com - zmp) - omega2 * (com - planned)
        assert np.sign(change[0]) == sign
        assert change == pytest.approx(-0.3 * omega2 * (planned - np.array(measured)))
    assert np.array_equal(cop_admittance_zmp(planned, planned, None, 0.3), planned)
    far = cop_admittance_zmp(planned, planned, np.array([1.0, -1.0]), gain=0.3)
    assert np.allclose(np.abs(far - planned), ADMITTANCE_LIMIT)


def test_clip_to_hull_keeps_inside_points_and_projects_outside_ones():
    corners = np.array([[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0], [2.0, 0.5]])
    inside = np.array([1.2, 0.5])
    assert np.array_equal(clip_to_hull(inside, corners), inside)
    assert np.allclose(clip_to_hull(np.array([0.5, -1.0]), corners), [0.5, 0.0])
    assert np.allclose(clip_to_hull(np.array([-1.0, 2.0]), corners), [0.0, 1.0])


def test_same_commands_give_the_same_result():
    results = []
    for _ in range(2):
        backend = PyBulletBackend("g1", com_reference_blend=0.05, com_tracking_gains=(1.0, 0.0))
        backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.array([0.0, 0.1])))
        state = stand(backend, 0.5, lambda t: np.array([20.0, 0.0]), zmp=(0.0, 0.02))
        results.append(np.concatenate([state.com_position, state.com_velocity]))
        backend.close()
    assert np.array_equal(results[0], results[1])


def test_swing_foot_lands_on_a_target_moved_during_the_swing(backend):
    over_left = LEFT.position.copy()
    backend.reset(InitialCondition(LEFT, RIGHT, over_left, np.zeros(2)))
    steps = round(0.8 / backend.control_period)
    for tick in range(steps):
        time = tick * backend.control_period
        target = np.array([0.08, -0.115]) if time < 0.3 else np.array([0.1, -0.13])
        backend.step(
            command(time, over_left, next_step=Foothold("right", target), since_step=time),
            np.zeros(2),
        )
        assert not backend.fall_status().fell
    landed = Foothold("right", np.array([0.1, -0.13]))
    event = StepEvent(0.8, "right", landed.position, False, False)
    for tick in range(20):
        time = 0.8 + tick * backend.control_period
        step = event if tick == 0 else None
        zmp = over_left + (landed.position - over_left) * 0.0
        backend.step(
            command(time, zmp, stance=landed, swing=LEFT, since_step=time - 0.8, step=step),
            np.zeros(2),
        )
    soles = backend.sole_positions()
    assert np.linalg.norm(soles["right"][:2] - landed.position) < 0.01
    assert abs(soles["right"][2]) < 0.005
    assert "right" in backend.feet_in_contact()
    assert not backend.fall_status().fell


def pushed_swing(backend, lateral_force, seconds):
    """Step a right-foot swing from LEFT toward (0.1, -0.13) m with ``lateral_force`` [N]
    on the pelvis from 0.2 to 0.7 s; yield (time [s], swing profile's sole position [m])
    after each tick of single support."""
    over_left = LEFT.position.copy()
    backend.reset(InitialCondition(LEFT, RIGHT, over_left, np.zeros(2)))
    planned: list[np.ndarray] = []
    update = backend.swing.update

    def recorded(*args):
        planned.append(update(*args).copy())
        return planned[-1].copy()

    backend.swing.update = recorded
    target = Foothold("right", np.array([0.1, -0.13]))
    for tick in range(round(seconds / backend.control_period)):
        time = tick * backend.control_period
        push = np.array([0.0, lateral_force]) if 0.2 < time < 0.7 else np.zeros(2)
        backend.step(command(time, over_left, next_step=target, since_step=time), push)
        if time > 0.1:  # single support
            yield time, planned[-1]


@pytest.mark.parametrize("gain", [0.0, 1.0])
def test_swing_feedback_keeps_the_real_swing_sole_on_its_trajectory_under_a_push(gain):
    """40 N sideways on the pelvis during the swing tilts G1 on its stance leg: without
    feedback the real swing sole ends 6.8 mm (relative to the stance sole) from where
    the swing trajectory puts it, with ``swing_feedback`` 1 within 1 mm (measured). The
    IK's swing sole is the trajectory's minus the filtered offset."""
    backend = PyBulletBackend("g1", swing_feedback=gain)
    try:
        for _, planned in pushed_swing(backend, 40.0, 0.78):
            ik = backend.ik.sole_world("right")[:2, 3]
            shifted = planned[:2] - gain * backend._swing_offset
            np.testing.assert_allclose(ik, shifted, atol=5e-4)
        assert not backend.fall_status().fell
        real = backend.sim.sole_position("right")[:2] - backend.sim.sole_position("left")[:2]
        error = float(np.linalg.norm(real - (planned[:2] - LEFT.position)))
        if gain == 0.0:
            assert error > 0.004
            assert not backend._swing_offset.any()
        else:
            assert error < 0.002
            assert 0.003 < np.linalg.norm(backend._swing_offset) <= SWING_FEEDBACK_LIMIT
    finally:
        backend.close()


@pytest.mark.parametrize("gain", [0.0, 1.0])
def test_swing_level_feedback_keeps_the_swing_sole_at_its_height_and_flat_under_a_push(gain):
    """40 N toward the swing side during the swing rolls G1 over its stance foot: without
    feedback the real swing sole's lowest corner comes down to 5 mm where the swing
    profile is at 34 mm (an early touchdown) and the sole tilts by 6.6 deg; with
    ``swing_level_feedback`` 1 it stays within 7 mm of the profile and within 1.5 deg
    of flat (measured). The IK's swing sole is raised by the filtered sag."""
    backend = PyBulletBackend("g1", swing_level_feedback=gain)
    try:
        height_errors, tilts = [], []
        for _, planned in pushed_swing(backend, -40.0, 0.62):
            ik = backend.ik.sole_world("right")[2, 3]
            raised = max(planned[2], backend.landing_clearance) + gain * backend._swing_sag
            assert ik == pytest.approx(raised, abs=5e-4)
            origin, rotation = backend.sim.sole_frame("right")
            lowest = origin[2] + np.min(rotation[2] @ backend._sole_corners.T)
            height_errors.append(abs(lowest - planned[2]))
            tilts.append(np.degrees(np.arccos(min(rotation[2, 2], 1.0))))
        assert not backend.fall_status().fell
        if gain == 0.0:
            assert max(height_errors) > 0.02 and tilts[-1] > 5.0
            assert backend._swing_sag == 0.0
        else:
            assert max(height_errors) < 0.01 and max(tilts) < 2.0
            assert backend._swing_sag > 0.01
    finally:
        backend.close()


def test_landing_clearance_keeps_the_swing_sole_up_until_the_step(backend):
    backend.landing_clearance = 0.002
    over_left = LEFT.position.copy()
    backend.reset(InitialCondition(LEFT, RIGHT, over_left, np.zeros(2)))
    heights = []
    for tick in range(round(0.8 / backend.control_period)):
        time = tick * backend.control_period
        backend.step(command(time, over_left, since_step=time), np.zeros(2))
        heights.append(backend.ik.sole_world("right")[2, 3])
    assert min(heights[20:]) == pytest.approx(0.002, abs=5e-4)
    # After the step the new stance sole is lowered from the clearance to the ground.
    assert backend._settle(0.0) == pytest.approx(0.002)
    assert backend._settle(backend.transfer_ramp) == 0.0
    assert not backend.fall_status().fell


def test_an_unreachable_stance_foot_is_a_fall_not_a_crash(backend):
    """Feet 1.5 m apart in double support make placo's QP infeasible: the backend
    holds its joint targets and reports a fall with the reason."""
    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    far = Foothold("left", np.array([1.5, 0.1]))
    backend.step(command(0.0, np.zeros(2), stance=far, since_step=0.0), np.zeros(2))
    status = backend.fall_status()
    assert status.fell and "IK infeasible" in status.reason
    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    assert not backend.fall_status().fell


def test_ik_infeasibility_is_a_project_error_with_its_data():
    from kinematics.whole_body_ik import IkInfeasibleError, WholeBodyIK, sole_pose
    from robots import get_robot

    ik = WholeBodyIK(get_robot("g1"))
    ik.reset(
        sole_pose(np.array([0.0, 0.1, 0.0])), sole_pose(np.array([0.0, -0.1, 0.0])), np.zeros(2)
    )
    before = ik.joint_angles()
    with pytest.raises(IkInfeasibleError) as caught:
        ik.solve(
            np.zeros(2),
            sole_pose(np.array([1.0, 0.1, 0.0])),
            sole_pose(np.array([-1.0, -0.1, 0.0])),
            "both",
            0.01,
        )
    assert caught.value.support == "both"
    np.testing.assert_array_equal(ik.joint_angles(), before)


def test_foothold_feedback_aims_the_swing_foot_against_the_stance_offset():
    """The stance sole is measured at the end of the double support; the swing target
    is shifted by minus its offset from the planner's foothold."""
    backend = PyBulletBackend("g1", foothold_feedback=True)
    try:
        shifted = Foothold("left", LEFT.position + np.array([0.01, 0.0]))  # o_H 1 cm ahead
        backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
        for tick in range(15):
            since = tick * backend.control_period
            backend.step(
                command(since, LEFT.position, stance=shifted, since_step=since), np.zeros(2)
            )
        measured = backend.sim.sole_position("left")[:2]
        np.testing.assert_allclose(backend._stance_offset, measured - shifted.position, atol=1e-3)
        assert backend._stance_offset[0] == pytest.approx(-0.01, abs=0.004)
    finally:
        backend.close()


@pytest.mark.parametrize("reanchor_min", [0.0, 0.02])
def test_reanchor_reports_the_measured_stance_sole_once_after_the_double_support(reanchor_min):
    """With ``reanchor_stance`` the measured state carries the stance sole, as measured,
    at the end of the double support and at no other tick, when it stands further than
    ``reanchor_min`` from the planner's foothold (here 1.2 cm); the foothold feedback
    then keeps no offset of its own. A nearer sole is left to the foothold feedback."""
    backend = PyBulletBackend(
        "g1", foothold_feedback=True, reanchor_stance=True, reanchor_min=reanchor_min
    )
    try:
        shifted = Foothold("left", LEFT.position + np.array([0.01, 0.0]))  # o_H 1 cm ahead
        backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
        reports = []
        for tick in range(30):
            since = tick * backend.control_period
            state = backend.step(
                command(since, LEFT.position, stance=shifted, since_step=since), np.zeros(2)
            )
            if state.stance_sole is not None:
                reports.append((since, state.stance_sole, backend.sim.sole_position("left", False)))
        if reanchor_min > 0.0:
            assert reports == []
            assert backend._stance_offset[0] == pytest.approx(-0.01, abs=0.004)
            return
        assert len(reports) == 1
        since, sole, measured = reports[0]
        assert since <= 0.1 < since + backend.control_period  # T_DSP = 0.1 s
        np.testing.assert_allclose(sole, measured[:2], atol=1e-9)
        assert sole[0] == pytest.approx(LEFT.position[0], abs=0.004)  # not at o_H
        np.testing.assert_array_equal(backend._stance_offset, np.zeros(2))
    finally:
        backend.close()


@pytest.mark.parametrize("switch", ["planned", "contact"])
def test_a_touchdown_is_reported_only_when_the_stance_switches_at_contact(switch):
    """The swing sole landing under load within CONTACT_WINDOW of the planned step is a
    touchdown at the measured sole, for ``stance_switch="contact"`` only. The ZMP is
    held 2 cm inside the left sole's centre line, so the robot leans towards the right
    foot and loads it as soon as it is down (with the ZMP on the centre line the foot
    comes down onto the ground carrying almost nothing, 0.26 m g at the step)."""
    backend = PyBulletBackend("g1", stance_switch=switch)
    try:
        over_left = LEFT.position + np.array([0.0, -0.02])
        backend.reset(InitialCondition(LEFT, RIGHT, over_left, np.zeros(2)))
        touchdowns = []
        for tick in range(round(0.8 / backend.control_period)):
            time = tick * backend.control_period
            state = backend.step(command(time, over_left, since_step=time), np.zeros(2))
            if state.touchdown is not None:
                touchdowns.append((state.time, state.touchdown))
        assert not backend.fall_status().fell
    finally:
        backend.close()
    if switch == "planned":
        assert touchdowns == []
        return
    assert touchdowns, "the swing foot lands at 0.8 s under load"
    for time, position in touchdowns:
        assert 0.8 - CONTACT_WINDOW <= time < 0.8
        np.testing.assert_allclose(position, RIGHT.position, atol=0.01)


def test_the_physics_log_records_every_step_consistently(backend, tmp_path):
    """Standing, then pushed: one row per physics step (2 ms on G1); the feet carry the weight on
    average (vertical equilibrium); the CoM velocity is the derivative of the CoM;
    the push is logged while it acts and its impulse is the one applied."""
    from app.physics_log import COLUMNS, PhysicsLog

    backend.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
    backend.physics_log = PhysicsLog()

    def push(time):
        return np.array([20.0, 0.0]) if 0.5 <= time < 0.6 else np.zeros(2)

    stand(backend, 1.0, push)
    path = backend.physics_log.write(tmp_path / "physics.csv")
    header, *lines = path.read_text().splitlines()
    assert tuple(header.split(",")) == COLUMNS
    rows = np.array([[float(v) for v in line.split(",")] for line in lines])
    column = {name: rows[:, i] for i, name in enumerate(COLUMNS)}
    step = backend.sim.time_step
    assert len(rows) == round(1.0 / step)
    assert np.allclose(np.diff(column["t"]), step)
    quiet = column["t"] < 0.5
    weight = backend.mass * 9.81
    support = column["left_fz"][quiet] + column["right_fz"][quiet]
    assert support.mean() == pytest.approx(weight, rel=0.02)
    derivative = np.gradient(column["com_x"], column["t"])
    assert np.abs(derivative[5:-5] - column["com_vx"][5:-5]).max() < 0.02
    impulse = column["push_fx"].sum() * step
    assert impulse == pytest.approx(2.0, rel=1e-6)
    assert np.all(column["left_sole_z"] > -0.005)


def test_the_physics_log_observes_without_changing_the_run():
    """A run with the log ends in exactly the state of the same run without it."""
    from app.physics_log import PhysicsLog

    def push(time):
        return np.array([60.0, 30.0]) if 0.3 <= time < 0.4 else np.zeros(2)

    finals = []
    for logged in (False, True):
        instance = PyBulletBackend("g1")
        try:
            instance.reset(InitialCondition(LEFT, RIGHT, np.zeros(2), np.zeros(2)))
            if logged:
                instance.physics_log = PhysicsLog()
            state = stand(instance, 1.0, push)
            finals.append(np.concatenate([state.com_position, state.com_velocity]))
        finally:
            instance.close()
    np.testing.assert_array_equal(finals[0], finals[1])
