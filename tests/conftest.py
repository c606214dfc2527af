"""Shared fixtures and helpers: planner configurations and LIPM runs, built once per
session; hand-made planner commands and a DCM feedback for full-robot tests (the
planner's part, without the planner); the cache of derived URDFs in the session's
temporary folder; servers run as subprocesses."""

# ruff: noqa: E402 (the kernels are pinned before numpy is imported)
from __future__ import annotations

import kernels

kernels.pin()  # before numpy loads

import socket
import subprocess
import threading
from collections.abc import Iterator
from contextlib import contextmanager

import numpy as np
import pytest
from numpy.typing import NDArray

from app.backends.lipm import LipmBackend
from app.runner import RunResult, run_closed_loop
from app.scenarios import BUILT_IN, Scenario
from planner.parameters import GRAVITY, PlannerConfig
from planner.types import Foothold, MeasuredState, PlannerOutput, Push, StepEvent


def scaled(scenario: Scenario, factor: float) -> Scenario:
    """``scenario`` with every impulse multiplied by ``factor``."""
    pushes = tuple(
        Push(p.time, np.asarray(p.impulse) * factor, p.duration) for p in scenario.pushes
    )
    return Scenario(f"{scenario.name}x{factor:g}", scenario.duration, pushes)


def run_lipm(controller: str, scenario: Scenario, qp_solver: str = "proxqp") -> RunResult:
    """One closed-loop run on the LIPM backend with default parameters."""
    config = PlannerConfig(controller=controller)
    return run_closed_loop(LipmBackend(config.model), config, scenario, qp_solver=qp_solver)


@pytest.fixture(scope="session")
def fig6_runs() -> dict[str, RunResult]:
    """paper-fig6 with each controller."""
    return {c: run_lipm(c, BUILT_IN["paper-fig6"]) for c in ("rsg", "fixed-timing", "no-step")}


LEFT = Foothold("left", np.array([0.0, 0.115]))
RIGHT = Foothold("right", np.array([0.0, -0.115]))
DCM_GAIN = 3.0  # [1/s] convergence rate of the test's DCM feedback


def command(
    time: float,
    zmp: NDArray[np.float64],
    stance: Foothold = LEFT,
    swing: Foothold = RIGHT,
    next_step: Foothold | None = None,
    since_step: float = 0.0,
    step: StepEvent | None = None,
    double_support_duration: float = 0.1,
    step_duration: float = 0.8,
    angular_momentum_rate: NDArray[np.float64] | None = None,
    angular_momentum_rate_feedback: NDArray[np.float64] | None = None,
) -> PlannerOutput:
    """A planner command: the ZMP ``zmp`` [m] on ``stance``, ``since_step`` [s] after
    the last step, the next step ``next_step`` (default: ``swing``) at the step
    duration; hdot [N m] and its feedback part default to zero."""
    zmp = np.asarray(zmp, float)
    zero = np.zeros(2)
    rate = zero if angular_momentum_rate is None else angular_momentum_rate
    feedback = zero if angular_momentum_rate_feedback is None else angular_momentum_rate_feedback
    return PlannerOutput(
        time=time,
        zmp=zmp,
        zmp_offset=np.zeros(2),
        window_center=zmp,
        angular_momentum_rate=rate,
        angular_momentum_rate_feedback=feedback,
        stance=stance,
        previous_stance=swing,
        next_step=next_step or swing,
        next_step_time=time - since_step + step_duration,
        time_since_step=since_step,
        double_support=since_step < double_support_duration,
        dcm_error=np.zeros(2),
        lyapunov=0.0,
        lyapunov_at_step=0.0,
        com_reference=zmp,
        step=step,
    )


def dcm_feedback_zmp(
    state: MeasuredState, target: NDArray[np.float64], com_height: float, gain: float = DCM_GAIN
) -> NDArray[np.float64]:
    """ZMP [m] that brings the DCM xi = c + cd / omega to ``target`` at the rate ``gain``:
    xi_dot = omega (xi - p) = -gain (xi - target) (Englsberger et al., IROS 2011)."""
    omega = np.sqrt(GRAVITY / com_height)
    dcm = state.com_position + state.com_velocity / omega
    return dcm + gain / omega * (dcm - np.asarray(target, float))


def session_cache(tmp_path_factory: pytest.TempPathFactory) -> str:
    """The session's RSG_CACHE_DIR: derived URDFs are built once, never in the user's cache."""
    return str(tmp_path_factory.getbasetemp() / "cache")


@pytest.fixture
def cache_in_tmp(tmp_path_factory: pytest.TempPathFactory, monkeypatch: pytest.MonkeyPatch) -> None:
    """RSG_CACHE_DIR set to :func:`session_cache` for one test."""
    monkeypatch.setenv("RSG_CACHE_DIR", session_cache(tmp_path_factory))


@contextmanager
def cache_for_module(tmp_path_factory: pytest.TempPathFactory) -> Iterator[None]:
    """RSG_CACHE_DIR set to :func:`session_cache` inside a module-scoped fixture."""
    with pytest.MonkeyPatch.context() as patch:
        patch.setenv("RSG_CACHE_DIR", session_cache(tmp_path_factory))
        yield


def free_port() -> int:
    """A TCP port free on 127.0.0.1 now."""
    with socket.socket() as probe:
        probe.bind(("127.0.0.1", 0))
        return int(probe.getsockname()[1])


@contextmanager
def output_lines(process: subprocess.Popen[str]) -> Iterator[list[str]]:
    """The lines ``process`` prints, as they come; the process is killed if still running."""
    lines: list[str] = []
    assert process.stdout is not None
    stdout = process.stdout
    reader = threading.Thread(target=lambda: lines.extend(stdout), daemon=True)
    reader.start()
    try:
        yield lines
    finally:
        if process.poll() is None:
            process.kill()
            process.wait(10)
    reader.join(5)


def assert_stands_one_second(backend, left: Foothold = LEFT, right: Foothold = RIGHT) -> None:
    """Reset ``backend`` (a full robot) on ``left`` and ``right`` and hold it 1 s with the
    DCM feedback: no fall, both feet on the ground, carrying m g within 2 % at the end."""
    from app.backends.base import InitialCondition

    state = backend.reset(InitialCondition(left, right, np.zeros(2), np.zeros(2)))
    for tick in range(round(1.0 / backend.control_period)):
        zmp = dcm_feedback_zmp(state, np.zeros(2), backend.description.pendulum_height)
        planned = command(tick * backend.control_period, zmp, left, right)
        state = backend.step(planned, np.zeros(2))
        assert not backend.fall_status().fell, (tick, backend.fall_status())
    total = sum(force for _, force in backend.foot_pressure().values())
    assert abs(total - backend.mass * GRAVITY) < 0.02 * backend.mass * GRAVITY, total
    assert backend.feet_in_contact() == {"left", "right"}
