"""Synchronized reference model (13), (14): energy, period, jump prediction."""

import numpy as np
import pytest

from planner.parameters import GaitParameters, LipmModel
from planner.reference_model import NominalOrbit, ReferenceModel

MODEL = LipmModel()
ORBIT = NominalOrbit(MODEL.omega, GaitParameters())


def test_nominal_orbit_reaches_its_jump_after_one_period():
    ref = ReferenceModel(ORBIT, sigma=1)
    assert not ref.in_nominal_jump_set()
    assert ref.time_to_nominal_jump() == pytest.approx(ORBIT.gait.step_duration, abs=1e-9)
    ref.flow(ORBIT.gait.step_duration)
    gait = ORBIT.gait
    # Left stance: the CoM ends half a stride ahead, on the right of the left foot,
    # and the right foot steps one stride forward and one step width to the right.
    np.testing.assert_allclose(ref.xi1, [gait.stride_length / 2, -gait.step_width / 2], atol=1e-9)
    np.testing.assert_allclose(
        ref.nominal_step(), [gait.stride_length, -gait.step_width], atol=1e-9
    )
    ref.jump()
    np.testing.assert_allclose(ref.state, ORBIT.state_after_step(-1), atol=1e-9)


@pytest.mark.parametrize("seed", range(4))
def test_energy_conserved_across_flows_and_early_jumps(seed):
    """Flows (13a) and jumps (13b) at arbitrary times keep E_x = E_x*, E_y = E_y*."""
    rng = np.random.default_rng(seed)
    nominal = ORBIT.energies()
    ref = ReferenceModel(ORBIT, sigma=1, time_since_step=rng.uniform(0, 0.8))
    for _ in range(12):
        ref.flow(rng.uniform(0.05, 0.8))
        np.testing.assert_allclose(ref.energies(), nominal, rtol=1e-9, atol=1e-12)
        ref.jump()
        np.testing.assert_allclose(ref.energies(), nominal, rtol=1e-9, atol=1e-12)


def test_time_to_nominal_jump_matches_simulation():
    ref = ReferenceModel(ORBIT, sigma=-1, time_since_step=0.2)
    ref.flow(0.1)
    ref.jump()  # an early jump: the reference is time-shifted
    predicted = ref.time_to_nominal_jump()
    dt, elapsed = 1e-4, 0.0
    while not ref.in_nominal_jump_set():
        ref.flow(dt)
        elapsed += dt
    assert elapsed == pytest.approx(predicted, abs=2 * dt)


@pytest.mark.parametrize("period", [0.001, 0.01])
def test_the_step_comes_at_the_tick_one_period_after_the_last(period):
    """Flowed in control ticks that divide T^*, the reference enters D_S at the tick
    of each nominal step time, not a tick later, cycle after cycle."""
    ref = ReferenceModel(ORBIT, sigma=1)
    ticks = round(ORBIT.gait.step_duration / period)
    for _ in range(3):
        for _ in range(ticks - 1):
            ref.flow(period)
            assert not ref.in_nominal_jump_set()
        ref.flow(period)
        assert ref.in_nominal_jump_set()
        ref.jump()
