"""Ankle CoP feedback: the stance ankle moves the measured CoP onto the planned one.

The CoM plan (:mod:`app.pybullet_com_plan`) assumes a CoP p_d on the stance sole;
joint position control realises it only approximately. In single support the ankle
torque sets the CoP: a torque tau on the sole moves it by (tau_y, -tau_x) / f_z.
A position-controlled ankle whose target is offset by delta about its world axis a
presses the sole by a torque along +a, so the offset that moves the CoP by e
(= p_d - p_measured) grows as

    d(delta)/dt = K_x a_y e_x - K_y a_x e_y        (per ankle joint)

with gains K [rad / (m s)] per axis, a leak back to zero with time constant
``leak`` (the offsets stay small and vanish in double support, where the split of
the load between the feet is not planned) and a bound ``limit``. It is the foot
damping of Kajita et al. (2010) and Caron et al. (2019) written for position
control.

Measured on G1 (``rsg run --scenario walk``), lateral gain 2 rad/(m s), no forward
gain: the lateral CoP error in single support drops from 0.71 cm rms to 0.40 cm,
and the walk no longer drifts: 180 s with no adjusted step and V_u at most 0.46
gamma_v, where it fell at 46 s before (the slow lateral CoP bias had carried the
DCM out of the +-2 cm window). A lateral gain of 5 halves the error again but
raises V_u at landings to 1.2 gamma_v; a forward gain of 2 raised the forward
error from 1.27 to 1.83 cm rms (the forward CoP moves with the swing leg faster
than the ankle loop can follow), so the forward gain is 0.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np
from numpy.typing import NDArray

from planner.exceptions import ParameterError

MIN_LOAD_FRACTION = 0.3  # the loop acts when the stance foot carries this much of m g [-]


class AnkleCopFeedback:
    """Offsets of the two ankle joints of each foot, driven by the CoP error.

    Attributes:
        gain: (K_x, K_y) [rad / (m s)].
        leak: Time constant of the offsets' return to zero [s].
        limit: Bound on each offset [rad].
        offsets: Foot -> offsets [rad] of its ankle joints (in the order of the axes
            given to :meth:`update`), shape (2,).
    """

    def __init__(
        self,
        gain: float | tuple[float, float] = 0.0,
        leak: float = 0.3,
        limit: float = 0.15,
    ) -> None:
        gains = np.broadcast_to(np.asarray(gain, float), (2,)).copy()
        if not (np.all(np.isfinite(gains)) and np.all(gains >= 0.0)):
            raise ParameterError("cop_feedback", gain, "gains >= 0 rad/(m s), per axis (x, y)")
        if not (leak > 0.0 and 0.0 < limit <= 0.5):
            raise ParameterError(
                "cop_feedback_leak/limit", (leak, limit), "leak > 0 s and limit in (0, 0.5] rad"
            )
        self.gain = gains
        self.leak = leak
        self.limit = limit
        self.offsets = {"left": np.zeros(2), "right": np.zeros(2)}

    @property
    def enabled(self) -> bool:
        """Whether any gain is non-zero."""
        return bool(np.any(self.gain > 0.0))

    def reset(self) -> None:
        """Zero offsets."""
        for offset in self.offsets.values():
            offset[:] = 0.0

    def update(
        self,
        dt: float,
        stance: str,
        single_support: bool,
        planned_cop: NDArray[np.float64],
        measured: tuple[NDArray[np.float64], float] | None,
        joint_axes: Sequence[NDArray[np.float64]],
        weight: float,
    ) -> dict[str, NDArray[np.float64]]:
        """Advance the offsets by one control period.

        Args:
            dt: Control period [s].
            stance: The stance foot.
            single_support: Whether the robot is in single support on ``stance``.
            planned_cop: CoP of the CoM plan [m], shape (2,).
            measured: (CoP [m], normal force [N]) of the stance foot, None if it
                does not touch the ground.
            joint_axes: World axes (3,) of the stance foot's ankle joints.
            weight: Robot weight m g [N].

        Returns:
            The offsets per foot [rad] (the same arrays as :attr:`offsets`).
        """
        decay = max(0.0, 1.0 - dt / self.leak)
        for offset in self.offsets.values():
            offset *= decay
        if single_support and measured is not None and measured[1] > MIN_LOAD_FRACTION * weight:
            error = self.gain * (np.asarray(planned_cop, float) - measured[0])
            offset = self.offsets[stance]
            for k, axis in enumerate(joint_axes):
                offset[k] += dt * (axis[1] * error[0] - axis[0] * error[1])
            np.clip(offset, -self.limit, self.limit, out=offset)
        return self.offsets
