"""The replay page's snapshots come from the recording: what the live page would show."""

from __future__ import annotations

import numpy as np
import pytest

from app.backends.lipm import LipmBackend
from app.results.replay import ReplayData, ReplayRecorder, load_replay
from app.runner import run_closed_loop
from app.scenarios import Scenario
from planner.parameters import PlannerConfig
from planner.types import Push
from web.replay_source import snapshot_at
from web.scene_model import draw_scene
from web.snapshot import PLOT_TIME, TRAIL_TIME


def record(tmp_path, pushes, duration: float) -> ReplayData:
    config = PlannerConfig()
    recorder = ReplayRecorder()
    result = run_closed_loop(
        LipmBackend(config.model), config, Scenario("s", duration, pushes), on_tick=recorder
    )
    recorder.write(result, "rsg", None, tmp_path)
    return load_replay(tmp_path)


@pytest.fixture(scope="module")
def replay(tmp_path_factory) -> ReplayData:
    push = Push(2.0, np.array([10.0, -8.0]), 0.1)
    return record(tmp_path_factory.mktemp("replay"), (push,), 12.0)


def test_snapshot_holds_the_recorded_state_at_that_time(replay):
    snap = snapshot_at(replay, 2.05)
    state = snap.state
    index = replay.index_at(2.05)
    assert state is not None and state.time == pytest.approx(2.05)
    np.testing.assert_allclose(
        state.com, [replay.column("com_x")[index], replay.column("com_y")[index]]
    )
    np.testing.assert_allclose(state.push_impulse, [10.0, -8.0])  # the push acts at 2.05 s
    drawing = draw_scene(state, snap.foot_lower, snap.foot_upper)
    assert drawing.push_arrow is not None
    assert (
        draw_scene(snapshot_at(replay, 2.2).state, snap.foot_lower, snap.foot_upper).push_arrow
        is None
    )
    assert len(state.com_trail) == round(TRAIL_TIME / 0.01)
    assert snap.plot_time[0] >= 2.05 - PLOT_TIME - 1e-9 and snap.plot_time[-1] == pytest.approx(
        2.05
    )
    assert snap.pushes_applied == 1 and snapshot_at(replay, 1.9).pushes_applied == 0
    later = snapshot_at(replay, 8.0)
    taken = replay.steps[replay.steps[:, 0] <= 8.0]
    assert later.state is not None and len(later.state.steps) == len(taken)
    assert later.adjusted_steps == int(taken[:, 4].sum()) >= 1
    np.testing.assert_allclose(later.state.steps[-1].position, taken[-1, 2:4])
    for time in (4.35, 7.77, 10.01):  # sample times are sums of float periods
        assert snapshot_at(replay, time).state.time == pytest.approx(time)
    assert snapshot_at(replay, -5.0).state.time == 0.0  # clipped to the recording
    assert snapshot_at(replay, 99.0).state.time == pytest.approx(replay.duration)


def test_a_fall_shows_at_the_end_of_the_recording(tmp_path):
    fallen = record(tmp_path, (Push(1.0, np.array([0.0, 200.0]), 0.1),), 6.0)
    assert fallen.meta["fell"] and fallen.duration < 6.0
    end = snapshot_at(fallen, fallen.duration)
    assert end.state is not None and end.state.fell and end.status.fell
    assert end.state.fall_reason == fallen.meta["fall_reason"] != ""
    assert not snapshot_at(fallen, 0.5).state.fell
