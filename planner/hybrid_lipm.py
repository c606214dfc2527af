"""Hybrid LIPM (4), (9)-(11) in the coordinates xi = (c_H - o_H, cdot_H).

The continuous input is u_c = (p~_H, hdot_H) (10): the ZMP offset from the window
centre r_H [m] and the rate of change of angular momentum [N m]; the perturbation is
Delta_c = (r~_H, f_H) with r~_H = r_H - o_H [m] and the push force f_H [N]. A step
is the jump xi_1^+ = xi_1 - u_d, sigma^+ = -sigma (11).
"""

from __future__ import annotations

import math

import numpy as np

from .parameters import LipmModel

# H of (1): maps hdot to its effect on the CoM, [[0, -1], [1, 0]].
H_MATRIX = np.array([[0.0, -1.0], [1.0, 0.0]])
H_INVERSE = H_MATRIX.T


def flow_matrices(model: LipmModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A, B, E of the flow map (11), for xi in R^4, u_c in R^4, Delta_c in R^4.

    Returns:
        A (4x4), B (4x4), E (4x4).
    """
    w2 = model.omega**2
    eye, zero = np.eye(2), np.zeros((2, 2))
    a = np.block([[zero, eye], [w2 * eye, zero]])
    b = np.block([[zero, zero], [-w2 * eye, H_MATRIX / (model.mass * model.com_height)]])
    e = np.block([[zero, zero], [-w2 * eye, eye / model.mass]])
    return a, b, e


def jump_matrix() -> np.ndarray:
    """F of the jump map (11): xi^+ = xi + F u_d."""
    return np.block([[-np.eye(2), np.zeros((2, 2))], [np.zeros((2, 2)), np.zeros((2, 2))]])


def effective_zmp(
    model: LipmModel, zmp: np.ndarray, angular_momentum_rate: np.ndarray, force: np.ndarray
) -> np.ndarray:
    """The point p_eff such that (1) reads cddot = omega^2 (c - p_eff) [m]."""
    return (
        np.asarray(zmp, dtype=float)
        - H_MATRIX @ np.asarray(angular_momentum_rate, dtype=float) / (model.mass * model.gravity)
        - np.asarray(force, dtype=float) * model.com_height / (model.mass * model.gravity)
    )


def integrate_lipm(
    model: LipmModel,
    com_position: np.ndarray,
    com_velocity: np.ndarray,
    zmp: np.ndarray,
    angular_momentum_rate: np.ndarray,
    force: np.ndarray,
    duration: float,
) -> tuple[np.ndarray, np.ndarray]:
    """Exact solution of (1) over ``duration`` [s] with constant inputs.

    Args:
        model: The LIPM.
        com_position: c_H at the start [m].
        com_velocity: cdot_H at the start [m/s].
        zmp: Constant ZMP p_H [m].
        angular_momentum_rate: Constant hdot_H [N m].
        force: Constant push force f_H [N].
        duration: Integration time [s].

    Returns:
        (c_H, cdot_H) at the end.
    """
    w = model.omega
    p_eff = effective_zmp(model, zmp, angular_momentum_rate, force)
    ch, sh = math.cosh(w * duration), math.sinh(w * duration)
    offset = np.asarray(com_position, dtype=float) - p_eff
    velocity = np.asarray(com_velocity, dtype=float)
    return p_eff + offset * ch + velocity * sh / w, offset * w * sh + velocity * ch


def flow_autonomous(omega: float, xi: np.ndarray, duration: float) -> np.ndarray:
    """exp(A t) xi for the free flow xi_dot = A xi (13a), xi = (xi1, xi2) in R^4."""
    ch, sh = math.cosh(omega * duration), math.sinh(omega * duration)
    xi1, xi2 = xi[:2], xi[2:]
    return np.concatenate([xi1 * ch + xi2 * sh / omega, xi1 * omega * sh + xi2 * ch])


def orbital_energy(omega: float, position: float, velocity: float) -> float:
    """Orbital energy E(w, wdot) = wdot^2 / 2 - omega^2 w^2 / 2 [m^2/s^2]."""
    return 0.5 * velocity**2 - 0.5 * omega**2 * position**2


def dcm(omega: float, xi: np.ndarray) -> np.ndarray:
    """xi_u = xi1 + xi2 / omega, the DCM relative to the stance ankle [m]."""
    return xi[:2] + xi[2:] / omega
