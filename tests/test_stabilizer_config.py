"""The stabilizer's options (:class:`app.stabilizer.config.StabilizerConfig`) and the
joint impedance they give."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from app.pybullet_backend import stabilizer_config
from app.stabilizer.config import OPTION_NAMES, RANGES, StabilizerConfig
from app.stabilizer.controller import joint_impedance
from kinematics.robot_model import RobotModel
from planner.exceptions import ParameterError
from robots import get_robot


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_every_option_but_the_estimator_has_a_range_and_the_defaults_are_in_it():
    assert set(OPTION_NAMES) == {*RANGES, "estimator"}
    assert len(OPTION_NAMES) <= 12  # the issue: about a dozen options
    config = StabilizerConfig()
    for name, (low, high) in RANGES.items():
        assert low <= getattr(config, name) <= high, name


@pytest.mark.parametrize("name", sorted(RANGES))
def test_each_number_option_refuses_values_out_of_its_range_or_of_the_wrong_type(name):
    low, high = RANGES[name]
    span = high - low
    for value in (
        low - 0.01 * span,
        high + 0.01 * span,
        float("nan"),
        float("inf"),
        "0.1",
        None,
        True,
    ):
        with pytest.raises(ParameterError) as error:
            StabilizerConfig(**{name: value})
        assert error.value.field == name, f"{name}={value!r}"
        assert error.value.value is value
        assert f"[{low:g}, {high:g}]" in error.value.allowed
    for value in (low, high, (low + high) / 2):
        assert getattr(StabilizerConfig(**{name: value}), name) == value
    assert StabilizerConfig(stiffness_angle=1).stiffness_angle == 1  # an int is a number


@pytest.mark.parametrize("value", ["kalman", "", 1, None])
def test_the_estimator_is_truth_or_odometry(value):
    with pytest.raises(ParameterError) as error:
        StabilizerConfig(estimator=value)
    assert error.value.field == "estimator"
    assert "truth" in error.value.allowed and "odometry" in error.value.allowed
    assert StabilizerConfig(estimator="odometry").estimator == "odometry"


def test_a_robots_backend_options_are_its_stabilizer_options():
    """An unknown name (an option of the old backend) is refused, naming it and the
    known ones; the control period is the backend's, not the stabilizer's."""
    config = stabilizer_config({"landing_depth": 0.004, "control_period": 0.004})
    assert config == dataclasses.replace(StabilizerConfig(), landing_depth=0.004)
    with pytest.raises(ParameterError) as error:
        stabilizer_config({"cop_admittance": 0.2})
    assert error.value.value == "cop_admittance"
    assert all(name in error.value.allowed for name in OPTION_NAMES)


def test_joint_impedance_reaches_the_effort_limit_at_the_stiffness_angle():
    """kp = effort / angle (the ankles with their own angle), kd = kp * damping time;
    on G1 the ankles are the pitch and roll joints above each sole."""
    model = RobotModel(get_robot("g1"))
    config = StabilizerConfig(
        stiffness_angle=0.2, ankle_stiffness_angle=0.8, damping_time=0.03, ankle_damping_time=0.07
    )
    stiffness, damping = joint_impedance(model, config)
    ankles = {name for name in model.joint_names if model.is_ankle(name)}
    assert ankles == {
        f"{side}_ankle_{axis}_joint" for side in ("left", "right") for axis in ("pitch", "roll")
    }
    effort = model.effort_limits
    assert np.all(effort > 0.0)
    for index, name in enumerate(model.joint_names):
        angle, time = (0.8, 0.07) if name in ankles else (0.2, 0.03)
        assert stiffness[index] * angle == pytest.approx(effort[index]), name
        assert damping[index] == pytest.approx(stiffness[index] * time), name
    knee = model.joint_names.index("left_knee_joint")
    assert stiffness[knee] == pytest.approx(139.0 / 0.2)  # G1's knee: 139 N m
