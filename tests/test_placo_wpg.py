"""The placo-wpg baseline: placo's WalkPatternGenerator and update_supports in the loop."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.placo_wpg import PlacoWalkPlanner, humanoid_parameters
from app.robot_setup import planner_config_for
from app.runner import walking_start
from app.sweep import SweepSpec
from planner.types import MeasuredState, PlannerOutput, sigma_of
from robots import get_robot

PERIOD = 0.01


@pytest.fixture(scope="module")
def planner() -> PlacoWalkPlanner:
    description = get_robot("g1")
    return PlacoWalkPlanner(description, planner_config_for(description, 33.3))


def _walk(planner: PlacoWalkPlanner, duration: float, error=None) -> list[PlannerOutput]:  # noqa: ANN001
    """Feed the trajectory's own CoM state back, plus ``error(t)`` on the DCM [m]."""
    initial = walking_start(planner.config)
    planner.reset(initial.stance, initial.swing)
    outputs = []
    for k in range(int(round(duration / PERIOD))):
        t = k * PERIOD
        com = np.asarray(planner.trajectory.get_p_world_CoM(t), float)[:2]
        velocity = np.asarray(planner.trajectory.get_v_world_CoM(t), float)[:2]
        if error is not None:
            velocity = velocity + planner.omega * error(t)
        outputs.append(planner.update(MeasuredState(t, com, velocity), PERIOD))
    return outputs


def _steps(outputs: list[PlannerOutput]) -> list[PlannerOutput]:
    return [out for out in outputs if out.step is not None]


def test_parameters_follow_the_robot_and_the_gait(planner: PlacoWalkPlanner) -> None:
    config = planner.config
    params = humanoid_parameters(planner.description, config)
    assert params.single_support_duration == pytest.approx(config.gait.single_support_duration)
    assert params.double_support_duration() == pytest.approx(config.gait.double_support_duration)
    assert params.walk_com_height == pytest.approx(config.model.com_height)
    assert params.feet_spacing == pytest.approx(config.gait.step_width)
    assert params.foot_length == pytest.approx(0.17)


def test_own_trajectory_fed_back_gives_the_nominal_plan(planner: PlacoWalkPlanner) -> None:
    outputs = _walk(planner, 3.0)
    gait = planner.config.gait
    steps = _steps(outputs)
    assert len(steps) == 3
    for k, out in enumerate(steps, start=1):
        assert out.step is not None
        nominal_time = gait.single_support_duration + (k - 1) * gait.step_duration
        assert out.time == pytest.approx(nominal_time, abs=PERIOD + 1e-9)
        side = 1.0 if out.stance.foot == "left" else -1.0
        nominal = np.array([k * gait.stride_length, side * gait.step_width / 2])
        np.testing.assert_allclose(out.stance.position, nominal, atol=1e-5)
        assert not out.step.adjusted
    assert max(float(np.linalg.norm(out.dcm_error)) for out in outputs) < 1e-6
    assert all(out.lyapunov == 0.0 for out in outputs)


def test_outputs_are_consistent(planner: PlacoWalkPlanner) -> None:
    outputs = _walk(planner, 3.0)
    feet = [out.stance.foot for out in _steps(outputs)]
    assert feet == ["right", "left", "right"]  # alternates, from the left stance
    previous = None
    for out in outputs:
        sigma = sigma_of(out.stance.foot)
        # the other foot is on its own side of the stance foot (no crossing)
        assert sigma * (out.stance.position[1] - out.next_step.position[1]) > 0.05
        assert out.next_step.foot != out.stance.foot
        assert out.double_support == (out.time_since_step < 0.1 - 1e-9)
        assert out.next_step_time >= out.time - 1e-9
        if out.step is not None and previous is not None:
            assert out.next_step_time > previous.next_step_time
            np.testing.assert_allclose(out.previous_stance.position, previous.stance.position)
        previous = out


@pytest.mark.parametrize(
    ("error", "moved"),
    [((0.0, 0.02), "y"), ((0.0, -0.02), "y"), ((0.03, 0.0), "x"), ((-0.03, 0.0), "x")],
)
def test_a_push_changes_the_next_step(planner: PlacoWalkPlanner, error, moved: str) -> None:  # noqa: ANN001
    """A DCM error growing as after a push at 0.3 s (left stance) moves the first step."""
    omega, e0 = planner.omega, np.array(error)

    def dcm_error(t: float) -> np.ndarray:
        return e0 * np.exp(omega * (t - 0.3)) if 0.3 <= t < 0.7 else np.zeros(2)

    first = _steps(_walk(planner, 0.8, dcm_error))[0]
    assert first.step is not None and first.step.location_adjusted
    nominal = np.array([0.1, -0.1])
    axis = 0 if moved == "x" else 1
    shift = first.stance.position[axis] - nominal[axis]
    assert np.sign(shift) == np.sign(e0[axis]) and abs(shift) > 0.02
    if moved == "y" and e0[1] > 0:  # towards the stance side: stopped by the no-crossing bound
        assert first.stance.position[1] <= 0.1 - 0.09 + 1e-6


@pytest.mark.parametrize("error", [(0.06, 0.0), (0.0, 0.03)])
def test_a_larger_push_also_moves_the_step_time(planner: PlacoWalkPlanner, error) -> None:  # noqa: ANN001
    """Forward, or towards the stance side (where the no-crossing bound stops the foot)."""
    omega, e0 = planner.omega, np.array(error)

    def dcm_error(t: float) -> np.ndarray:
        return e0 * np.exp(omega * (t - 0.3)) if 0.3 <= t else np.zeros(2)

    outputs = _walk(planner, 0.75, dcm_error)
    planned = [out.next_step_time for out in outputs if 0.3 < out.time < 0.65]
    assert min(planned) < 0.68  # the first step is planned > 20 ms earlier than nominal (0.7 s)


def test_sweep_and_run_accept_it_on_pybullet_only(tmp_path: Path, capsys) -> None:  # noqa: ANN001
    SweepSpec(model="pybullet", controllers=("rsg", "placo-wpg"))
    code = main(["run", "--model", "lipm", "--controller", "placo-wpg", "--out", str(tmp_path)])
    assert code == 2
    message = capsys.readouterr().err
    assert "placo-wpg" in message and "pybullet" in message and "rsg" in message


@pytest.mark.slow
def test_placo_wpg_drives_the_g1_deterministically() -> None:
    from app.placo_wpg import build_placo_wpg_backend
    from app.runner import run_closed_loop
    from app.scenarios import Scenario

    results = []
    for _ in range(2):
        backend, config, initial, factory = build_placo_wpg_backend("g1")
        try:
            results.append(
                run_closed_loop(backend, config, Scenario("walk", 3.0), initial, planner=factory)
            )
        finally:
            backend.close()
    first, second = results
    np.testing.assert_array_equal(first.timeseries, second.timeseries)
    assert first.steps, "placo-wpg took no step"
    assert first.sim_time > 1.0
    print(
        f"placo-wpg on G1: {first.sim_time:.2f} s simulated, {len(first.steps)} steps, "
        f"fell={first.fall.fell} ({first.fall.reason})"
    )
