"""Keep the worst runs of a sweep or a push grid replayable (``rsg replay``).

Per controller, the :data:`WORST_PER_CONTROLLER` failed runs with the smallest
impulse relative to the push's capture bound (a failure on a push the LIPM could
recover is the one to look at; a fall before a mere "not recovered"):

- push grid: runs that fell or were not recovered;
- sweep: per job, the run at the smallest impulse that failed (the bisection's
  upper end), for jobs that found one.

Runs are deterministic (the full robot's reality is drawn again from the record's
``reality_seed``), so each chosen run is simulated again once with a
:class:`app.results.replay.ReplayRecorder` (a few runs, against the hundreds of the sweep)
and written to ``OUT/replays/<controller>-<direction>deg-phase<p>-<impulse>Ns/``:
``replay.npz`` and ``summary.json``.
"""

from __future__ import annotations

import argparse
import json
import math
from pathlib import Path
from typing import Any

import numpy as np

from app.experiments.sweep import build_controller
from app.experiments.trial import push_timing
from app.results.replay import ReplayRecorder
from app.results.run_files import summary_of
from app.runner import run_closed_loop
from app.scenarios import Scenario
from app.setup.build import backend_reality
from app.setup.overrides import is_robot_model
from planner.exceptions import RsgError
from planner.types import Push

WORST_PER_CONTROLLER = 3
REPLAYS_DIR = "replays"


def add_replays_argument(parser: argparse.ArgumentParser) -> None:
    """``--replays N``: how many failed runs per controller to keep replayable."""
    parser.add_argument(
        "--replays",
        type=_count,
        default=WORST_PER_CONTROLLER,
        metavar="N",
        help=f"keep the N worst failed runs per controller replayable in OUT/{REPLAYS_DIR} "
        f"(rsg replay; 0: none) (default {WORST_PER_CONTROLLER})",
    )


def _count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        value = -1
    if not 0 <= value <= 100:
        raise argparse.ArgumentTypeError(f"--replays={text!r}: expected an integer in [0, 100]")
    return value


def format_replays(replays: list[dict]) -> str:
    """Where the replays are, one line each."""
    if not replays:
        return "no failed run to replay"
    lines = ["replays of the worst failed runs (rsg replay FOLDER):"]
    for r in replays:
        lines.append(
            f"  {r['controller']:<13} {r['direction_deg']:5.1f} deg phase {r['phase']:g} "
            f"{r['impulse']:.2f} N s {r['outcome']:<9} {r['folder']}"
        )
    return "\n".join(lines)


def worst_grid_runs(records: list[dict], count: int = WORST_PER_CONTROLLER) -> list[dict]:
    """The grid's worst failed runs per controller (see the module docstring)."""
    failed = [{**r, "bound": r["capture_bound"]} for r in records if r["outcome"] != "recovered"]
    return _worst(failed, count)


def worst_sweep_runs(records: list[dict], count: int = WORST_PER_CONTROLLER) -> list[dict]:
    """The sweep's worst failed runs per controller: each job's smallest failing impulse."""
    failed = [
        {**r, "impulse": r["failed_at"], "outcome": "not recovered"}
        for r in records
        if r.get("failed_at") is not None
    ]
    return _worst(failed, count)


def _worst(failed: list[dict], count: int) -> list[dict]:
    def severity(record: dict) -> tuple[int, float]:
        ratio = record["impulse"] / record["bound"] if record["bound"] > 0 else math.inf
        return (0 if record["outcome"] == "fell" else 1, ratio)

    chosen: list[dict] = []
    for controller in dict.fromkeys(r["controller"] for r in failed):
        ranked = sorted((r for r in failed if r["controller"] == controller), key=severity)
        chosen += ranked[:count]
    return chosen


def replay_name(record: dict) -> str:
    """Folder name of a run: controller, direction, phase and impulse."""
    return (
        f"{record['controller']}-{record['direction_deg']:03.0f}deg-"
        f"phase{record['phase']:g}-{record['impulse']:.2f}Ns"
    )


def write_worst_replays(spec: Any, runs: list[dict], out: Path) -> list[dict]:
    """Simulate ``runs`` again with a recorder; write their replays under ``out/replays``.

    Args:
        spec: The sweep's or grid's specification (model, robot, cycle, duration,
            settle, overrides, ...).
        runs: From :func:`worst_grid_runs` or :func:`worst_sweep_runs`.
        out: The sweep's or grid's folder.

    Returns:
        One entry per run: controller, direction_deg, phase, impulse [N s], outcome
        of the replayed run, and its folder.

    Raises:
        RsgError: A folder cannot be written.
    """
    written = []
    for record in runs:
        seed = record.get("reality_seed", 0)  # the run's robot (0: a folder of before)
        backend, config, initial, planner = build_controller(spec, record["controller"], seed)
        options = {} if planner is None else {"planner": planner}
        recorder = ReplayRecorder()
        try:
            t_push, _, _ = push_timing(config, spec.cycle, record["phase"])
            angle = math.radians(record["direction_deg"])
            impulse = record["impulse"] * np.array([math.cos(angle), math.sin(angle)])
            push = Push(t_push, impulse, spec.duration)
            scenario = Scenario(replay_name(record), t_push + spec.settle, (push,))
            solver = getattr(spec, "qp_solver", "exact")
            result = run_closed_loop(
                backend, config, scenario, initial, qp_solver=solver, on_tick=recorder, **options
            )
        finally:
            backend.close()
        result.extra["reality"] = spec.reality
        result.extra["reality_seed"] = seed
        draw = backend_reality(backend, spec.reality, seed) if is_robot_model(spec.model) else None
        if draw is not None:
            result.extra["reality_draw"] = draw.as_dict()
        folder = out / REPLAYS_DIR / replay_name(record)
        recorder.write(result, record["controller"], spec.robot, folder)
        try:
            summary = summary_of(result, record["controller"])
            (folder / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        except OSError as exc:
            raise RsgError(f"cannot write {folder / 'summary.json'}: {exc}") from exc
        outcome = "fell" if result.fall.fell else ("recovered" if result.recovered else "survived")
        entry = {
            "controller": record["controller"],
            "direction_deg": record["direction_deg"],
            "phase": record["phase"],
            "impulse": record["impulse"],
            "outcome": outcome,
            "folder": str(folder),
        }
        written.append(entry)
    return written
