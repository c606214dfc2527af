"""Shared fixtures: planner configurations and LIPM runs, built once per session."""

from __future__ import annotations

import numpy as np
import pytest

from app.lipm_backend import LipmBackend
from app.runner import RunResult, run_closed_loop
from app.scenarios import BUILT_IN, Scenario
from planner.parameters import PlannerConfig
from planner.types import Push


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
