"""The stabilizer's options (:class:`app.stabilizer.config.StabilizerConfig`) and each
robot's joint gains."""

from __future__ import annotations

import dataclasses

import pytest

from app.backends.pybullet import stabilizer_config
from app.stabilizer.config import OPTION_NAMES, RANGES, StabilizerConfig
from app.stabilizer.controller import joint_impedance
from kinematics.robot_model import RobotModel
from planner.exceptions import ParameterError
from robots import get_robot
from robots.g1 import DAMPING_FACTOR, PUBLISHED_GAINS, STIFFNESS_FACTOR


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def test_every_number_option_has_a_range_and_the_defaults_are_in_it():
    assert set(OPTION_NAMES) == set(RANGES)
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
    assert StabilizerConfig(friction=1).friction == 1  # an int is a number


def test_a_robots_backend_options_are_its_stabilizer_options():
    """An unknown name (an option of the old backend) is refused, naming it and the
    known ones; the control period is the backend's, not the stabilizer's."""
    config = stabilizer_config({"landing_depth": 0.004, "control_period": 0.004})
    assert config == dataclasses.replace(StabilizerConfig(), landing_depth=0.004)
    with pytest.raises(ParameterError) as error:
        stabilizer_config({"cop_admittance": 0.2})
    assert error.value.value == "cop_admittance"
    assert all(name in error.value.allowed for name in OPTION_NAMES)


def test_g1s_joint_gains_are_unitrees_published_ones_scaled_but_the_ankles():
    """Every joint of the model has gains; the ankles (pitch and roll above each sole)
    keep Unitree's kp 40, kd 2; the others take 5 x kp and 10 x kd."""
    description = get_robot("g1")
    model = RobotModel(description)
    stiffness, damping = joint_impedance(model, description)
    ankles = {name for name in model.joint_names if model.is_ankle(name)}
    assert ankles == {
        f"{side}_ankle_{axis}_joint" for side in ("left", "right") for axis in ("pitch", "roll")
    }
    for index, name in enumerate(model.joint_names):
        group = next(
            (g for g in ("waist_yaw", "hip", "knee", "ankle", "waist") if g in name), "arm"
        )
        kp, kd = PUBLISHED_GAINS[group]
        scale = (1.0, 1.0) if name in ankles else (STIFFNESS_FACTOR, DAMPING_FACTOR)
        assert stiffness[index] == pytest.approx(scale[0] * kp), name
        assert damping[index] == pytest.approx(scale[1] * kd), name
    assert stiffness[model.joint_names.index("left_knee_joint")] == pytest.approx(1500.0)


def test_talos_joints_reach_their_effort_limit_at_a_tenth_of_a_radian():
    """No gains are published for Talos: kp = effort / 0.1 rad (ankles / 1 rad)."""
    description = get_robot("talos")
    model = RobotModel(description)
    stiffness, _ = joint_impedance(model, description)
    effort = model.effort_limits
    for index, name in enumerate(model.joint_names):
        angle = 1.0 if model.is_ankle(name) else 0.1
        assert stiffness[index] * angle == pytest.approx(effort[index]), name


def test_a_joint_without_gains_is_refused_naming_it():
    description = get_robot("g1")
    model = RobotModel(description)
    gains = dict(description.joint_impedance)
    del gains["left_knee_joint"]
    with pytest.raises(ParameterError) as error:
        joint_impedance(model, dataclasses.replace(description, joint_impedance=gains))
    assert error.value.field == "joint_impedance"
    assert error.value.value == ["left_knee_joint"]
