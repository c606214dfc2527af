"""rsg bench: statistics, the timing wrapper, the step QP comparison and the table."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from app.cli import main
from app.experiments.bench import bench_rsg_ticks, bench_step_qp, format_bench, stats, timed


def test_stats_and_wrapper() -> None:
    summary = stats([float(v) for v in range(1, 101)])
    assert summary["median"] == pytest.approx(50.5)
    assert summary["p95"] == pytest.approx(95.05)
    assert stats([])["count"] == 0
    sink: list[float] = []
    double = timed(lambda x: 2 * x, sink)
    assert double(3) == 6 and len(sink) == 1 and sink[0] >= 0.0


def test_step_qp_methods_agree_and_exact_is_optimal() -> None:
    report = bench_step_qp(samples=200)
    assert report["qp_proxqp"]["count"] == 200 == report["qp_exact"]["count"]
    assert report["qp_exact_objective_not_worse"]
    assert report["qp_agree_fraction"] > 0.95


def test_rsg_ticks_split_flow_and_jumps() -> None:
    report = bench_rsg_ticks(duration=2.0)
    assert report["rsg_tick"]["count"] + report["rsg_step_tick"]["count"] == 2000
    assert report["rsg_step_tick"]["count"] == 2  # nominal steps at 0.7 s and 1.5 s


def test_bench_command_writes_json(tmp_path: Path, capsys: pytest.CaptureFixture) -> None:
    assert main(["bench", "--no-robot", "--samples", "50", "--out", str(tmp_path)]) == 0
    report = json.loads((tmp_path / "bench.json").read_text())
    assert report["qp_exact"]["count"] == 50
    assert "planner tick" in capsys.readouterr().out
    assert "| IK solve |" in format_bench(report)


def test_bench_times_the_robot_it_is_given_with_set(
    tmp_path: Path, capsys: pytest.CaptureFixture
) -> None:
    """``rsg bench --set locked_joints=none --set physics_time_step=0.0005`` times G1
    with all 29 joints in the physics at 2 kHz; the default has the description's
    locked joints welded (fewer motors) at 1 kHz, and the table says which step;
    a bad value is an error naming the field before anything runs."""
    from app.experiments.bench import bench_robot

    counts, steps, labels = [], [], []
    for overrides in ((), (("locked_joints", "none"), ("physics_time_step", "0.0005"))):
        report = bench_robot("g1", 0.05, overrides=overrides)
        assert report["simulated"] == pytest.approx(0.05) and not report["fell"]
        counts.append(report["motors"])
        steps.append(report["physics_time_step"])
        labels.append([line for line in format_bench(report).splitlines() if "physics" in line])
    assert counts == [19, 29] and steps == [0.001, 0.0005]
    assert labels[0][0].startswith("| physics step (1 ms) |")
    assert labels[1][0].startswith("| physics step (0.5 ms) |")
    assert main(["bench", "--set", "solver_iterations=0", "--out", str(tmp_path)]) == 2
    assert "solver_iterations" in capsys.readouterr().err
    assert not (tmp_path / "bench.json").exists()


def test_tick_breakdown_adds_up_the_parts() -> None:
    """The controller's time less the IK's is the stabilizer's; the parts add up."""
    from app.experiments.bench import tick_breakdown

    report = {
        "control_period": 0.01,
        "real_time_factor": 2.0,
        "robot_planner_tick": stats([1e-4, 1e-4]),
        "ik": stats([2e-4, 2e-4]),
        "backend_timers_mean_per_tick": {"physics": 4e-3, "estimation": 1e-4, "control": 5e-4},
    }
    line = tick_breakdown(report)
    assert "physics and motors 4.00 ms" in line and "RSG 0.10 ms" in line
    assert "IK 0.20 ms" in line and "stabilizer, swing foot, feed-forward 0.30 ms" in line
    assert "measurement and estimation 0.10 ms" in line
    assert "total 4.70 ms" in line and "real-time factor 2.00" in line
