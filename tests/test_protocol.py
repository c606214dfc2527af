"""The IHMC-style protocol: push timing and sides, and the bisected fractions (LIPM)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.protocol import DIRECTIONS, GRAVITY, ProtocolSpec, protocol_jobs
from app.push_outcome import PushRun, impulse_along
from app.runner import run_closed_loop
from app.scenarios import Scenario
from app.setup import build_backend
from app.sweep_trial import push_timing
from planner.exceptions import ParameterError
from planner.types import Push


@pytest.mark.parametrize("robot", ["g1", "talos", None])
def test_pushes_start_at_mid_swing_and_mid_double_support(robot: str | None) -> None:
    """Forward, backward and inward at single-support start + half the swing, outward at
    double-support start + half of it, on the left stance foot; checked on the run (on
    the paper's point mass each step lands 2 ms after its nominal time, 7 ms by the
    push; on the robots' planners on time)."""
    spec = ProtocolSpec(model="lipm", robot=robot)
    sweep = spec.sweep_spec()
    backend, config, initial = build_backend("lipm", robot, "rsg")
    gait = config.gait
    touchdown = gait.single_support_duration + (spec.cycle - 1) * gait.step_duration
    jobs = protocol_jobs(sweep)
    assert [round(math.degrees(j.angle)) for j in jobs] == [0, 180, 90, 270]
    for job, name in zip(jobs, DIRECTIONS, strict=True):
        start, sigma, since = push_timing(config, sweep.cycle, job.phase)
        in_transfer = name == "outward"
        expected = gait.double_support_duration / 2 if in_transfer else (
            gait.double_support_duration + gait.single_support_duration / 2
        )  # fmt: skip
        assert start == pytest.approx(touchdown + expected), name
        assert sigma == 1, name  # left stance, as IHMC's right swing
        # What the run shows at the push start: s~, the stance foot and the push's side.
        push = Push(start, 0.01 * impulse_along(math.degrees(job.angle), 1.0), 0.1)
        scenario = Scenario("protocol", start + 0.3, (push,))
        result = run_closed_loop(backend, config, scenario, initial, qp_solver="exact")
        time = result.column("t")
        tick = int(np.argmin(np.abs(time - start)))
        late = 0.008 if robot is None else 0.0015
        assert result.column("time_since_step")[tick] == pytest.approx(expected, abs=late)
        assert (result.column("time_since_step")[tick] < gait.double_support_duration) == (
            in_transfer
        )  # fmt: skip
        assert result.column("stance_sigma")[tick] == 1.0
        towards_stance = result.column("foot_y")[tick] - result.column("com_y")[tick]
        if name == "inward":
            assert math.sin(job.angle) * towards_stance > 0.0
        if name == "outward":
            assert math.sin(job.angle) * towards_stance < 0.0
        pushing = np.hypot(result.column("push_fx"), result.column("push_fy")) > 0.0
        assert time[pushing].min() == pytest.approx(start, abs=0.0011)
        assert time[pushing].max() == pytest.approx(start + 0.1, abs=0.0011)


def test_bad_protocols_name_the_field() -> None:
    for change, field in [({"cycle": 3}, "cycle"), ({"tolerance": 0.0}, "tolerance"),
                          ({"robot": "atlas"}, "robot")]:  # fmt: skip
        with pytest.raises(ParameterError) as error:
            ProtocolSpec(**change)
        assert error.value.field == field


def test_largest_fractions_on_g1s_planner(tmp_path: Path, capsys) -> None:
    """``rsg protocol --model lipm --robot g1``: each fraction f is recovered and
    f + tolerance is not (independent full runs), and the velocity change is f g 0.1 s."""
    tolerance = 0.1
    code = main(["protocol", "--model", "lipm", "--robot", "g1", "--tolerance", f"{tolerance}",
                 "--settle", "4", "--workers", "2", "--out", str(tmp_path), "--quiet"])  # fmt: skip
    assert code == 0
    printed = capsys.readouterr().out
    assert "Atlas (IHMC CI test)" in printed and "0.80 (0.78)" in printed
    document = json.loads((tmp_path / "protocol.json").read_text())
    assert "AtlasICPOptimizationPushRecoveryATest" in document["source"]
    rows = document["controllers"]["rsg"]
    assert list(rows) == list(DIRECTIONS)
    spec = ProtocolSpec(model="lipm", robot="g1", settle=4.0)
    config = build_backend("lipm", "g1", "rsg")[1]
    for name, row in rows.items():
        assert row["velocity_change"] == pytest.approx(row["fraction"] * GRAVITY * 0.1)
        assert row["impulse"] == pytest.approx(row["fraction"] * config.model.mass * GRAVITY * 0.1)
        assert row["atlas_fraction"] == DIRECTIONS[name][2]
        assert row["fraction"] > 0.0, name
        for fraction, recovered in ((row["fraction"], True), (row["fraction"] + tolerance, False)):
            if row["capped"] and not recovered:
                continue
            magnitude = fraction * config.model.mass * GRAVITY * 0.1
            push = Push(row["push_time"], impulse_along(row["direction_deg"], magnitude), 0.1)
            result = PushRun(spec.sweep_spec(), "rsg").run(push, push.time + spec.settle)
            assert result.recovered == recovered, (name, fraction)
    assert rows["forward"]["fraction"] > rows["inward"]["fraction"]  # the crossing limit
