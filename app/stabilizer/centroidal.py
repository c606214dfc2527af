"""What the feet must do for the CoM to move as the planner's pendulum.

The planner commands a ZMP p and a rate of angular momentum hdot; on its LIPM
they act together as the pivot (centroidal moment pivot, CMP) r = p - H hdot / (m g),
H = [[0, -1], [1, 0]] of (1), and the CoM accelerates as

    m cdd = m omega^2 (c - r)       (horizontal),      vertical force m g.

The robot's CoM height is not the LIPM's by construction: a touchdown or a foot rolling
on its edge moves it, and the legs then push more or less than m g. The net force holds
the height with a critically damped loop, f_z = m (g + zdd) (the CoM feedback of Hyon,
Hale and Cheng, "Full-body compliant human-humanoid interaction", IEEE T-RO 2007), so
the feet's moments are planned for the force they will carry; its horizontal part keeps
the line from the pivot through the CoM (a pendulum's, f_xy = f_z (c - r) / Z).

On the robot the ground's centre of pressure and the body's own angular momentum
rate Ldot together make the pivot: r = cop - H Ldot / (m g). So the CoP that realises
the planner's pivot while the body moves with Ldot is

    cop = r + H Ldot / (m g),

and it must lie on the support: clipped to the stance sole in single support; in
double support the wrench distribution (:mod:`app.stabilizer.wrench_distribution`)
keeps it in the hull of the two soles. Ldot is that of the whole-body motion the IK
plans (legs and the upper-body flywheel, :mod:`kinematics.upper_body`), so the
flywheel's share of hdot takes load off the CoP. (Popovic, Goswami and Herr, "Ground
reference points in legged locomotion", IJRR 2005, for the CMP.)

Part of Ldot is the body's sway: as the CoM moves over the feet the legs turn and
L = m h_r H cdot (:mod:`kinematics.pendulum`), so Ldot = m h_r H cdd. With that part in
the CoP, the CoM moves as a pendulum c_z + h_r tall about the CoP; the planner's LIPM is
that tall (``RobotDescription.pendulum_height``), so the sway's share is left out of the
CoP (:func:`sway_rate`): a CoP on the sole's edge then stops the CoM as the planner
expects, where a LIPM at c_z would expect more than the robot can do.

What the CoP cannot do (clipped at a sole's edge) the limbs' momentum does to the CoM,
and the planner sees it as a DCM error. The angular momentum about the CoP changes only
by gravity's moment (the ground's force passes through the CoP), so for a CoM at
constant height the velocity

    u = cdot + H^T (L - m h_r H cdot) / (m Z),      d/dt u = omega^2 (c - cop),

moves as the LIPM's whatever the limbs do (L the centroidal angular momentum, Z the
planner's pendulum height): it is the CoM velocity once the limbs' momentum is back in the
CoM. :func:`momentum_velocity`; the planner reads it as its CoM velocity (Orin, Goswami and
Lee, "Centroidal dynamics of a humanoid robot", Auton. Robots 2013, for L).
"""

from __future__ import annotations

import numpy as np
from numpy.typing import NDArray

from planner.hybrid_lipm import H_MATRIX
from planner.parameters import GRAVITY, LipmModel
from robots.description import SoleRectangle


def pivot(
    zmp: NDArray[np.float64], angular_momentum_rate: NDArray[np.float64], mass: float
) -> NDArray[np.float64]:
    """The planner's pivot r = p - H hdot / (m g) [m], shape (2,)."""
    return zmp - H_MATRIX @ angular_momentum_rate / (mass * GRAVITY)


def centre_of_pressure(
    pivot_point: NDArray[np.float64],
    motion_momentum_rate: NDArray[np.float64],
    mass: float,
    stance: NDArray[np.float64],
    sole: SoleRectangle,
    double_support: bool,
) -> NDArray[np.float64]:
    """CoP [m] that realises ``pivot_point`` while the body's angular momentum changes
    at ``motion_momentum_rate`` [N m]; clipped to the stance sole (at ``stance``
    [m], no yaw) in single support."""
    cop = pivot_point + H_MATRIX @ motion_momentum_rate / (mass * GRAVITY)
    if double_support:
        return cop
    low = stance + np.array([sole.x_min, -sole.half_width])
    high = stance + np.array([sole.x_max, sole.half_width])
    return np.minimum(np.maximum(cop, low), high)


def height_acceleration(frequency: float, height_error: float, vertical_velocity: float) -> float:
    """Vertical CoM acceleration [m/s^2] of a critically damped height loop,
    omega_z^2 (z* - z) - 2 omega_z zdot, at ``frequency`` omega_z [rad/s] for the error
    z* - z [m] and the CoM's vertical velocity [m/s]."""
    return frequency**2 * height_error - 2.0 * frequency * vertical_velocity


def contact_force(
    model: LipmModel,
    com: NDArray[np.float64],
    pivot_point: NDArray[np.float64],
    vertical_acceleration: float = 0.0,
) -> NDArray[np.float64]:
    """Net ground force [N], shape (3,): m (g + zdd) upward (never pulling), and along
    the line from the pivot through the CoM, so it adds no moment about the CoM:
    f_xy = f_z (c - r) / Z, the LIPM's m omega^2 (c - r) at zdd = 0."""
    normal = max(model.mass * (model.gravity + vertical_acceleration), 0.0)
    scale = normal / (model.mass * model.gravity)
    horizontal = scale * model.mass * model.omega**2 * (np.asarray(com, float) - pivot_point)
    return np.array([horizontal[0], horizontal[1], normal])


def sway_rate(force: NDArray[np.float64], rotational_height: float) -> NDArray[np.float64]:
    """Angular momentum rate of the body's sway, m h_r H cdd = h_r H f [N m], shape (2,),
    for the net ground ``force`` [N] and h_r ``rotational_height`` [m]."""
    return rotational_height * (H_MATRIX @ np.asarray(force, float)[:2])


def momentum_velocity(
    com_velocity: NDArray[np.float64],
    angular_momentum: NDArray[np.float64],
    mass: float,
    pendulum_height: float,
    rotational_height: float,
) -> NDArray[np.float64]:
    """u = cdot + H^T (L - m h_r H cdot) / (m Z) [m/s], shape (2,): m Z H u is the
    horizontal angular momentum about any point of the ground (module docstring).

    Args:
        com_velocity: Horizontal CoM velocity cdot [m/s], (2,).
        angular_momentum: Horizontal centroidal angular momentum L [N m s], (2,).
        mass: m [kg].
        pendulum_height: Z, the planner's pendulum height [m].
        rotational_height: h_r [m], the sway's share of L per unit m H cdot.
    """
    velocity = np.asarray(com_velocity, float)
    stored = np.asarray(angular_momentum, float) - mass * rotational_height * (H_MATRIX @ velocity)
    return velocity + H_MATRIX.T @ stored / (mass * pendulum_height)
