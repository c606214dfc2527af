"""Push grid: outcomes on the LIPM, counts, files, errors."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from app.cli import main
from app.experiments.grid import GridSpec, format_grid, run_grid, summarize, write_grid
from planner.exceptions import ParameterError


def test_on_the_lipm_stepping_recovers_pushes_the_ankle_alone_cannot(tmp_path: Path) -> None:
    """20 N s is within the ZMP window's reach for both; at 60 N s only stepping helps."""
    spec = GridSpec(
        model="lipm", controllers=("rsg", "no-step"), impulses=(20.0, 60.0), directions=4
    )
    records = run_grid(spec, workers=1, progress=False)
    assert len(records) == 2 * 2 * 4
    summary = summarize(spec, records)
    rsg, no_step = summary["rsg"]["0.5625"], summary["no-step"]["0.5625"]
    assert rsg["per_impulse"]["20"]["recovered"] == no_step["per_impulse"]["20"]["recovered"] == 4
    assert rsg["per_impulse"]["60"]["recovered"] > no_step["per_impulse"]["60"]["recovered"]
    for part in (rsg, no_step):
        total = part["total"]
        assert total["recovered"] + total["survived"] + total["fell"] == total["runs"] == 8
    for record in records:
        if record["outcome"] == "recovered" and record["controller"] == "rsg":
            assert record["adjusted_steps"] >= 0
        if record["outcome"] == "fell":
            assert record["fall_reason"]
    paths = write_grid(tmp_path, spec, records, 1.0)
    document = json.loads(paths[0].read_text())
    assert document["summary"] == json.loads(json.dumps(summary))
    assert len(paths[1].read_text().splitlines()) == len(records) + 1
    assert "rsg" in format_grid(spec, records)


@pytest.mark.parametrize(
    ("change", "field"),
    [
        ({"impulses": ()}, "impulses"),
        ({"impulses": (-1.0,)}, "impulses"),
        ({"directions": 0}, "directions"),
        ({"phases": (1.0,)}, "phases"),
        ({"controllers": ("rsg", "rsg")}, "controllers"),
        ({"model": "lipm", "controllers": ("placo-wpg",)}, "controllers"),
        ({"settle": 0.1}, "settle"),
    ],
)
def test_bad_grids_name_the_field(change: dict, field: str) -> None:
    with pytest.raises(ParameterError) as error:
        GridSpec(**change)
    assert error.value.field == field


def test_the_command_writes_the_grid_and_its_plot(tmp_path: Path, capsys) -> None:
    code = main(
        ["grid", "--model", "lipm", "--controllers", "rsg", "--impulses", "30",
         "--directions", "2", "--workers", "1", "--quiet", "--out", str(tmp_path)]
    )  # fmt: skip
    assert code == 0
    for name in ("grid.json", "grid.csv", "grid.png"):
        assert (tmp_path / name).is_file()
    assert "not fallen 2/2" in capsys.readouterr().out
    assert main(["grid", "--directions", "0", "--out", str(tmp_path)]) == 2


def test_a_push_above_its_capture_bound_falls_and_is_marked() -> None:
    """G1's planner on the LIPM at phase 0.25 (right stance): towards the stance side
    (270 deg) no stepping controller can take 18 N s (the bound, 16.2 N s with G1's
    5 N m hdot bound, first step 0.35 s after the touchdown and 0.55 m outward reach, is
    below it), forward the bound is several times larger and the push is recovered."""
    spec = GridSpec(
        model="lipm", robot="g1", controllers=("rsg",), impulses=(18.0,), directions=4,
        phases=(0.25,),
    )  # fmt: skip
    records = {r["direction_deg"]: r for r in run_grid(spec, workers=1, progress=False)}
    sideways, forward = records[270.0], records[0.0]
    assert sideways["stance"] == "right"
    assert sideways["capture_bound"] < 18.0 < forward["capture_bound"] / 2.0
    assert sideways["outcome"] == "fell"
    assert forward["outcome"] == "recovered"
    summary = summarize(spec, list(records.values()))
    assert summary["rsg"]["0.25"]["total"]["beyond_bound"] == 1
    text = format_grid(spec, list(records.values()))
    assert "(1 above the bound)" in text
    assert "[o" in text and "X]" in text  # 0 deg recovered ... 270 deg fell, above
