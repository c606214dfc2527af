"""Contact wrench distribution: the desired CoP and net force shared among the feet.

A small QP (Caron, Kheddar and Tempier, ICRA 2019, Section IV-B; the contact
constraints of Caron, Pham and Nakamura, ICRA 2015) over one 6-D wrench per foot
on the ground, each taken at its sole point (the ground point under the ankle, world
axes): the feet's forces sum to the desired force, their moment about the desired
CoP has no horizontal part, and each wrench stays in its foot's contact wrench cone
(CoP inside the sole rectangle, Coulomb friction pyramid, torsion bounded). The net
force and CoP are soft, with the force weighted far above the CoP, so a CoP outside
the support ends on its nearest edge at the desired force. A small cost on the ankle
torques makes the split between two feet unique (each CoP as close to its ankle as
the balance allows).

Each foot's wrench then has its ankle's roll and pitch torques within the joints'
effort limits (the torque limits of a whole-body QP, e.g. Koolen et al., "Design of a
momentum-based control framework and application to the humanoid robot Atlas", IJHR
2016): a sole's CoP is only as far from its ankle as the ankle can push, about
tau_max / f_z, and a CoP beyond is moved towards the ankle with the force kept. The
moments are taken about the ankle in the sole's axes, those of a flat foot's ankle
joints. (As rows of the QP the limits led proxqp to declare feasible cases infeasible.)

The controller then bounds each foot's moments by the normal force the foot is measured
to carry (:func:`within_sole_at_force`): the feed-forward asks no ankle for a CoP off its
sole when its foot carries less than planned.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import RsgError
from planner.qp import solve_polished
from robots.description import SoleRectangle

# The QP is solved for wrenches divided by the desired normal force (well conditioned);
# the weights are per unit of that force, moments per metre of CoP offset.
FORCE_WEIGHT = 1.0  # on the net force error [-]
MOMENT_WEIGHT = 1e-2  # on the horizontal moment about the desired CoP [1/m^2]
ANKLE_WEIGHT = 1e-4  # on each foot's ankle torque [1/m^2] (breaks ties)
# (regularisation on every wrench coordinate, proxqp's eps_abs): the second if the first stalls
ATTEMPTS = ((1e-8, 1e-8), (1e-6, 1e-7))


@dataclass(frozen=True)
class FootContact:
    """A foot on the ground, as the distribution sees it.

    Attributes:
        sole_point: Ground point under the ankle [m], shape (3,).
        yaw: Heading of the sole about the vertical [rad].
        ankle_height: Height of the ankle above the sole [m].
        min_force: Lower bound on the foot's normal force [N] (a foot being unloaded).
        max_force: Upper bound on the foot's normal force [N] (a foot being loaded).
    """

    sole_point: NDArray[np.float64]
    yaw: float
    ankle_height: float
    min_force: float = 0.0
    max_force: float = np.inf


@dataclass(frozen=True)
class ContactLimits:
    """Contact model shared by the feet.

    Attributes:
        sole: Sole rectangle around the ankle [m].
        friction: Coulomb friction coefficient [-] (pyramid, inner approximation).
        torsion_arm: Torsion bound per newton of normal force [m].
        min_force: Smallest normal force of a foot in contact [N].
        ankle_torque: Bounds on the ankle's roll and pitch torques [N m] (the joints'
            effort limits; inf: none).
    """

    sole: SoleRectangle
    friction: float = 0.7
    torsion_arm: float = 0.01
    min_force: float = 0.0
    ankle_torque: tuple[float, float] = (np.inf, np.inf)


class WrenchDistributionError(RsgError):
    """The QP had no solution.

    Attributes:
        feet: Number of feet in the problem.
        force: The desired net force [N].
        cop: The desired CoP [m].
    """

    def __init__(self, feet: int, force: NDArray[np.float64], cop: NDArray[np.float64]) -> None:
        super().__init__(
            f"wrench distribution over {feet} foot contact(s) found no solution "
            f"(force {np.round(force, 1)} N, CoP {np.round(cop, 3)} m)"
        )
        self.feet, self.force, self.cop = feet, force, cop

    def __reduce__(self) -> tuple[Any, ...]:
        # Rebuilt from its data, so it crosses process boundaries (sweep and grid workers).
        return (type(self), (self.feet, self.force, self.cop))


def _skew(v: NDArray[np.float64]) -> NDArray[np.float64]:
    return np.array([[0.0, -v[2], v[1]], [v[2], 0.0, -v[0]], [-v[1], v[0], 0.0]])


def _yaw_matrix(yaw: float) -> NDArray[np.float64]:
    c, s = np.cos(yaw), np.sin(yaw)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def _cone(limits: ContactLimits, contact: FootContact) -> tuple[NDArray, NDArray]:
    """Rows (G, h) with G w <= h for one foot's wrench w = (f, m) at its sole point."""
    rotation = _yaw_matrix(contact.yaw)
    mu, sole = limits.friction, limits.sole
    # In the sole frame: f' = R^T f, m' = R^T m; the CoP is (-m'_y, m'_x) / f_z.
    rows_local = [
        # friction pyramid |f'_x|, |f'_y| <= mu f_z
        ([1.0, 0.0, -mu], [0.0, 0.0, 0.0]),
        ([-1.0, 0.0, -mu], [0.0, 0.0, 0.0]),
        ([0.0, 1.0, -mu], [0.0, 0.0, 0.0]),
        ([0.0, -1.0, -mu], [0.0, 0.0, 0.0]),
        # CoP x in [x_min, x_max]: x_min f_z <= -m'_y <= x_max f_z
        ([0.0, 0.0, -sole.x_max], [0.0, -1.0, 0.0]),
        ([0.0, 0.0, sole.x_min], [0.0, 1.0, 0.0]),
        # CoP y in [-Y, Y]: -Y f_z <= m'_x <= Y f_z
        ([0.0, 0.0, -sole.half_width], [1.0, 0.0, 0.0]),
        ([0.0, 0.0, -sole.half_width], [-1.0, 0.0, 0.0]),
        # torsion |m'_z| <= arm f_z
        ([0.0, 0.0, -limits.torsion_arm], [0.0, 0.0, 1.0]),
        ([0.0, 0.0, -limits.torsion_arm], [0.0, 0.0, -1.0]),
    ]
    G = np.array([np.concatenate([f @ rotation.T, m @ rotation.T]) for f, m in rows_local])
    h = np.zeros(len(rows_local))
    bounds = [(np.array([0, 0, -1.0, 0, 0, 0]), -max(limits.min_force, contact.min_force))]
    if np.isfinite(contact.max_force):
        bounds.append((np.array([0, 0, 1.0, 0, 0, 0]), contact.max_force))
    G = np.vstack([G, *[row for row, _ in bounds]])
    h = np.concatenate([h, [value for _, value in bounds]])
    return G, h


def distribute_wrench(
    contacts: Sequence[FootContact],
    force: NDArray[np.float64],
    cop: NDArray[np.float64],
    limits: ContactLimits,
) -> list[NDArray[np.float64]]:
    """Wrenches (f, m) [N, N m] at each foot's sole point, world axes, shape (6,) each.

    Args:
        contacts: The feet on the ground (one or two).
        force: Desired net contact force [N], shape (3,).
        cop: Desired centre of pressure on the ground [m], shape (2,).
        limits: Friction and sole.

    Raises:
        WrenchDistributionError: The QP has no solution (it always has one while
            ``min_force`` is below every ``max_force``).
    """
    if len(contacts) == 1:
        return [
            _single_support(contacts[0], np.asarray(force, float), np.asarray(cop, float), limits)
        ]
    count = len(contacts)
    size = 6 * count
    scale = max(float(force[2]), 1.0)  # [N]
    target = np.array([cop[0], cop[1], 0.0])
    # Net force rows and horizontal moment about the desired CoP.
    A_force = np.hstack([np.hstack([np.eye(3), np.zeros((3, 3))]) for _ in contacts])
    A_moment = np.hstack([np.hstack([_skew(c.sole_point - target), np.eye(3)]) for c in contacts])
    A_moment = A_moment[:2]
    P = FORCE_WEIGHT * A_force.T @ A_force + MOMENT_WEIGHT * A_moment.T @ A_moment
    q = -FORCE_WEIGHT * A_force.T @ (np.asarray(force, float) / scale)
    for index, contact in enumerate(contacts):
        # Ankle torque: m + (sole point - ankle) x f = m - (h e_z) x f.
        ankle = np.hstack([-_skew(np.array([0.0, 0.0, contact.ankle_height])), np.eye(3)])[:2]
        block = slice(6 * index, 6 * index + 6)
        P[block, block] += ANKLE_WEIGHT * ankle.T @ ankle
    cones = [_cone(limits, contact) for contact in contacts]
    G = np.zeros((sum(len(h) for _, h in cones), size))
    h = np.concatenate([h for _, h in cones]) / scale
    row = 0
    for index, (G_foot, h_foot) in enumerate(cones):
        G[row : row + len(h_foot), 6 * index : 6 * index + 6] = G_foot
        row += len(h_foot)
    for regularisation, eps_abs in ATTEMPTS:
        solution = solve_polished(P + regularisation * np.eye(size), q, G, h, eps_abs=eps_abs)
        if solution is not None:
            break
    if solution is None:
        raise WrenchDistributionError(count, np.asarray(force, float), np.asarray(cop, float))
    return [
        _within_ankle_reach(contact, scale * solution[6 * i : 6 * i + 6], limits)
        for i, contact in enumerate(contacts)
    ]


def _single_support(
    contact: FootContact,
    force: NDArray[np.float64],
    cop: NDArray[np.float64],
    limits: ContactLimits,
) -> NDArray[np.float64]:
    """The QP's solution for one foot in closed form: the force within the friction
    pyramid, the CoP clipped to the sole (then to the ankle's reach), no torsion."""
    rotation = _yaw_matrix(contact.yaw)
    normal = float(np.clip(force[2], max(limits.min_force, contact.min_force), contact.max_force))
    local_force = rotation.T @ force
    bound = limits.friction * normal
    local_force = np.array([*np.clip(local_force[:2], -bound, bound), normal])
    offset = rotation.T @ np.array([cop[0], cop[1], 0.0]) - rotation.T @ contact.sole_point
    sole = limits.sole
    x = float(np.clip(offset[0], sole.x_min, sole.x_max))
    y = float(np.clip(offset[1], -sole.half_width, sole.half_width))
    local_moment = np.array([y * normal, -x * normal, 0.0])
    wrench = np.concatenate([rotation @ local_force, rotation @ local_moment])
    return _within_ankle_reach(contact, wrench, limits)


def _within_ankle_reach(
    contact: FootContact, wrench: NDArray[np.float64], limits: ContactLimits
) -> NDArray[np.float64]:
    """``wrench`` with its CoP moved towards the ankle, its force kept, until the ankle's
    roll and pitch torques are within ``limits.ankle_torque``."""
    rotation = _yaw_matrix(contact.yaw)
    force, moment = rotation.T @ wrench[:3], rotation.T @ wrench[3:]
    if not force[2] > 0.0:
        return wrench
    roll, pitch = limits.ankle_torque
    arm = contact.ankle_height
    # tau' = m' - h e_z x f' = (m'_x + h f'_y, m'_y - h f'_x); the CoP is (-m'_y, m'_x) / f'_z
    x_force = float(np.clip(-moment[1], -pitch - arm * force[0], pitch - arm * force[0]))
    y_force = float(np.clip(moment[0], -roll - arm * force[1], roll - arm * force[1]))
    if x_force == -moment[1] and y_force == moment[0]:  # (the CoP's x and y times f'_z)
        return wrench
    local_moment = np.array([y_force, -x_force, moment[2]])
    return np.concatenate([wrench[:3], rotation @ local_moment])


def within_sole_at_force(
    contact: FootContact, wrench: NDArray[np.float64], normal_force: float, sole: SoleRectangle
) -> NDArray[np.float64]:
    """``wrench`` with its roll and pitch moments bounded so that its CoP under
    ``normal_force`` [N], the force the foot carries, lies on ``sole``; its force kept.

    A foot's ankle pushes its CoP no further than the sole's edge whatever force it is
    planned for: a moment beyond what the carried force holds there turns the foot about
    that edge (the foot-rotation indicator of Goswami, "Postural stability of biped
    robots and the foot-rotation indicator (FRI) point", IJRR 1999).
    """
    rotation = _yaw_matrix(contact.yaw)
    moment = rotation.T @ wrench[3:]
    force = max(float(normal_force), 0.0)
    x_force = float(np.clip(-moment[1], sole.x_min * force, sole.x_max * force))
    y_force = float(np.clip(moment[0], -sole.half_width * force, sole.half_width * force))
    local_moment = np.array([y_force, -x_force, moment[2]])
    return np.concatenate([wrench[:3], rotation @ local_moment])


def center_of_pressure(
    contacts: Sequence[FootContact], wrenches: Sequence[NDArray[np.float64]]
) -> NDArray[np.float64]:
    """CoP [m] of the wrenches (f, m) taken at the contacts' sole points, shape (2,)."""
    force = np.sum([w[:3] for w in wrenches], axis=0)
    moment = np.sum(
        [w[3:] + np.cross(c.sole_point, w[:3]) for c, w in zip(contacts, wrenches, strict=True)],
        axis=0,
    )
    return np.array([-moment[1], moment[0]]) / force[2]
