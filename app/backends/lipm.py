"""The LIPM backend: the point-mass model (1) integrated exactly.

Within a control period the ZMP, the rate of change of angular momentum and the
push force are constant, so (1) has a closed-form solution
(:func:`planner.hybrid_lipm.integrate_lipm`); the loop passes the push force
averaged over the period, so the impulse of a push is exact.

Fall: the model has no knee to buckle, so a fall is declared when the CoM is more
than ``fall_distance`` from the stance ankle (the leg could not reach), or when the
DCM error exceeds ``fall_dcm_error``.
"""

from __future__ import annotations

import numpy as np

from app.backends.base import FallStatus, InitialCondition
from planner.hybrid_lipm import integrate_lipm
from planner.parameters import LipmModel
from planner.types import MeasuredState, PlannerOutput, Vector2

CONTROL_PERIOD = 0.001  # [s] the loop's tick on the point mass (1 kHz)
LEG_REACH = 0.6  # [m] CoM to stance-ankle distance beyond which the LIPM counts a fall


class LipmBackend:
    """Closed-form LIPM (1) with the planner's ZMP and angular momentum.

    Args:
        model: The LIPM (mass, CoM height).
        control_period: Duration of one step [s].
        fall_distance: CoM to stance-ankle distance that counts as a fall [m].
        fall_dcm_error: DCM error norm that counts as a fall [m].
    """

    name = "lipm"

    def __init__(
        self,
        model: LipmModel,
        control_period: float = CONTROL_PERIOD,
        fall_distance: float = LEG_REACH,
        fall_dcm_error: float = 0.5,
    ) -> None:
        self.model = model
        self.mass = model.mass
        self.com_height = model.com_height
        self.control_period = control_period
        self.fall_distance = fall_distance
        self.fall_dcm_error = fall_dcm_error
        self.time = 0.0
        self.com_position = np.zeros(2)
        self.com_velocity = np.zeros(2)
        self._fall = FallStatus(False)

    def reset(self, initial: InitialCondition) -> MeasuredState:
        self.time = 0.0
        self.com_position = np.asarray(initial.com_position, dtype=float).copy()
        self.com_velocity = np.asarray(initial.com_velocity, dtype=float).copy()
        self._fall = FallStatus(False)
        return self._measure()

    def step(self, command: PlannerOutput, push_force: Vector2) -> MeasuredState:
        self.com_position, self.com_velocity = integrate_lipm(
            self.model,
            self.com_position,
            self.com_velocity,
            command.zmp,
            command.angular_momentum_rate,
            push_force,
            self.control_period,
        )
        self.time += self.control_period
        if not self._fall.fell:
            distance = float(np.linalg.norm(self.com_position - command.stance.position))
            if distance > self.fall_distance:
                self._fall = FallStatus(
                    True, f"CoM {distance:.2f} m from the stance ankle (> {self.fall_distance} m)"
                )
            elif float(np.linalg.norm(command.dcm_error)) > self.fall_dcm_error:
                self._fall = FallStatus(
                    True,
                    f"DCM error {np.linalg.norm(command.dcm_error):.2f} m "
                    f"(> {self.fall_dcm_error} m)",
                )
        return self._measure()

    def fall_status(self) -> FallStatus:
        return self._fall

    def close(self) -> None:
        pass

    def _measure(self) -> MeasuredState:
        return MeasuredState(self.time, self.com_position.copy(), self.com_velocity.copy())
