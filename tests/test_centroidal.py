"""The pivot, the CoP and the net force that make the CoM move as the planner's LIPM
(:mod:`app.stabilizer.centroidal`), checked by moment balance about the CoM."""

from __future__ import annotations

import numpy as np
import pytest

from app.stabilizer.centroidal import (
    centre_of_pressure,
    contact_force,
    height_acceleration,
    momentum_velocity,
    pivot,
    sway_rate,
)
from planner.hybrid_lipm import H_MATRIX
from planner.parameters import GRAVITY, LipmModel
from robots import get_robot

MODEL = LipmModel(mass=33.3, com_height=0.66)
SOLE = get_robot("g1").sole
RNG_SEED = 22


def cases(count: int = 50):
    """Random CoM [m], ZMP [m] and angular momentum rate [N m] (seeded)."""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(count):
        com = rng.uniform(-0.1, 0.1, 2)
        yield com, com + rng.uniform(-0.05, 0.05, 2), rng.uniform(-5.0, 5.0, 2)


def moment_about_com(point, com, force):
    """Horizontal moment [N m] about the CoM (at c_z) of ``force`` acting at ground ``point``."""
    arm = np.array([point[0] - com[0], point[1] - com[1], -MODEL.com_height])
    return np.cross(arm, force)[:2]


def test_the_planners_zmp_and_hdot_give_the_pivot_where_the_force_line_meets_the_ground():
    """r = p - H hdot / (m g): the net force m omega^2 (c - r), m g passes through the
    CoM and r, and applied at the ZMP p it turns the body at hdot (the CMP, Popovic,
    Goswami and Herr 2005)."""
    for com, zmp, rate in cases():
        r = pivot(zmp, rate, MODEL.mass)
        force = contact_force(MODEL, com, r)
        np.testing.assert_allclose(moment_about_com(r, com, force), 0.0, atol=1e-9)
        np.testing.assert_allclose(moment_about_com(zmp, com, force), rate, atol=1e-9)


def test_without_angular_momentum_rate_the_cop_is_the_pivot():
    for _, zmp, _ in cases(10):
        r = pivot(zmp, np.zeros(2), MODEL.mass)
        np.testing.assert_array_equal(r, zmp)
        for double_support in (True, False):
            cop = centre_of_pressure(r, np.zeros(2), MODEL.mass, zmp, SOLE, double_support)
            np.testing.assert_allclose(cop, r, atol=1e-12)


def test_the_cop_moves_by_h_ldot_over_m_g_so_the_ground_turns_the_body_at_its_ldot():
    """cop = r + H Ldot / (m g): the ground force at the CoP accelerates the CoM as the
    pivot says and changes the body's angular momentum at the motion's Ldot."""
    for com, zmp, rate in cases():
        r = pivot(zmp, rate, MODEL.mass)
        motion_rate = -rate[::-1]  # any Ldot
        cop = centre_of_pressure(r, motion_rate, MODEL.mass, np.zeros(2), SOLE, True)
        force = contact_force(MODEL, com, r)
        np.testing.assert_allclose(moment_about_com(cop, com, force), motion_rate, atol=1e-9)
        shift = np.linalg.norm(cop - r)
        assert shift == pytest.approx(np.linalg.norm(motion_rate) / (MODEL.mass * GRAVITY))


def test_with_the_sway_left_out_of_the_cop_the_com_moves_as_a_pendulum_c_z_plus_h_r_tall():
    """A body at c_z whose angular momentum follows its CoM velocity, L = m h_r H cdot,
    plus any other motion's Ldot: the CoP for the pivot of a LIPM c_z + h_r tall, with
    the sway's m h_r H cdd left out of it (the other Ldot kept), balances the moments
    about the CoM with the body's whole Ldot, and the CoM accelerates as that taller
    pendulum about the pivot."""
    h_r = 0.1
    tall = LipmModel(mass=MODEL.mass, com_height=MODEL.com_height + h_r)
    for com, zmp, rate in cases():
        r = pivot(zmp, rate, MODEL.mass)
        force = contact_force(tall, com, r)
        other = -rate[::-1]  # any Ldot of the rest of the motion
        cdd = force[:2] / MODEL.mass
        body_rate = MODEL.mass * h_r * np.array([-cdd[1], cdd[0]])  # d/dt of m h_r H cdot
        np.testing.assert_allclose(sway_rate(force, h_r), body_rate)
        cop = centre_of_pressure(r, other, MODEL.mass, np.zeros(2), SOLE, True)
        np.testing.assert_allclose(moment_about_com(cop, com, force), body_rate + other, atol=1e-9)
        np.testing.assert_allclose(force[:2], tall.mass * tall.omega**2 * (com - r))


def test_the_net_force_is_the_lipms():
    """m cdd = m omega^2 (c - r) horizontally and m g vertically."""
    for com, zmp, rate in cases():
        r = pivot(zmp, rate, MODEL.mass)
        force = contact_force(MODEL, com, r)
        np.testing.assert_allclose(force[:2] / MODEL.mass, MODEL.omega**2 * (com - r))
        assert force[2] == pytest.approx(MODEL.mass * GRAVITY)


def test_with_a_vertical_acceleration_the_force_line_still_passes_through_the_com():
    """f_z = m (g + zdd), never pulling, and f_xy = f_z (c - r) / Z: the pivot stays where
    the force line meets the ground (no moment about the CoM), and applied at the ZMP the
    force turns the body at hdot f_z / (m g)."""
    for zdd in (-3.0, -0.5, 0.5, 4.0):
        for com, zmp, rate in cases(20):
            r = pivot(zmp, rate, MODEL.mass)
            force = contact_force(MODEL, com, r, zdd)
            assert force[2] == pytest.approx(MODEL.mass * (GRAVITY + zdd))
            np.testing.assert_allclose(force[:2] / force[2], (com - r) / MODEL.com_height)
            np.testing.assert_allclose(moment_about_com(r, com, force), 0.0, atol=1e-9)
            turning = rate * force[2] / (MODEL.mass * GRAVITY)
            np.testing.assert_allclose(moment_about_com(zmp, com, force), turning, atol=1e-9)
    np.testing.assert_array_equal(contact_force(MODEL, np.ones(2), np.zeros(2), -2 * GRAVITY), 0.0)


def test_the_height_loop_brings_a_bounced_com_back_without_overshoot():
    """zdd = omega_z^2 (z* - z) - 2 omega_z zdot is critically damped: a CoM launched
    upward at 0.4 m/s (a touchdown's bounce) returns to its height without crossing it,
    and within 1 mm after 7 / omega_z."""
    frequency, dt = 10.0, 1e-4
    error, velocity, lowest = 0.0, 0.4, 0.0  # z - z* [m], zdot [m/s]
    for _ in range(round(0.7 / dt)):
        velocity += height_acceleration(frequency, -error, velocity) * dt
        error += velocity * dt
        lowest = min(lowest, error)
    assert lowest > -1e-4 and abs(error) < 1e-3
    assert height_acceleration(frequency, 0.01, 0.0) == pytest.approx(1.0)  # omega_z^2 per m


def test_in_single_support_the_cop_is_clipped_to_the_stance_sole():
    """The nearest point of the sole rectangle around the stance foothold; inside, the
    CoP is kept; in double support it is not clipped (the wrench distribution keeps
    it in the support)."""
    stance = np.array([0.3, -0.1])
    low = stance + np.array([SOLE.x_min, -SOLE.half_width])
    high = stance + np.array([SOLE.x_max, SOLE.half_width])
    rng = np.random.default_rng(RNG_SEED)
    # The sole as a grid of points 0.5 mm apart, for a brute-force nearest point.
    xs = np.linspace(low[0], high[0], 341)
    ys = np.linspace(low[1], high[1], 101)
    grid = np.stack(np.meshgrid(xs, ys), axis=-1).reshape(-1, 2)
    clipped = 0
    for wanted in rng.uniform(-0.3, 0.3, (200, 2)) + stance:
        cop = centre_of_pressure(wanted, np.zeros(2), MODEL.mass, stance, SOLE, False)
        assert np.all(cop >= low - 1e-12) and np.all(cop <= high + 1e-12)
        nearest = grid[np.argmin(np.linalg.norm(grid - wanted, axis=1))]
        assert np.linalg.norm(cop - wanted) <= np.linalg.norm(nearest - wanted) + 1e-12
        if np.any(wanted < low) or np.any(wanted > high):
            clipped += 1
        else:
            np.testing.assert_array_equal(cop, wanted)
        double = centre_of_pressure(wanted, np.zeros(2), MODEL.mass, stance, SOLE, True)
        np.testing.assert_array_equal(double, wanted)
    assert clipped > 100


def point_masses(rng, count=12):
    """Random point masses [kg], positions [m] (CoM at MODEL.com_height) and velocities
    [m/s] (no vertical CoM velocity): a robot whose limbs move any way."""
    masses = rng.uniform(0.5, 5.0, count)
    positions = rng.uniform(-0.4, 0.4, (count, 3))
    velocities = rng.uniform(-1.0, 1.0, (count, 3))
    positions += np.array([0.0, 0.0, MODEL.com_height]) - masses @ positions / masses.sum()
    velocities[:, 2] -= masses @ velocities[:, 2] / masses.sum()
    return masses, positions, velocities


def test_the_momentum_velocity_is_the_angular_momentum_about_any_ground_point():
    """m Z H u = L_p, the horizontal angular momentum about any point p of the ground,
    whatever h_r: gravity is the only external force with a moment about the CoP, so u
    changes at omega^2 (c - cop) whatever the limbs do."""
    rng = np.random.default_rng(RNG_SEED)
    for _ in range(20):
        masses, positions, velocities = point_masses(rng)
        mass = masses.sum()
        com = masses @ positions / mass
        com_velocity = masses @ velocities / mass

        def momentum_about(point, masses=masses, positions=positions, velocities=velocities):
            arms = positions - point
            return np.sum(np.cross(arms, masses[:, None] * velocities), axis=0)[:2]

        h_r = rng.uniform(0.0, 0.2)
        pendulum = MODEL.com_height + h_r
        u = momentum_velocity(com_velocity[:2], momentum_about(com), mass, pendulum, h_r)
        ground = np.array([*rng.uniform(-1.0, 1.0, 2), 0.0])
        np.testing.assert_allclose(
            mass * pendulum * H_MATRIX @ u, momentum_about(ground), atol=1e-9
        )


def test_a_body_that_only_sways_has_its_com_velocity_as_momentum_velocity():
    """L = m h_r H cdot, the share the pendulum's height holds: u = cdot."""
    rng = np.random.default_rng(RNG_SEED)
    h_r = 0.1
    for com_velocity in rng.uniform(-1.0, 1.0, (10, 2)):
        sway = MODEL.mass * h_r * H_MATRIX @ com_velocity
        u = momentum_velocity(com_velocity, sway, MODEL.mass, MODEL.com_height + h_r, h_r)
        np.testing.assert_allclose(u, com_velocity, atol=1e-12)
