"""Whole-body IK, swing-foot trajectory and LIPM CoM plan."""

from __future__ import annotations

import numpy as np
import pytest

from kinematics.pendulum import rotational_height
from kinematics.reach import holds, lateral_reach, stance
from kinematics.swing_foot import SwingFootTrajectory, SwingTiming, swing_height, swing_yaw
from kinematics.whole_body_ik import KNEE_MARGIN, WholeBodyIK, leg_joints, sole_pose
from planner.exceptions import ParameterError
from robots import get_robot

DT = 0.01


@pytest.fixture(scope="module")
def ik():
    return WholeBodyIK(get_robot("g1"))


def test_ik_reaches_com_targets_with_feet_fixed(ik):
    left, right = sole_pose([0.0, 0.115, 0.0]), sole_pose([0.0, -0.115, 0.0])
    ik.reset(left, right, np.zeros(2))
    assert ik.com_world()[2] == pytest.approx(get_robot("g1").com_height, abs=5e-3)
    for target in ([0.03, 0.0], [0.0, 0.08], [-0.02, -0.06]):
        for _ in range(30):
            ik.solve(np.array(target), left, right, "both", DT)
        assert np.linalg.norm(ik.com_world()[:2] - target) < 2e-3
        assert np.linalg.norm(ik.sole_world("left")[:3, 3] - left[:3, 3]) < 1e-4
        assert np.linalg.norm(ik.sole_world("right")[:3, 3] - right[:3, 3]) < 1e-3


def test_ik_moves_the_swing_foot_in_single_support(ik):
    left, right = sole_pose([0.0, 0.115, 0.0]), sole_pose([0.0, -0.115, 0.0])
    ik.reset(left, right, np.array([0.0, 0.1]))
    lifted = sole_pose([0.1, -0.115, 0.05])
    for _ in range(30):
        ik.solve(np.array([0.0, 0.1]), left, lifted, "left", DT)
    assert np.linalg.norm(ik.sole_world("right")[:3, 3] - lifted[:3, 3]) < 5e-3
    assert np.linalg.norm(ik.sole_world("left")[:3, 3] - left[:3, 3]) < 1e-4


def test_ik_reports_the_angular_momentum_of_its_own_motion(ik):
    left, right = sole_pose([0.0, 0.115, 0.0]), sole_pose([0.0, -0.115, 0.0])
    ik.reset(left, right, np.array([0.0, 0.1]))
    for _ in range(5):
        ik.solve(np.array([0.0, 0.1]), left, right, "left", DT)
    assert np.linalg.norm(ik.angular_momentum) < 1e-6  # at rest
    momenta = []
    for k in range(1, 11):  # swing the right foot forward: the body turns about y
        swing = sole_pose([0.02 * k, -0.115, 0.05])
        ik.solve(np.array([0.0, 0.1]), left, swing, "left", DT)
        momenta.append(ik.angular_momentum.copy())
    assert ik.angular_momentum.shape == (3,)
    assert max(abs(m[1]) for m in momenta) > 0.05  # [N m s]


def test_locked_joints_stay_at_their_standing_angle_while_the_others_move(ik):
    """G1's locked arm joints are welded in the physics; the IK must not move them
    either (the CoM task would otherwise use the arms)."""
    g1 = get_robot("g1")
    locked = [ik.joint_names.index(name) for name in g1.locked_joints]
    standing = np.array([g1.standing_posture.get(name, 0.0) for name in g1.locked_joints])
    left, right = sole_pose([0.0, 0.115, 0.0]), sole_pose([0.0, -0.115, 0.0])
    start = ik.reset(left, right, np.zeros(2))
    for k in range(1, 31):  # CoM to the left foot while the right one swings forward
        angles = ik.solve(
            np.array([0.0, 0.1]), left, sole_pose([0.005 * k, -0.115, 0.04]), "left", DT
        )
    assert angles[locked] == pytest.approx(standing, abs=1e-12)
    assert np.max(np.abs(np.delete(angles - start, locked))) > 0.05  # [rad]: the rest moved


def test_ik_rejects_unknown_support(ik):
    with pytest.raises(ParameterError):
        ik.solve(np.zeros(2), np.eye(4), np.eye(4), "none", DT)


TIMING = SwingTiming()


def _swing(target_of_time, landing=None, timing=TIMING):
    trajectory = SwingFootTrajectory(timing, apex_height=0.06)
    trajectory.start(np.array([0.0, -0.1]))
    positions = []
    steps = round((landing or timing.nominal_step) / DT)
    for k in range(1, steps + 1):
        time = k * DT
        positions.append(trajectory.update(time, target_of_time(time), DT, landing))
    return np.array(positions)


def test_swing_foot_reaches_a_moving_target_and_lands_at_the_step_time():
    def target(time):
        return np.array([0.2, -0.1]) if time < 0.4 else np.array([0.25, -0.05])

    positions = _swing(target)
    assert np.allclose(positions[:9, :2], [0.0, -0.1])  # still in double support
    assert positions[:, 2].max() == pytest.approx(0.06, abs=5e-3)
    assert np.linalg.norm(positions[-1, :2] - [0.25, -0.05]) < 1e-3
    assert positions[-1, 2] == pytest.approx(0.0, abs=1e-9)
    speeds = np.linalg.norm(np.diff(positions[:, :2], axis=0), axis=1) / DT
    assert speeds.max() <= 2.0 + 1e-9


def test_swing_foot_lands_early_when_the_planner_plans_an_early_step():
    positions = _swing(lambda _: np.array([0.15, -0.1]), landing=0.4)
    assert np.linalg.norm(positions[-1, :2] - [0.15, -0.1]) < 1e-3
    assert positions[-1, 2] == pytest.approx(0.0, abs=1e-9)


def test_swing_height_profile():
    assert swing_height(0.05, 0.1, 0.8, 0.06) == 0.0
    assert swing_height(0.45, 0.1, 0.8, 0.06) == pytest.approx(0.06)
    assert swing_height(0.8, 0.1, 0.8, 0.06) == pytest.approx(0.0)


def test_the_swing_yaw_leaves_where_the_foot_stood_and_lands_on_the_heading():
    lift_off, landing, start = 0.1, 0.45, 0.2  # [s], [s], [rad]
    times = np.linspace(0.0, 0.6, 61)
    yaws = np.array([swing_yaw(t, lift_off, landing, start, 0.0) for t in times])
    assert np.all(yaws[times <= lift_off] == start)  # still loaded in the double support
    assert np.all(yaws[times >= landing] == 0.0)
    assert np.all(np.diff(yaws) <= 0.0)
    assert np.max(np.abs(np.diff(yaws))) <= start * 0.01 / (landing - lift_off) + 1e-12
    # The shorter way round: from 170 deg to -170 deg through 180 deg.
    half = swing_yaw(0.275, lift_off, landing, np.radians(170.0), np.radians(-170.0))
    assert half == pytest.approx(np.pi)


def test_swing_acceleration_bound_and_descent_funnel():
    """A foothold that jumps 10 cm late in the swing is reached with bounded
    acceleration (re-planning horizon >= sqrt(6 d / a)), and the sole does not come
    down below ``descent_slope`` times the distance still to go."""
    bounded = SwingFootTrajectory(
        TIMING, apex_height=0.06, max_acceleration=20.0, descent_slope=0.5
    )
    free = SwingFootTrajectory(TIMING, apex_height=0.06)
    runs = {}
    for name, trajectory in (("bounded", bounded), ("free", free)):
        trajectory.start(np.array([0.0, -0.1]))
        positions = []
        for k in range(1, round(1.2 / DT) + 1):
            time = k * DT
            target = np.array([0.2, -0.1]) if time < 0.55 else np.array([0.2, 0.0])
            positions.append(trajectory.update(time, target, DT, landing_time=0.6))
        runs[name] = np.array(positions)
    late = round(0.55 / DT)

    def peak_acceleration(positions):
        return np.abs(np.diff(positions[late - 2 :, :2], n=2, axis=0)).max() / DT**2

    assert peak_acceleration(runs["bounded"]) < 0.5 * peak_acceleration(runs["free"])
    to_go = np.linalg.norm(runs["bounded"][late:, :2] - [0.2, 0.0], axis=1)
    heights = runs["bounded"][late:, 2]
    previous = runs["bounded"][late - 1 :, 2][:-1]
    assert np.all(heights >= np.minimum(previous, 0.5 * to_go) - 1e-9)
    assert np.linalg.norm(runs["bounded"][-1, :2] - [0.2, 0.0]) < 1e-3
    assert runs["bounded"][-1, 2] == pytest.approx(0.0, abs=1e-9)


def test_a_bounded_swing_can_still_land_on_time():
    """With the acceleration bound alone a foothold that moves 8 cm 0.15 s before the
    landing is still centimetres away (and the sole up) when the step is due; with
    ``land_on_time`` the sole is over it and on the ground then."""
    landing = 0.5
    at_landing = {}
    for land_on_time in (False, True):
        trajectory = SwingFootTrajectory(
            TIMING, max_acceleration=20.0, descent_slope=0.5, land_on_time=land_on_time
        )
        trajectory.start(np.array([0.0, -0.1]))
        for k in range(1, round(landing / DT) + 1):
            time = k * DT
            target = np.array([0.2, -0.1]) if time < landing - 0.15 else np.array([0.12, 0.0])
            position = trajectory.update(time, target, DT, landing_time=landing)
        at_landing[land_on_time] = (np.linalg.norm(position[:2] - [0.12, 0.0]), position[2])
    distance, height = at_landing[False]
    assert distance > 0.02 and height > 0.01
    distance, height = at_landing[True]
    assert distance < 2e-3 and height == pytest.approx(0.0, abs=2e-3)


def test_swing_bounds_are_validated():
    with pytest.raises(ParameterError, match="max_acceleration"):
        SwingFootTrajectory(TIMING, max_acceleration=0.0)
    with pytest.raises(ParameterError, match="descent_slope"):
        SwingFootTrajectory(TIMING, descent_slope=-1.0)


@pytest.mark.parametrize("robot", ["g1", "talos"])
def test_each_robots_outward_step_bound_is_its_legs_lateral_reach(robot):
    """The planner's widest outward step is the widest flat-footed stance the legs hold
    with the CoM midway (kinematics/reach.py), to within 1 cm below it: a wider bound
    plans double supports the joints cannot stand in, a narrower one gives away reach."""
    description = get_robot(robot)
    reach = lateral_reach(description)
    for bound in (description.step_max[1], -description.step_min[1]):
        assert reach - 0.01 <= bound <= reach, (robot, bound, reach)


def test_g1s_lateral_reach_ends_where_its_ankle_rolls_reach_their_limits():
    """G1's ankle roll joints turn +-15 deg, less than its hips: spread to its reach with
    flat soles, both ankle rolls are at their limits, and 2 cm wider the IK can no longer
    keep the soles where they are asked at the CoM height."""
    description = get_robot("g1")
    reach = lateral_reach(description)
    ik = WholeBodyIK(description)
    width = description.foot_spacing
    ik.reset(*stance(width), np.zeros(2))
    while width < reach - 1e-9:
        width += 0.005
        assert holds(ik, description, width)
    angles = dict(zip(ik.joint_names, ik.joint_angles(), strict=True))
    for side in ("left", "right"):
        assert abs(angles[f"{side}_ankle_roll_joint"]) == pytest.approx(np.radians(15.0), abs=0.01)
    assert not holds(ik, description, reach + 0.02)


def test_lateral_reach_rejects_a_bad_increment():
    with pytest.raises(ParameterError) as caught:
        lateral_reach(get_robot("g1"), increment=0.0)
    assert (caught.value.field, caught.value.value) == ("increment", 0.0)


@pytest.mark.parametrize(
    "robot",
    [
        pytest.param(
            "g1",
            marks=pytest.mark.xfail(
                strict=True,
                reason="the armature's discs spin with their links in the model: h_r 0.111 m",
            ),
        ),
        pytest.param(
            "talos",
            marks=pytest.mark.xfail(
                strict=True,
                reason="the armature's discs spin with their links in the model: h_r 0.129 m",
            ),
        ),
    ],
)
def test_each_robots_pendulum_is_as_tall_as_its_whole_body_motion_makes_it(robot):
    """As the IK sways the CoM over fixed soles, the body's angular momentum follows the
    CoM velocity, L = m h_r H cdot (kinematics/pendulum.py); the description's h_r, which
    makes the planner's LIPM c_z + h_r tall, is within 1 cm of it along x and along y."""
    description = get_robot(robot)
    along_x, along_y = rotational_height(description)
    assert along_x > 0.05 and along_y > 0.05, (along_x, along_y)  # the body does turn
    for measured in (along_x, along_y):
        assert abs(description.rotational_height - measured) <= 0.01, (robot, measured)
    assert description.pendulum_height == description.com_height + description.rotational_height


def _sway_in_a_wide_stance(ik, description, width):
    """Joint angles [rad] of each 10 ms solve while the soles spread from the nominal
    stance to ``width`` [m] in 0.5 s and the CoM then sways 0.6 of the way to a sole
    and back in 1 s (a double support after a wide outward step)."""
    ik.reset(*stance(description.foot_spacing), np.zeros(2))
    solutions = [ik.joint_angles()]
    for i in range(150):
        spread = description.foot_spacing + (width - description.foot_spacing) * min(i / 50, 1.0)
        sway = 0.0 if i < 50 else 0.3 * spread * np.sin(np.pi * (i - 50) / 100)
        solutions.append(ik.solve(np.array([0.0, sway]), *stance(spread), "both", DT))
    return np.array(solutions)


@pytest.mark.parametrize(("robot", "width"), [("g1", 0.55), ("talos", 0.8)])
def test_the_ik_keeps_its_knees_off_the_singularity_in_a_wide_stance(robot, width):
    """In a stance as wide as the outward step bound the legs are nearly straight; with
    the CoM swaying over it, the knees stay bent by KNEE_MARGIN and no joint target moves
    more than 0.15 rad from one 10 ms tick to the next (at a straight knee the QP's step
    flips: up to 1.9 rad per tick on G1 without the margin)."""
    description = get_robot(robot)
    ik = WholeBodyIK(description, upper_body=bool(description.upper_body_joints))
    solutions = _sway_in_a_wide_stance(ik, description, width)
    knees = [ik.joint_names.index(name) for name in leg_joints(ik.robot.model)["knees"]]
    assert solutions[:, knees].min() >= KNEE_MARGIN - 1e-6
    assert np.abs(np.diff(solutions, axis=0)).max() <= 0.15


def test_the_ik_holds_the_joints_the_plan_does_not_move():
    """Talos has no flywheel: its torso, arms and head hold their standing angles (within
    0.1 rad) while the IK sways the CoM over a 0.8 m wide stance, where the legs are near
    their limits (without the hold the arms swing 2.7 rad, up to 4.9 rad in a tick)."""
    description = get_robot("talos")
    ik = WholeBodyIK(description)
    assert {"arm_left_1_joint", "torso_1_joint", "head_1_joint"} <= set(ik.held_joints)
    assert not set(ik.held_joints) & set(leg_joints(ik.robot.model)["chains"])
    solutions = _sway_in_a_wide_stance(ik, description, 0.8)
    standing = ik.standing_posture()
    held = [ik.joint_names.index(name) for name in ik.held_joints]
    posture = np.array([standing[name] for name in ik.held_joints])
    assert np.abs(solutions[:, held] - posture).max() <= 0.1


def test_g1s_flywheel_joints_are_not_held():
    """G1's upper body is its flywheel: with the flywheel every joint the IK may move is
    a leg's or the flywheel's (none is held); without it, the flywheel's joints hold."""
    description = get_robot("g1")
    assert WholeBodyIK(description, upper_body=True).held_joints == []
    assert set(WholeBodyIK(description).held_joints) == set(description.upper_body_joints)


@pytest.mark.parametrize("robot", ["g1", "talos"])
def test_beyond_the_legs_reach_the_ik_gives_the_nearest_stance_without_jumps(robot):
    """Soles spread 1 cm per 10 ms tick from the nominal stance to 15 cm past the legs'
    reach, then held there: the IK (damped as Levenberg-Marquardt's) moves no joint target
    more than 0.25 rad in a tick, settles (the last 10 ticks under 0.02 rad each), and
    leaves each sole no further from its target than the stance is beyond the reach, plus 1
    cm. With the stance soles as hard tasks the QP had no solution 1.5 cm past G1's
    reach; soft but undamped, G1's joint targets jumped by 4.5 rad in a tick."""
    description = get_robot(robot)
    reach = lateral_reach(description)
    ik = WholeBodyIK(description, upper_body=bool(description.upper_body_joints))
    ik.reset(*stance(description.foot_spacing), np.zeros(2))
    solutions = [ik.joint_angles()]
    widest = reach + 0.15
    for i in range(int(round((widest - description.foot_spacing) / 0.01)) + 30):
        width = min(description.foot_spacing + 0.01 * i, widest)
        targets = stance(width)
        solutions.append(ik.solve(np.zeros(2), *targets, "both", DT))
    steps = np.abs(np.diff(np.array(solutions), axis=0)).max(axis=1)
    assert steps.max() <= 0.25, (robot, steps.max())
    assert steps[-10:].max() <= 0.02, (robot, steps[-10:])
    for foot, target in zip(("left", "right"), targets, strict=True):
        error = np.linalg.norm(ik.sole_world(foot)[:3, 3] - target[:3, 3])
        assert error <= (widest - reach) + 0.01, (robot, foot, error)
