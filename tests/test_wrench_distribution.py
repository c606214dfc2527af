"""The contact wrench distribution (:mod:`app.stabilizer.wrench_distribution`): every
foot's wrench in its contact wrench cone, the net force and CoP as asked when they
can be, the nearest point of the support when they cannot."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from scipy.spatial import ConvexHull

from app.setup.robot_config import planner_config_for
from app.stabilizer.wrench_distribution import (
    ContactLimits,
    FootContact,
    WrenchDistributionError,
    center_of_pressure,
    distribute_wrench,
    within_sole_at_force,
)
from kinematics.robot_model import RobotModel
from planner.parameters import GRAVITY
from robots import get_robot

SOLE = get_robot("g1").sole
LIMITS = ContactLimits(SOLE, friction=0.7, torsion_arm=0.01)
ANKLE_HEIGHT = 0.035  # [m] G1's ankle above its sole
WEIGHT = 33.3 * 9.81  # [N]
CONE_TOLERANCE = 1e-4  # [-, of the normal force] on each cone row
# [m] The split between two feet also pays for ankle torque (a tie-breaker weighted
# 1e-2 of the CoP's): the CoP is off by up to 0.63 mm (median 0.17 mm) over 300
# random feasible cases of two feet; exact with one.
COP_TOLERANCE = 0.001


def rotation(yaw):
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def corners(contact):
    """The sole rectangle's corners on the ground [m], shape (4, 2)."""
    local = [
        (SOLE.x_min, -SOLE.half_width),
        (SOLE.x_max, -SOLE.half_width),
        (SOLE.x_max, SOLE.half_width),
        (SOLE.x_min, SOLE.half_width),
    ]
    turn = rotation(contact.yaw)[:2, :2]
    return np.array([contact.sole_point[:2] + turn @ np.array(c) for c in local])


def cone_violation(contact, wrench, limits=LIMITS):
    """Largest violation of ``contact``'s wrench cone by ``wrench`` (f, m) at its sole
    point, world axes: [N] for the force rows, [N m] for the moment rows."""
    turn = rotation(contact.yaw)
    force, moment = turn.T @ wrench[:3], turn.T @ wrench[3:]
    normal = force[2]
    cop_x, cop_y = -moment[1], moment[0]  # times the normal force
    return max(
        abs(force[0]) - limits.friction * normal,
        abs(force[1]) - limits.friction * normal,
        cop_x - SOLE.x_max * normal,
        SOLE.x_min * normal - cop_x,
        abs(cop_y) - SOLE.half_width * normal,
        abs(moment[2]) - limits.torsion_arm * normal,
        max(limits.min_force, contact.min_force) - normal,
        normal - contact.max_force,
    )


def nearest_point_of_support(contacts, point):
    """Nearest point [m] of the convex hull of the soles to ``point`` (brute force
    over the hull's edges; ``point`` itself when inside)."""
    points = np.vstack([corners(c) for c in contacts])
    hull = ConvexHull(points)
    if np.all(hull.equations[:, :2] @ point + hull.equations[:, 2] <= 1e-12):
        return point
    best, best_distance = None, np.inf
    for a, b in hull.simplices:
        p, q = points[a], points[b]
        t = np.clip((point - p) @ (q - p) / ((q - p) @ (q - p)), 0.0, 1.0)
        candidate = p + t * (q - p)
        if np.linalg.norm(candidate - point) < best_distance:
            best, best_distance = candidate, np.linalg.norm(candidate - point)
    return best


def random_feet(rng, count):
    """One foot, or two feet side by side (G1's stance, a step ahead or behind), yawed."""
    if count == 1:
        position = rng.uniform(-0.2, 0.2, 2)
        return [FootContact(np.array([*position, 0.0]), rng.uniform(-0.5, 0.5), ANKLE_HEIGHT)]
    centre = rng.uniform(-0.2, 0.2, 2)
    heading = rng.uniform(-0.5, 0.5)
    stride = rng.uniform(-0.25, 0.25)
    width = rng.uniform(0.18, 0.3)
    offsets = [np.array([stride / 2, width / 2]), np.array([-stride / 2, -width / 2])]
    turn = rotation(heading)[:2, :2]
    return [
        FootContact(
            np.array([*(centre + turn @ offset), 0.0]),
            heading + rng.uniform(-0.3, 0.3),
            ANKLE_HEIGHT,
        )
        for offset in offsets
    ]


def feasible_case(rng, contacts):
    """A net force within the friction pyramid of every foot and a CoP inside the
    support (a random point of the hull, pulled towards its centre)."""
    points = np.vstack([corners(c) for c in contacts])
    weights = rng.dirichlet(np.ones(len(points)))
    centre = points.mean(axis=0)
    cop = centre + 0.9 * (weights @ points - centre)
    normal = WEIGHT * rng.uniform(0.5, 1.5)
    # |f_t| <= mu f_z / sqrt(2) fits the pyramid of a foot of any yaw.
    tangential = rng.uniform(-1.0, 1.0, 2) * 0.6 * LIMITS.friction * normal / np.sqrt(2)
    return np.array([*tangential, normal]), cop


def net(contacts, wrenches):
    return np.sum(wrenches, axis=0)[:3], center_of_pressure(contacts, wrenches)


@pytest.mark.parametrize("count", [1, 2])
def test_feasible_cases_get_their_force_and_cop_within_every_foots_cone(count):
    rng = np.random.default_rng(22 + count)
    for case in range(100):
        contacts = random_feet(rng, count)
        force, cop = feasible_case(rng, contacts)
        wrenches = distribute_wrench(contacts, force, cop, LIMITS)
        for contact, wrench in zip(contacts, wrenches, strict=True):
            assert cone_violation(contact, wrench) < CONE_TOLERANCE * force[2], f"{case=}"
        total, realised = net(contacts, wrenches)
        np.testing.assert_allclose(total, force, atol=CONE_TOLERANCE * force[2], err_msg=f"{case=}")
        np.testing.assert_allclose(realised, cop, atol=COP_TOLERANCE, err_msg=f"{case=}")


def test_a_cop_outside_the_two_soles_ends_on_the_nearest_edge_with_the_force_kept():
    """The force is weighted far above the CoP: for a CoP 1-10 cm outside the support
    the weight is carried (measured: within 0.01 %; the CoP's cost pulls it down by
    about 1e-2 d^2 for a CoP d metres out) and the CoP goes to the nearest point of
    the hull of the soles (checked against a brute force over the hull's edges; within
    1.3 mm over 1000 such cases, median 0.07 mm: the ankle-torque tie-breaker)."""
    rng = np.random.default_rng(7)
    cases = 0
    while cases < 60:
        contacts = random_feet(rng, 2)
        force, _ = feasible_case(rng, contacts)
        centre = np.mean([c.sole_point[:2] for c in contacts], axis=0)
        direction = rng.normal(size=2)
        wanted = centre + rng.uniform(0.05, 0.3) * direction / np.linalg.norm(direction)
        nearest = nearest_point_of_support(contacts, wanted)
        if not 0.01 <= np.linalg.norm(nearest - wanted) <= 0.1:
            continue
        cases += 1
        wrenches = distribute_wrench(contacts, force, wanted, LIMITS)
        for contact, wrench in zip(contacts, wrenches, strict=True):
            assert cone_violation(contact, wrench) < CONE_TOLERANCE * force[2], f"{cases=}"
        total, realised = net(contacts, wrenches)
        np.testing.assert_allclose(total, force, atol=1e-3 * force[2], err_msg=f"{cases=}")
        assert np.linalg.norm(realised - nearest) < 0.002, f"{realised=} {nearest=}"


def test_without_force_bounds_every_case_has_a_solution():
    """No wrench at all satisfies every cone, so the QP is never infeasible: whatever
    the CoP and force asked for (the planned CoP is not clipped in double support),
    the distribution returns wrenches in the cones rather than an error."""
    rng = np.random.default_rng(13)
    failures = []
    for case in range(1000):
        contacts = random_feet(rng, 2)
        force, _ = feasible_case(rng, contacts)
        centre = np.mean([c.sole_point[:2] for c in contacts], axis=0)
        wanted = centre + rng.uniform(-0.35, 0.35, 2)
        try:
            wrenches = distribute_wrench(contacts, force, wanted, LIMITS)
        except WrenchDistributionError:
            failures.append(case)
            continue
        for contact, wrench in zip(contacts, wrenches, strict=True):
            assert cone_violation(contact, wrench) < CONE_TOLERANCE * force[2], f"{case=}"
    assert failures == [], f"{len(failures)} of 1000 cases raised"


def test_a_feasible_case_its_solver_once_called_infeasible_is_solved():
    """A CoP on the support that proxqp (eps_abs 1e-8) declared primal infeasible."""
    contacts = [
        FootContact(np.array([-0.0243, 0.1705, 0.0]), 0.2038, ANKLE_HEIGHT),
        FootContact(np.array([0.0906, -0.0316, 0.0]), -0.1415, ANKLE_HEIGHT),
    ]
    force, cop = np.array([-58.4, -45.9, 386.3]), np.array([0.177, -0.06])
    wrenches = distribute_wrench(contacts, force, cop, LIMITS)
    for contact, wrench in zip(contacts, wrenches, strict=True):
        assert cone_violation(contact, wrench) < CONE_TOLERANCE * force[2]
    total, realised = net(contacts, wrenches)
    np.testing.assert_allclose(total, force, atol=1e-3 * force[2])
    assert np.linalg.norm(realised - nearest_point_of_support(contacts, cop)) < COP_TOLERANCE


def test_crossed_feet_and_a_cop_far_away_get_wrenches_within_the_ankles_limits():
    """Two crossed feet of a falling G1 and a CoP 0.7 m away (with the ankle limits as rows
    of the QP, proxqp declared this case infeasible)."""
    limits = dataclasses.replace(LIMITS, ankle_torque=(35.0, 35.0))
    contacts = [
        FootContact(np.array([0.5529622457083501, -0.4649455043525553, 0.0]), 0.5828, 0.035),
        FootContact(np.array([0.5960208338052637, -0.5227239554504023, 0.0]), 0.1904, 0.035),
    ]
    force = np.array([11.470704274717866, 4.634481819489441, 328.3572132777546])
    cop = np.array([0.42409512634901336, 0.2530349862429677])
    wrenches = distribute_wrench(contacts, force, cop, limits)
    for contact, wrench in zip(contacts, wrenches, strict=True):
        assert cone_violation(contact, wrench, limits) < CONE_TOLERANCE * force[2]
        assert np.all(np.abs(ankle_torque(contact, wrench)) <= 35.0 + 1e-3)
    # the CoP's cost, 0.7 m off, takes 0.5 % off the force (as without the ankle rows)
    np.testing.assert_allclose(np.sum(wrenches, axis=0)[:3], force, atol=0.01 * force[2])


def test_in_single_support_a_cop_outside_the_sole_is_clipped_onto_it():
    """The closed form: the CoP the nearest point of the (yawed) sole, the force kept
    where the friction pyramid allows and clipped to it where not, no torsion."""
    rng = np.random.default_rng(11)
    for case in range(100):
        (contact,) = random_feet(rng, 1)
        force = np.array([*rng.uniform(-1.0, 1.0, 2) * 1.2 * LIMITS.friction * WEIGHT, WEIGHT])
        wanted = contact.sole_point[:2] + rng.uniform(-0.3, 0.3, 2)
        (wrench,) = distribute_wrench([contact], force, wanted, LIMITS)
        assert cone_violation(contact, wrench) < CONE_TOLERANCE * WEIGHT, f"{case=}"
        realised = center_of_pressure([contact], [wrench])
        nearest = nearest_point_of_support([contact], wanted)
        np.testing.assert_allclose(realised, nearest, atol=1e-9, err_msg=f"{case=}")
        local = rotation(contact.yaw).T @ force
        kept = np.abs(local[:2]) <= LIMITS.friction * WEIGHT
        local_result = rotation(contact.yaw).T @ wrench[:3]
        np.testing.assert_allclose(local_result[:2][kept], local[:2][kept], atol=1e-9)
        assert wrench[5] == pytest.approx(0.0, abs=1e-9)


def test_force_bounds_of_a_foot_being_unloaded_or_loaded_hold():
    """A foot bounded to at most 20 % of the weight (being loaded) and the other to at
    least 30 % (being unloaded): the bounds hold, the rest is as asked."""
    rng = np.random.default_rng(5)
    for case in range(50):
        free = random_feet(rng, 2)
        contacts = [
            FootContact(free[0].sole_point, free[0].yaw, ANKLE_HEIGHT, max_force=0.2 * WEIGHT),
            FootContact(free[1].sole_point, free[1].yaw, ANKLE_HEIGHT, min_force=0.3 * WEIGHT),
        ]
        force = np.array([0.0, 0.0, WEIGHT])
        cop = free[0].sole_point[:2]  # asks for the whole weight on the bounded foot
        wrenches = distribute_wrench(contacts, force, cop, LIMITS)
        for contact, wrench in zip(contacts, wrenches, strict=True):
            assert cone_violation(contact, wrench) < CONE_TOLERANCE * WEIGHT, f"{case=}"
        assert wrenches[0][2] == pytest.approx(0.2 * WEIGHT, rel=1e-3)
        np.testing.assert_allclose(net(contacts, wrenches)[0], force, atol=1e-3 * WEIGHT)


def test_bounds_that_cannot_hold_together_are_an_error_with_its_data():
    rng = np.random.default_rng(3)
    free = random_feet(rng, 2)
    contacts = [
        FootContact(free[0].sole_point, free[0].yaw, ANKLE_HEIGHT, min_force=0.8 * WEIGHT),
        FootContact(free[1].sole_point, free[1].yaw, ANKLE_HEIGHT, max_force=0.1 * WEIGHT),
    ]
    contacts[0] = FootContact(
        contacts[0].sole_point, contacts[0].yaw, ANKLE_HEIGHT, min_force=0.8 * WEIGHT,
        max_force=0.5 * WEIGHT,
    )  # fmt: skip
    force, cop = np.array([0.0, 0.0, WEIGHT]), np.zeros(2)
    with pytest.raises(WrenchDistributionError) as error:
        distribute_wrench(contacts, force, cop, LIMITS)
    assert error.value.feet == 2
    np.testing.assert_array_equal(error.value.force, force)


def ankle_torque(contact, wrench):
    """The ankle's roll and pitch torques [N m] of ``wrench`` (f, m) at the sole point,
    in the sole's axes: the moment about the ankle, ``ankle_height`` above it."""
    turn = rotation(contact.yaw)
    force, moment = turn.T @ wrench[:3], turn.T @ wrench[3:]
    return (moment - np.cross([0.0, 0.0, contact.ankle_height], force))[:2]


@pytest.mark.parametrize("count", [1, 2])
def test_no_ankle_is_given_more_torque_than_its_effort_limit(count):
    """G1's ankles push with 35 N m, which under its weight holds the CoP about 10 cm from
    the ankle; the sole reaches 12 cm. Asked for the CoP at a toe, every foot's ankle
    torques stay within the limit, the force is the one asked, and in single support the
    CoP is as far forward as the ankle allows (without the limit the toe needs ~40 N m)."""
    limited = dataclasses.replace(LIMITS, ankle_torque=(35.0, 35.0))
    rng = np.random.default_rng(5)
    for case in range(50):
        contacts = random_feet(rng, count)
        front = contacts[0]
        toe = front.sole_point[:2] + rotation(front.yaw)[:2, :2] @ np.array([SOLE.x_max, 0.0])
        force = np.array([*rng.uniform(-0.1, 0.1, 2) * WEIGHT, WEIGHT * rng.uniform(1.0, 1.3)])
        wrenches = distribute_wrench(contacts, force, toe, limited)
        for contact, wrench in zip(contacts, wrenches, strict=True):
            assert np.all(np.abs(ankle_torque(contact, wrench)) <= 35.0 + 1e-3), f"{case=}"
            assert cone_violation(contact, wrench) < CONE_TOLERANCE * WEIGHT, f"{case=}"
        np.testing.assert_allclose(np.sum(wrenches, axis=0)[:3], force, atol=1e-3 * WEIGHT)
        if count == 1:
            (free,) = distribute_wrench(contacts, force, toe, LIMITS)
            assert abs(ankle_torque(front, free)[1]) > 36.0, f"{case=}"
            assert abs(ankle_torque(front, wrenches[0])[1]) == pytest.approx(35.0, abs=1e-6)


@pytest.mark.parametrize("robot", ["g1", "talos"])
def test_every_zmp_of_the_planners_window_is_a_cop_the_stance_ankle_holds(robot):
    """Under the robot's weight, a ZMP at any corner of the planner's window is the CoP
    the single support's wrench gets: the ankles' effort limits do not move it inwards
    (G1's ankles, 35 N m, hold the CoP 0.107 m ahead of the ankle; its sole reaches 0.12)."""
    description = get_robot(robot)
    constraints = planner_config_for(description, description.total_mass).constraints
    limits = ContactLimits(
        description.sole, ankle_torque=RobotModel(description).ankle_effort_limits()
    )
    contact = FootContact(np.zeros(3), 0.0, -description.sole_offset[2])
    weight = np.array([0.0, 0.0, description.total_mass * GRAVITY])
    low, high = constraints.zmp_window_min, constraints.zmp_window_max
    for corner in [(x, y) for x in (low[0], high[0]) for y in (low[1], high[1])]:
        wrench = distribute_wrench([contact], weight, np.array(corner), limits)[0]
        np.testing.assert_allclose(center_of_pressure([contact], [wrench]), corner, atol=1e-9)


@pytest.mark.parametrize("yaw", [0.0, 0.6])
def test_a_foot_carrying_less_than_planned_keeps_its_cop_on_the_sole(yaw):
    """A single-support wrench planned for m g with its CoP 0.1 m ahead of the ankle and
    0.02 m inward: on a foot carrying a third of that, its CoP at the carried force, which
    would be 0.3 m ahead and 0.06 m inward, ends on the sole's front and inner edges; the
    force and the torsion are kept. Carried in full, the wrench is unchanged; carried not
    at all, it has no roll or pitch moment."""
    contact = FootContact(np.array([0.3, -0.1, 0.0]), yaw, ANKLE_HEIGHT)
    R = rotation(yaw)
    offset = np.array([0.1, 0.02, 0.0])
    wrench = distribute_wrench(
        [contact],
        np.array([10.0, -5.0, WEIGHT]),
        contact.sole_point[:2] + (R @ offset)[:2],
        dataclasses.replace(LIMITS, ankle_torque=(np.inf, np.inf)),
    )[0]
    assert np.allclose(wrench[:3], [10.0, -5.0, WEIGHT])

    carried = WEIGHT / 3.0
    bounded = within_sole_at_force(contact, wrench, carried, SOLE)
    np.testing.assert_allclose(bounded[:3], wrench[:3])
    local = R.T @ bounded[3:]
    cop = np.array([-local[1], local[0]]) / carried  # in the sole's frame, at the carried force
    assert cop[0] == pytest.approx(SOLE.x_max)
    assert cop[1] == pytest.approx(SOLE.half_width)
    assert local[2] == pytest.approx((R.T @ wrench[3:])[2])

    np.testing.assert_allclose(within_sole_at_force(contact, wrench, WEIGHT, SOLE), wrench)
    unloaded = R.T @ within_sole_at_force(contact, wrench, 0.0, SOLE)[3:]
    np.testing.assert_allclose(unloaded[:2], 0.0, atol=1e-12)
