"""The IHMC-style protocol: push timing and sides, and the bisected fractions (LIPM)."""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.experiments.outcome import PushRun, impulse_along
from app.experiments.protocol import DIRECTIONS, GRAVITY, ProtocolSpec, protocol_jobs
from app.experiments.sweep import run_job
from app.runner import run_closed_loop
from app.scenarios import Scenario
from app.setup.build import build_backend
from planner.exceptions import ParameterError
from planner.types import Push


def check_timing(spec: ProtocolSpec, tolerance: float) -> None:
    """Run the inward and outward jobs of ``spec`` (a coarse bisection) and check, on a
    run with a tiny push at each record's start, s~, the stance foot and the push's
    side: inward at single-support start + half the swing towards the stance foot,
    outward at double-support start + half of it away from it, left stance."""
    sweep = replace(spec.sweep_spec(), tolerance=tolerance)
    jobs = protocol_jobs(sweep)
    assert [round(math.degrees(j.angle)) for j in jobs] == [0, 180, 90, 270]
    assert jobs[0].phase == jobs[1].phase == jobs[2].phase != jobs[3].phase
    backend, config, initial = build_backend(spec.model, spec.robot, "rsg", reality=spec.reality)
    gait = config.gait
    expected = {
        "inward": gait.double_support_duration + gait.single_support_duration / 2,
        "outward": gait.double_support_duration / 2,
    }
    records = {name: run_job(sweep, jobs[i]) for i, name in ((2, "inward"), (3, "outward"))}
    pushes = [
        Push(records[n]["push_time"], 0.01 * impulse_along(records[n]["direction_deg"], 1.0), 0.1)
        for n in ("inward", "outward")
    ]
    scenario = Scenario("protocol", records["inward"]["push_time"] + 0.3, tuple(pushes))
    try:
        result = run_closed_loop(backend, config, scenario, initial, qp_solver="exact")
    finally:
        backend.close()
    time = result.column("t")
    pushing = np.hypot(result.column("push_fx"), result.column("push_fy")) > 0.0
    for name, record in records.items():
        start = record["push_time"]
        tick = int(np.argmin(np.abs(time - start)))
        since = result.column("time_since_step")[tick]
        assert since == pytest.approx(expected[name], abs=1.5 * backend.control_period), name
        assert (since < gait.double_support_duration) == (name == "outward"), name
        assert result.column("stance_sigma")[tick] == 1.0, name
        towards_stance = result.column("foot_y")[tick] - result.column("com_y")[tick]
        lateral = math.sin(math.radians(record["direction_deg"]))
        assert lateral * towards_stance * (1 if name == "inward" else -1) > 0.0, name
        window = time[pushing & (np.abs(time - start - 0.05) < 0.1)]
        assert window.min() == pytest.approx(start, abs=backend.control_period + 1e-6), name
        assert window.max() == pytest.approx(start + 0.1, abs=backend.control_period + 1e-6)


@pytest.mark.parametrize("robot", ["g1", None])
def test_pushes_start_at_mid_swing_and_mid_double_support(robot: str | None) -> None:
    """On the LIPM, where each step lands 2 ms after its nominal time (7 ms by the push)."""
    check_timing(ProtocolSpec(model="lipm", robot=robot), tolerance=0.5)


@pytest.mark.slow
def test_pushes_start_at_mid_swing_and_mid_double_support_on_g1() -> None:
    """On G1 in PyBullet (exact sensors: the bisection's runs and the check's walk the same)."""
    check_timing(ProtocolSpec(model="pybullet", reality="ideal"), tolerance=0.5)


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
