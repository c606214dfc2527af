"""Sweeps and push grids keep their worst failed runs replayable."""

from __future__ import annotations

import math

import numpy as np
import pytest

from app.experiments.grid import GridSpec, run_grid
from app.results.replay import load_replay
from app.results.worst_runs import (
    format_replays,
    replay_name,
    worst_grid_runs,
    worst_sweep_runs,
    write_worst_replays,
)


def grid_record(controller, outcome, impulse, bound, direction=0.0):
    return {"controller": controller, "outcome": outcome, "impulse": impulse,
            "capture_bound": bound, "direction_deg": direction, "phase": 0.5}  # fmt: skip


def test_worst_runs_are_falls_far_inside_the_capture_bound_per_controller():
    records = [
        grid_record("rsg", "recovered", 2.0, 10.0),
        grid_record("rsg", "survived", 3.0, 10.0),  # not recovered, below the bound
        grid_record("rsg", "fell", 9.0, 10.0),
        grid_record("rsg", "fell", 12.0, 10.0),  # above the bound: less telling
        grid_record("no-step", "fell", 8.0, 10.0),
    ]
    worst = worst_grid_runs(records, count=2)
    assert [(r["controller"], r["impulse"]) for r in worst] == [
        ("rsg", 9.0), ("rsg", 12.0), ("no-step", 8.0)
    ]  # fmt: skip
    assert worst_grid_runs(records, count=0) == []
    sweep = [
        {"controller": "rsg", "failed_at": None, "bound": 10.0, "direction_deg": 0, "phase": 0},
        {"controller": "rsg", "failed_at": 6.0, "bound": 10.0, "direction_deg": 90, "phase": 0},
        {"controller": "rsg", "failed_at": 4.0, "bound": 10.0, "direction_deg": 180, "phase": 0},
    ]
    assert [r["direction_deg"] for r in worst_sweep_runs(sweep, count=1)] == [180]


def test_kept_runs_replay_what_the_grid_ran(tmp_path):
    spec = GridSpec(model="lipm", controllers=("no-step",), impulses=(40.0,), directions=1,
                    settle=1.5)  # fmt: skip
    records = run_grid(spec, workers=1, progress=False)
    worst = worst_grid_runs(records)
    assert len(worst) >= 1
    written = write_worst_replays(spec, worst, tmp_path)
    for record, entry in zip(worst, written, strict=True):
        folder = tmp_path / "replays" / replay_name(record)
        assert entry["folder"] == str(folder) and (folder / "summary.json").is_file()
        replay = load_replay(folder)
        assert entry["outcome"] == record["outcome"]  # deterministic: the same run again
        assert replay.meta["fell"] == (record["outcome"] == "fell")
        angle = math.radians(record["direction_deg"])
        np.testing.assert_allclose(
            replay.pushes[0, 1:3], 40.0 * np.array([math.cos(angle), math.sin(angle)]), atol=1e-9
        )
        assert replay.pushes[0, 0] == pytest.approx(record["push_time"])
    assert str(tmp_path / "replays") in format_replays(written)
