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
from app.runner import TIMESERIES_COLUMNS, RunResult
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


def test_a_push_after_the_last_step_is_not_judged_recovered(runs: dict) -> None:
    """The last two nominal steps must come after the push: a push in the run's last
    0.1 s that the steps before it could not see gives no verdict of recovery."""
    end = START + 3.0
    late = Push(end - 0.1, np.array([3.0, 0.0]), 0.05)
    result = PushRun(SPEC, "rsg").run(late, end)
    assert not result.fall.fell
    last = result.steps[-2:]
    assert all(not s.event["adjusted"] for s in last)
    assert all(s.event["lyapunov_before"] < result.lyapunov_threshold for s in last)
    assert last[-1].event["t"] < late.time
    assert not result.recovered
    assert outcome_of(result) == "survived"


def test_v_u_is_judged_at_the_jumps(runs: dict) -> None:
    """A step taken with V_u >= gamma_v among the last two is not a recovery, even at
    the nominal location."""
    result, _ = runs["recovered"]
    assert result.recovered
    gamma = result.lyapunov_threshold
    steps = [*result.steps[:-1], _raised(result.steps[-1], gamma)]
    above = RunResult(**{**vars(result), "steps": steps})
    assert not above.recovered


def _raised(step, level: float):  # noqa: ANN001, ANN202
    return type(step)({**step.event, "lyapunov_before": level}, step.step)


def test_the_runs_last_instant_does_not_decide(runs: dict) -> None:
    """V_u above gamma_v at the last tick (a robot just after a touchdown) leaves a run
    whose last two steps were nominal and taken below gamma_v recovered."""
    result, _ = runs["recovered"]
    series = result.timeseries.copy()
    series[-1, TIMESERIES_COLUMNS.index("lyapunov")] = 2.0 * result.lyapunov_threshold
    bumped = RunResult(**{**vars(result), "timeseries": series})
    assert bumped.final_lyapunov >= bumped.lyapunov_threshold
    assert bumped.recovered
    assert outcome_of(bumped) == "recovered"
