"""The CoM filter on the LIPM (app.stabilizer.lipm_filter): against an exact pendulum whose
CoM is off the kinematic one, with the kinematic CoM measured with noise."""

from __future__ import annotations

import numpy as np
import pytest

from app.stabilizer.lipm_filter import LipmFilter
from planner.exceptions import ParameterError
from planner.hybrid_lipm import integrate_lipm
from planner.parameters import LipmModel

MODEL = LipmModel(mass=33.0, com_height=0.6)
PERIOD = 0.01  # [s] the controller's tick
POSITION_NOISE = 0.003  # [m]
VELOCITY_NOISE = 0.05  # [m/s]
TRUE_OFFSET = np.array([0.02, -0.015])  # [m] true CoM minus kinematic CoM


def balance(
    drift: float, push_force: np.ndarray | None = None, seconds: float = 10.0, seed: int = 0
):
    """A capture-point feedback balancing the true pendulum on the filter's estimate; a
    push of ``push_force`` [N] over 0.1 s at 5 s. Returns (estimates, truths, offsets) per
    tick: the filter's CoM and velocity, the true ones, the filter's offset."""
    rng = np.random.default_rng(seed)
    flt = LipmFilter(MODEL.omega, 1.0, POSITION_NOISE, VELOCITY_NOISE, drift)
    com, velocity = np.zeros(2), np.zeros(2)
    estimate = flt.update(com - TRUE_OFFSET, velocity, com, 0.0)
    estimates, truths, offsets = [], [], []
    for tick in range(round(seconds / PERIOD)):
        pivot = estimate[0] + 1.5 * estimate[1] / MODEL.omega
        force = np.zeros(2)
        if push_force is not None and 500 <= tick < 510:
            force = push_force
        com, velocity = integrate_lipm(MODEL, com, velocity, pivot, np.zeros(2), force, PERIOD)
        estimate = flt.update(
            com - TRUE_OFFSET + rng.normal(0.0, POSITION_NOISE, 2),
            velocity + rng.normal(0.0, VELOCITY_NOISE, 2),
            pivot,
            PERIOD,
        )
        estimates.append(np.concatenate(estimate))
        truths.append(np.concatenate([com, velocity]))
        offsets.append(flt.offset)
    return np.array(estimates), np.array(truths), np.array(offsets)


def test_offset_is_learnt_and_the_com_estimate_loses_its_bias():
    estimates, truths, offsets = balance(drift=0.005)
    # learnt within 3 s, to 3 mm
    np.testing.assert_allclose(offsets[300:].mean(axis=0), TRUE_OFFSET, atol=0.003)
    error = estimates[300:] - truths[300:]
    assert np.all(np.abs(error[:, :2].mean(axis=0)) < 0.003)  # no bias left in the CoM
    assert np.all(np.sqrt((error[:, 2:] ** 2).mean(axis=0)) < 0.6 * VELOCITY_NOISE)


def test_without_drift_no_offset_and_the_bias_stays():
    estimates, truths, offsets = balance(drift=0.0)
    assert not offsets.any()
    bias = (estimates[300:, :2] - truths[300:, :2]).mean(axis=0)
    np.testing.assert_allclose(bias, -TRUE_OFFSET, atol=0.005)  # what the offset removes


def test_a_push_moves_the_offset_a_little_and_it_comes_back():
    push = np.array([100.0, 0.0])  # [N] over 0.1 s: 10 N s, 0.3 m/s on 33 kg
    _, _, offsets = balance(drift=0.005, push_force=push)
    moved = np.abs(offsets[500:600, 0] - TRUE_OFFSET[0]).max()
    assert moved < 0.02  # against a DCM jump of 0.3 m/s / omega = 7.5 cm
    np.testing.assert_allclose(offsets[900:, 0].mean(), TRUE_OFFSET[0], atol=0.004)


@pytest.mark.parametrize(
    ("name", "kwargs"),
    [
        ("omega", {"omega": 0.0}),
        ("process_noise", {"process_noise": float("nan")}),
        ("position_noise", {"position_noise": -1.0}),
        ("offset_drift", {"offset_drift": -0.1}),
        ("max_offset", {"max_offset": 0.0}),
    ],
)
def test_bad_parameters_are_refused_by_name(name, kwargs):
    arguments = {
        "omega": 4.0,
        "process_noise": 1.0,
        "position_noise": 0.003,
        "velocity_noise": 0.05,
    } | kwargs
    with pytest.raises(ParameterError, match=name):
        LipmFilter(**arguments)
