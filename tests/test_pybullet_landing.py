"""Landing correction (app/pybullet_landing.py) and the G1 planner settings it goes with."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from app.pybullet_landing import LandingCorrection
from app.robot_setup import planner_config_for
from planner.exceptions import ParameterError
from planner.types import Foothold, PlannerOutput, StepEvent
from robots import get_robot


def output(stance: Foothold, previous: Foothold, next_step: Foothold, step: bool) -> PlannerOutput:
    zero = np.zeros(2)
    event = StepEvent(0.0, stance.foot, stance.position, False, False) if step else None
    return PlannerOutput(
        time=0.0,
        zmp=stance.position,
        zmp_offset=zero,
        window_center=stance.position,
        angular_momentum_rate=zero,
        angular_momentum_rate_feedback=zero,
        stance=stance,
        previous_stance=previous,
        next_step=next_step,
        next_step_time=0.8,
        time_since_step=0.0,
        double_support=step,
        dcm_error=zero,
        lyapunov=0.0,
        lyapunov_at_step=0.0,
        com_reference=stance.position,
        step=event,
    )


def test_the_jumps_offset_is_learned_in_the_foot_frame_and_applied_to_both_feet():
    landing = LandingCorrection(1.0)
    left = Foothold("left", np.array([0.0, 0.1]))
    announced = Foothold("right", np.array([0.1, -0.1]))
    # Before any jump the announcement is the target.
    before = output(left, announced, announced, step=False)
    landing.observe(before)
    assert np.allclose(landing.target(before), announced.position)
    # The planner jumps 4.5 mm further forward and 7 mm further outward (right).
    right = Foothold("right", np.array([0.1045, -0.107]))
    next_left = Foothold("left", np.array([0.2, 0.1]))
    after = output(right, left, next_left, step=True)
    landing.observe(after)
    assert np.allclose(landing.correction, [0.0045, 0.007])
    # The left foot is aimed forward and outward (+y) by as much.
    assert np.allclose(landing.target(after), [0.2045, 0.107])
    landing.reset()
    assert np.allclose(landing.target(after), next_left.position)


def test_landing_correction_gain_zero_is_off_and_the_gain_is_validated():
    landing = LandingCorrection(0.0)
    left = Foothold("left", np.array([0.0, 0.1]))
    right = Foothold("right", np.array([0.1, -0.1]))
    landing.observe(output(left, right, right, step=False))
    landing.observe(output(Foothold("right", np.array([0.2, -0.2])), left, left, step=True))
    assert np.array_equal(landing.correction, np.zeros(2))
    with pytest.raises(ParameterError):
        LandingCorrection(1.5)
    with pytest.raises(ParameterError):
        LandingCorrection((1.0, -0.1))


def test_robot_filter_time_constant_reaches_the_planner():
    g1 = get_robot("g1")
    assert planner_config_for(g1, 33.3).rsg.filter_time_constant == g1.filter_time_constant
    other = dataclasses.replace(g1, filter_time_constant=0.03)
    assert planner_config_for(other, 33.3).rsg.filter_time_constant == 0.03
