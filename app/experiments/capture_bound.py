"""The capture bound of a push from the nominal gait: the yardstick of ``rsg sweep``.

The model and its limits: :mod:`app.experiments.capturability`; the linear programme:
:mod:`app.experiments.capture_lp`; derivation and measurements: ``docs/bound.md``.
"""

from __future__ import annotations

import math

import numpy as np

from app.experiments.capturability import CaptureModel
from app.experiments.capture_lp import PushCase, largest_impulse
from planner.exceptions import ParameterError
from planner.parameters import PlannerConfig
from planner.reference_model import NominalOrbit


def nominal_state(config: PlannerConfig, sigma: int, time_since_step: float) -> np.ndarray:
    """(c - o, cdot) on the nominal orbit, ``time_since_step`` [s] after a step onto
    ``sigma`` [m, m/s], shape (4,)."""
    orbit = NominalOrbit(config.model.omega, config.gait)
    return orbit.state_at(sigma, time_since_step)


def nominal_dcm(config: PlannerConfig, sigma: int, time_since_step: float) -> np.ndarray:
    """DCM relative to the stance ankle on the nominal orbit [m]."""
    state = nominal_state(config, sigma, time_since_step)
    return state[:2] + state[2:] / config.model.omega


def impulse_bound(
    config: PlannerConfig,
    angle: float,
    sigma: int,
    time_since_step: float,
    push_duration: float,
    include_angular_momentum: bool = True,
) -> float:
    """Largest impulse [N s] along ``angle`` [rad] any controller can capture from the
    nominal gait on the LIPM with ``config``'s limits (module docstring).

    Args:
        config: The controller's parameters (mass, window, steps, timing).
        angle: Push direction in the world, 0 = forward (+x), pi/2 = left (+y) [rad].
        sigma: Stance foot at the push start (+1 left, -1 right).
        time_since_step: s~ at the push start [s].
        push_duration: Delta [s].
        include_angular_momentum: Widen the window by hdot_max / (m g).

    Raises:
        ParameterError: A bad push or limit.
    """
    if not (math.isfinite(time_since_step) and time_since_step >= 0.0):
        raise ParameterError("time_since_step", time_since_step, "a finite number >= 0")
    if not (math.isfinite(push_duration) and push_duration > 0.0):
        raise ParameterError("push_duration", push_duration, "a finite number > 0")
    if sigma not in (1, -1):
        raise ParameterError("sigma", sigma, "+1 (left stance) or -1 (right stance)")
    model = CaptureModel.from_config(config, include_angular_momentum)
    state = nominal_state(config, sigma, time_since_step)
    orbit = NominalOrbit(config.model.omega, config.gait)
    case = PushCase(
        com=state[:2],
        velocity=state[2:],
        sigma=sigma,
        time_since_step=time_since_step,
        previous_step=-2.0 * orbit.state_after_step(sigma)[:2],
        direction=np.array([math.cos(angle), math.sin(angle)]),
        duration=push_duration,
    )
    return largest_impulse(model, case).impulse
