"""Replay files: what a run writes for ``rsg replay``, read back, and bad files refused."""

from __future__ import annotations

import numpy as np
import pytest

from app.backends.lipm import LipmBackend
from app.results.replay import REPLAY_FILE, ReplayError, ReplayRecorder, load_replay
from app.runner import RunResult, run_closed_loop
from app.scenarios import Scenario
from planner.lyapunov import design_lyapunov
from planner.parameters import PlannerConfig
from planner.types import Push


@pytest.fixture(scope="module")
def recorded() -> tuple[RunResult, ReplayRecorder]:
    config = PlannerConfig()
    scenario = Scenario("side", 3.0, (Push(1.0, np.array([0.0, 20.0]), 0.1),))
    recorder = ReplayRecorder()
    result = run_closed_loop(LipmBackend(config.model), config, scenario, on_tick=recorder)
    return result, recorder


def test_replay_holds_the_run_sampled_every_10_ms(recorded, tmp_path):
    result, recorder = recorded
    path = recorder.write(result, "rsg", None, tmp_path)
    assert path == tmp_path / REPLAY_FILE
    replay = load_replay(tmp_path)
    assert replay.robot is None and replay.meta["model"] == "lipm"
    np.testing.assert_allclose(np.diff(replay.time), 0.01, atol=1e-9)
    ticks = np.round(replay.time / 0.001).astype(int)  # the LIPM's control period is 1 ms
    for name in ("com_x", "com_y", "com_vx", "zmp_y", "dcm_error_x", "lyapunov"):
        np.testing.assert_allclose(
            replay.column(name), result.column(name)[ticks], rtol=1e-5, atol=1e-6, err_msg=name
        )
    assert len(replay.steps) == len(result.steps) > 3
    np.testing.assert_allclose(replay.steps[:, 0], [s.event["t"] for s in result.steps])
    assert replay.steps[:, 4].sum() == sum(s.event["adjusted"] for s in result.steps) > 0
    np.testing.assert_allclose(replay.impulse_at(1.05), [0.0, 20.0])
    assert replay.impulse_at(1.2) is None
    design = design_lyapunov(result.config.model, result.config.constraints, result.config.rsg)
    np.testing.assert_allclose(replay.level_set(0.002), design.level_set(0.002), atol=1e-12)


def test_an_interrupted_write_leaves_the_previous_file_or_none(recorded, tmp_path, monkeypatch):
    result, recorder = recorded
    recorder.write(result, "rsg", None, tmp_path)
    before = (tmp_path / REPLAY_FILE).read_bytes()

    def interrupted(handle, **arrays):
        handle.write(b"PK\x03\x04 half a zip")
        raise KeyboardInterrupt

    monkeypatch.setattr(np, "savez_compressed", interrupted)
    with pytest.raises(KeyboardInterrupt):
        recorder.write(result, "rsg", None, tmp_path)
    assert (tmp_path / REPLAY_FILE).read_bytes() == before
    assert sorted(p.name for p in tmp_path.iterdir()) == [REPLAY_FILE]
    with pytest.raises(KeyboardInterrupt):
        recorder.write(result, "rsg", None, tmp_path / "new")
    assert list((tmp_path / "new").iterdir()) == []


def test_bad_folders_and_files_are_refused_with_the_reason(recorded, tmp_path):
    result, recorder = recorded
    with pytest.raises(ReplayError, match="no such folder"):
        load_replay(tmp_path / "missing")
    (tmp_path / "file.txt").write_text("x")
    with pytest.raises(ReplayError, match="not a folder"):
        load_replay(tmp_path / "file.txt")
    with pytest.raises(ReplayError, match="no replay.npz: not a run folder"):
        load_replay(tmp_path)
    (tmp_path / REPLAY_FILE).write_bytes(b"not a zip at all")
    with pytest.raises(ReplayError, match="not a readable replay"):
        load_replay(tmp_path)
    good = tmp_path / "good"
    recorder.write(result, "rsg", None, good)
    data = (good / REPLAY_FILE).read_bytes()
    (tmp_path / REPLAY_FILE).write_bytes(data[: len(data) // 2])  # cut short
    with pytest.raises(ReplayError, match="not a readable replay"):
        load_replay(tmp_path)
    with np.load(good / REPLAY_FILE) as archive:
        arrays = {name: archive[name] for name in archive.files}
    arrays["state"] = arrays["state"][:, :5]
    np.savez(tmp_path / REPLAY_FILE, **arrays)
    with pytest.raises(ReplayError, match="state has shape"):
        load_replay(tmp_path)
