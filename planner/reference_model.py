"""Synchronized reference model (13), (14).

The reference xi* = (xi1*, xi2*) flows freely with A (13a), the ZMP at the ankle,
and jumps with the nominal input u_d* = 2 xi1* (13b), i.e. xi1*+ = -xi1*, at the
same moments as the hybrid LIPM. Both flows and jumps conserve the orbital energy
E(w, wdot) = wdot^2/2 - omega^2 w^2/2 in x and y, so the reference always lies on the
nominal gait's energy level, time-shifted when a push has moved the step times.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .hybrid_lipm import flow_autonomous, orbital_energy
from .parameters import GaitParameters


@dataclass(frozen=True)
class NominalOrbit:
    """The nominal LIPM gait (3) of period T^* with the ZMP at the ankle.

    Attributes:
        omega: sqrt(g / c_z) [1/s].
        gait: Nominal gait.
    """

    omega: float
    gait: GaitParameters

    def state_after_step(self, sigma: int) -> np.ndarray:
        """xi* just after a nominal step onto the foot ``sigma``.

        The CoM is half a stride behind the new ankle and on the side of the other
        foot, moving forward and towards the new stance foot.
        """
        w, period = self.omega, self.gait.step_duration
        half_stride, half_width = self.gait.stride_length / 2, self.gait.step_width / 2
        vx = w * half_stride / math.tanh(w * period / 2)
        vy = w * half_width * math.tanh(w * period / 2)
        return np.array([-half_stride, -sigma * half_width, vx, sigma * vy])

    def state_at(self, sigma: int, time_since_step: float) -> np.ndarray:
        """xi* a time [s] after a nominal step onto ``sigma``."""
        return flow_autonomous(self.omega, self.state_after_step(sigma), time_since_step)

    def energies(self) -> tuple[float, float]:
        """Nominal orbital energies (E_x^*, E_y^*) [m^2/s^2]."""
        xi = self.state_after_step(1)
        return (
            orbital_energy(self.omega, xi[0], xi[2]),
            orbital_energy(self.omega, xi[1], xi[3]),
        )


class ReferenceModel:
    """State xi_bar* of the synchronized reference model (13).

    Args:
        orbit: The nominal gait it mimics.
        sigma: Stance foot at the start (+1 left, -1 right).
        time_since_step: Where on the nominal orbit it starts [s]; this makes the
            initial orbital energy equal to the nominal one in x and in y.
    """

    def __init__(self, orbit: NominalOrbit, sigma: int, time_since_step: float = 0.0) -> None:
        self.orbit = orbit
        self.state = orbit.state_at(sigma, time_since_step)

    @property
    def xi1(self) -> np.ndarray:
        """xi1* = c* - o* [m]."""
        return self.state[:2]

    @property
    def xi2(self) -> np.ndarray:
        """xi2* = cdot* [m/s]."""
        return self.state[2:]

    def dcm(self) -> np.ndarray:
        """Reference DCM relative to the stance ankle, xi1* + xi2*/omega [m]."""
        return self.xi1 + self.xi2 / self.orbit.omega

    def flow(self, duration: float) -> None:
        """(13a) over ``duration`` [s]."""
        self.state = flow_autonomous(self.orbit.omega, self.state, duration)

    def nominal_step(self) -> np.ndarray:
        """u_d*(xi*) = 2 xi1* [m]."""
        return 2.0 * self.xi1

    def jump(self) -> None:
        """(13b): xi1*+ = xi1* - u_d* = -xi1*."""
        self.state = np.concatenate([-self.xi1, self.xi2])

    def in_nominal_jump_set(self) -> bool:
        """D_S of (14): sign(xi2y*) xi1y* >= L_y^* / 2."""
        # The orbit reaches D_S on a tick; rounding must not push the jump a tick later.
        return bool(np.sign(self.state[3]) * self.state[1] >= self.orbit.gait.step_width / 2 - 1e-9)

    def energies(self) -> tuple[float, float]:
        """Current orbital energies (E_x, E_y) [m^2/s^2]."""
        w, s = self.orbit.omega, self.state
        return orbital_energy(w, s[0], s[2]), orbital_energy(w, s[1], s[3])

    def time_to_nominal_jump(self) -> float:
        """Time [s] until the reference enters D_S when flowing freely (inf if never)."""
        w, half_width = self.orbit.omega, self.orbit.gait.step_width / 2
        y, vy = self.state[1], self.state[3]
        if np.sign(vy) * y >= half_width:
            return 0.0
        # y(t) = a e^{wt} + b e^{-wt}; solve sign(vy) y(t) = half_width for t > 0.
        a, b = 0.5 * (y + vy / w), 0.5 * (y - vy / w)
        for target in (half_width, -half_width):
            if abs(a) < 1e-15:
                continue
            # a z^2 - target z + b = 0 with z = e^{wt} > 1.
            disc = target**2 - 4 * a * b
            if disc < 0:
                continue
            roots = [(target + s * math.sqrt(disc)) / (2 * a) for s in (1.0, -1.0)]
            times = [math.log(z) / w for z in roots if z > 1.0]
            for t in sorted(times):
                vel = w * (a * math.exp(w * t) - b * math.exp(-w * t))
                if np.sign(vel) * target >= half_width - 1e-12:
                    return t
        return math.inf
