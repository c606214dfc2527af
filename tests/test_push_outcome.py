"""One push, one run: outcome classes and the steps until V_u stays below gamma_v (LIPM)."""

from __future__ import annotations

import numpy as np
import pytest

from app.experiments.grid import GridSpec
from app.experiments.outcome import (
    PushRun,
    adjusted_steps_after,
    describe,
    outcome_of,
    settle_steps,
)
from app.runner import RunResult
from planner.types import Push

SPEC = GridSpec(model="lipm", controllers=("rsg", "no-step"), impulses=(1.0,), directions=1)
START = 1.6  # [s] in the second cycle of the paper's gait


def run(controller: str, impulse: float, after: float) -> tuple[RunResult, Push]:
    push = Push(START, np.array([impulse, 0.0]), 0.1)
    return PushRun(SPEC, controller).run(push, START + after), push


@pytest.fixture(scope="module")
def runs() -> dict[str, tuple[RunResult, Push]]:
    return {
        "recovered": run("rsg", 60.0, 4.0),
        "fell": run("no-step", 80.0, 4.0),
        "survived": run("rsg", 60.0, 0.5),  # still stepping when the run ends
        "small": run("rsg", 3.0, 3.0),
    }


@pytest.mark.parametrize("name", ["recovered", "fell", "survived"])
def test_outcome_classes(runs: dict, name: str) -> None:
    result, push = runs[name]
    assert outcome_of(result) == name
    assert result.recovered == (name == "recovered")
    assert result.fall.fell == (name == "fell")
    figures = describe(result, push, "rsg")
    assert figures["outcome"] == name
    assert bool(figures["fall_reason"]) == (name == "fell")
    if name != "recovered":
        assert figures["settle_steps"] is None  # V_u not below gamma_v for good


def test_steps_until_v_u_stays_below_gamma_v(runs: dict) -> None:
    result, push = runs["recovered"]
    gamma = result.lyapunov_threshold
    count = settle_steps(result, push.time)
    assert count is not None and count >= 1
    after = [s.event for s in result.steps if s.event["t"] >= push.time]
    last = after[count - 1]
    # Between the previous touchdown and that step V_u was at or above gamma_v (at a
    # tick, or just before the step's jump); from that step on it stays below.
    since = after[count - 2]["t"] if count >= 2 else push.time
    ticks = [
        level
        for t, level in zip(result.column("t"), result.column("lyapunov"), strict=True)
        if since <= t < last["t"]
    ]
    assert last["lyapunov_before"] >= gamma or max(ticks) >= gamma
    time, level = result.column("t"), result.column("lyapunov")
    assert np.all(level[time >= last["t"]] < gamma)
    assert all(s["lyapunov_before"] < gamma for s in after[count:])
    assert adjusted_steps_after(result, push.time) >= 1


def test_a_push_the_ankle_absorbs_needs_no_step(runs: dict) -> None:
    result, push = runs["small"]
    assert outcome_of(result) == "recovered"
    assert settle_steps(result, push.time) == 0
    assert adjusted_steps_after(result, push.time) == 0
    assert np.all(result.column("lyapunov") < result.lyapunov_threshold)
