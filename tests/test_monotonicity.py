"""``rsg sweep --monotonicity``: fractions of each largest recovered impulse (LIPM)."""

from __future__ import annotations

import json
from pathlib import Path

from app.cli import main
from app.experiments.jobs import JobRun
from app.experiments.monotonicity import FRACTIONS, run_monotonicity
from app.experiments.sweep import SweepSpec
from app.experiments.trial import push_timing
from planner.parameters import PlannerConfig


def test_on_the_lipm_every_fraction_of_a_recovered_push_recovers(tmp_path: Path, capsys) -> None:
    args = ["sweep", "--model", "lipm", "--controllers", "rsg", "--directions", "1",
            "--phases", "0.5", "--tolerance", "8", "--settle", "4", "--workers", "2",
            "--out", str(tmp_path), "--quiet", "--monotonicity"]  # fmt: skip
    assert main(args) == 0
    assert "rsg           0/3 (0 at 0.25, 0 at 0.5, 0 at 0.75)" in capsys.readouterr().out
    report = json.loads((tmp_path / "monotonicity.json").read_text())
    assert report["controllers"]["rsg"]["runs"] == len(FRACTIONS)
    assert report["controllers"]["rsg"]["not_passed"] == 0
    checks = (tmp_path / "monotonicity" / "jobs.jsonl").read_text().splitlines()
    assert len(checks) == 3
    assert main(args) == 0  # resumed: nothing runs again
    assert len((tmp_path / "monotonicity" / "jobs.jsonl").read_text().splitlines()) == 3


def test_a_push_weaker_than_one_reported_recovered_that_falls_is_counted(tmp_path: Path) -> None:
    """A record claiming 600 N s forward at phase 0.5 was recovered: 150 N s is (rsg's
    largest there is about 178 N s), 300 and 450 N s are not."""
    spec = SweepSpec(controllers=("rsg",), directions=1, phases=(0.5,), settle=4.0)
    start = push_timing(PlannerConfig(), spec.cycle, 0.5)[0]
    claimed = {"key": "rsg|0|0.5", "controller": "rsg", "direction_deg": 0.0, "phase": 0.5,
               "push_time": start, "impulse": 600.0}  # fmt: skip
    report = run_monotonicity(spec, [claimed], JobRun(tmp_path, workers=1, progress=False))
    part = report["controllers"]["rsg"]
    assert part["per_fraction"] == {"0.25": 0, "0.5": 1, "0.75": 1}
    assert part["not_passed"] == 2
    assert {f["impulse"] for f in part["failed"]} == {300.0, 450.0}
