"""Ankle CoP feedback: signs from the statics of a flat foot, leak, bound, errors."""

from __future__ import annotations

import numpy as np
import pytest

from app.pybullet_ankle import AnkleCopFeedback
from planner.exceptions import ParameterError

ROLL_AXIS = np.array([1.0, 0.0, 0.0])  # world axes of a flat foot's ankle joints
PITCH_AXIS = np.array([0.0, 1.0, 0.0])
WEIGHT = 330.0  # [N]
DT = 0.01  # [s]


def cop_shift(axis: np.ndarray, offset: float) -> np.ndarray:
    """Direction in which a torque of sign ``offset`` about ``axis`` on the sole moves
    the CoP: the ground's moment f_z (r_y, -r_x) balances the ankle torque."""
    torque = offset * axis
    return np.array([torque[1], -torque[0]])


def step(feedback: AnkleCopFeedback, planned, measured, single_support=True, load=WEIGHT):
    return feedback.update(
        DT,
        "left",
        single_support,
        np.asarray(planned, float),
        (np.asarray(measured, float), load),
        [ROLL_AXIS, PITCH_AXIS],
        WEIGHT,
    )


@pytest.mark.parametrize("error", [(0.03, 0.0), (-0.02, 0.0), (0.0, 0.01), (0.0, -0.015)])
def test_the_offsets_press_the_sole_toward_the_planned_cop(error):
    feedback = AnkleCopFeedback(gain=(2.0, 2.0))
    offsets = step(feedback, planned=error, measured=(0.0, 0.0))["left"]
    shift = cop_shift(ROLL_AXIS, offsets[0]) + cop_shift(PITCH_AXIS, offsets[1])
    assert shift @ np.asarray(error) > 0.0
    assert np.allclose(feedback.offsets["right"], 0.0)


def test_no_offset_grows_in_double_support_or_without_load():
    feedback = AnkleCopFeedback(gain=(2.0, 2.0))
    step(feedback, planned=(0.05, 0.02), measured=(0.0, 0.0), single_support=False)
    step(feedback, planned=(0.05, 0.02), measured=(0.0, 0.0), load=0.1 * WEIGHT)
    assert np.allclose(feedback.offsets["left"], 0.0)


def test_offsets_leak_back_to_zero_and_stay_bounded():
    feedback = AnkleCopFeedback(gain=(50.0, 50.0), leak=0.2, limit=0.1)
    for _ in range(200):
        step(feedback, planned=(0.05, 0.02), measured=(0.0, 0.0))
    assert np.all(np.abs(feedback.offsets["left"]) == pytest.approx(0.1))
    for _ in range(200):  # 2 s of double support = 10 time constants
        step(feedback, planned=(0.05, 0.02), measured=(0.0, 0.0), single_support=False)
    assert np.all(np.abs(feedback.offsets["left"]) < 0.1 * np.exp(-8))


def test_a_zero_gain_axis_is_left_alone():
    feedback = AnkleCopFeedback(gain=(0.0, 2.0))
    offsets = step(feedback, planned=(0.05, 0.0), measured=(0.0, 0.0))
    assert np.allclose(offsets["left"], 0.0)


@pytest.mark.parametrize(
    ("kwargs", "field"),
    [
        ({"gain": -1.0}, "cop_feedback"),
        ({"gain": (1.0, float("nan"))}, "cop_feedback"),
        ({"leak": 0.0}, "cop_feedback_leak/limit"),
        ({"limit": 2.0}, "cop_feedback_leak/limit"),
    ],
)
def test_bad_parameters_name_the_field(kwargs, field):
    with pytest.raises(ParameterError) as error:
        AnkleCopFeedback(**kwargs)
    assert error.value.field == field
