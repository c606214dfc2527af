"""Push grid: every controller against the same fixed pushes, one run each.

The sweep (:mod:`app.experiments.sweep`) bisects the largest recovered impulse per direction,
which assumes recovery is monotonic in the impulse. On the full robot it is not
(G1 at 45 deg, mid single support: 4 and 8 N s survived, 6 and 10 N s fell), so a
bisection can stop at any of several thresholds. The grid runs each
(controller, phase, direction, impulse) once and reports each outcome: recovered,
survived (no fall within ``settle`` after the push start) or fell
(:mod:`app.experiments.outcome`).

Each record also carries the push's capture bound
(:func:`app.experiments.capture_bound.impulse_bound` with the controller's
configuration: the largest impulse in that direction and at that time that any
controller could capture on the LIPM with the robot's ZMP window, step bounds, step
timing and leg reach). A fall above it is a limit of the robot's parameters, not of a
controller; the printed grid writes those outcomes in capitals.

Counts over the grid compare controllers without the monotonicity assumption.

Reality (``--reality``, :mod:`app.reality`): each push (phase, direction, impulse) meets
its own robot, the same for every controller, drawn from
:func:`app.experiments.sweep.push_reality_seed`; its record holds the seed.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import asdict, dataclass
from pathlib import Path

from app.experiments.capture_bound import impulse_bound
from app.experiments.jobs import JobProgress, check_workers, run_in_processes
from app.experiments.outcome import (
    OUTCOMES,
    RECOVERED_MEANS,
    PushRun,
    describe,
    impulse_along,
)
from app.experiments.sweep import PushExperiment, check_pushes, push_reality_seed
from app.experiments.trial import push_timing
from planner.exceptions import ParameterError, RsgError
from planner.types import Push

MAX_IMPULSES = 100


@dataclass(frozen=True)
class GridSpec(PushExperiment):
    """What the grid runs.

    Attributes:
        model, robot, controllers, paper_rules, fall_dcm_error, overrides: As
            :class:`app.experiments.sweep.PushExperiment`'s.
        impulses: Push impulses [N s].
        directions: Number of push directions, evenly spaced from 0 (forward).
        phases: Push phases p in [0, 1) of the walking cycle (as the sweep's).
        duration: Push duration [s].
        cycle: Walking cycle (>= 1) in which the push starts.
        settle: Simulated time after the push start [s].
    """

    model: str = "pybullet"
    controllers: tuple[str, ...] = ("rsg", "fixed-timing", "no-step")
    impulses: tuple[float, ...] = (4.0, 6.0, 8.0, 10.0)
    directions: int = 8
    phases: tuple[float, ...] = (0.5625,)
    duration: float = 0.1
    cycle: int = 3
    settle: float = 8.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_pushes(
            self.model, self.controllers, self.directions, self.phases, self.overrides, self.robot
        )
        if not (
            0 < len(self.impulses) <= MAX_IMPULSES
            and all(math.isfinite(i) and 0.0 < i <= 1000.0 for i in self.impulses)
            and len(set(self.impulses)) == len(self.impulses)
        ):
            raise ParameterError(
                "impulses", self.impulses, f"1 to {MAX_IMPULSES} distinct impulses in (0, 1000] N s"
            )
        if not (math.isfinite(self.duration) and 1e-3 <= self.duration <= 1.0):
            raise ParameterError("duration", self.duration, "a number in [0.001, 1] s")
        if not (math.isfinite(self.settle) and 1.0 <= self.settle <= 60.0):
            raise ParameterError("settle", self.settle, "a number in [1, 60] s")
        if not (isinstance(self.cycle, int) and 1 <= self.cycle <= 20):
            raise ParameterError("cycle", self.cycle, "an integer in [1, 20]")

    def directions_deg(self) -> list[float]:
        """Push directions [deg]."""
        return [360.0 * i / self.directions for i in range(self.directions)]


@dataclass(frozen=True)
class GridJob:
    """One run of the grid."""

    controller: str
    phase: float
    direction_deg: float
    impulse: float


def all_grid_jobs(spec: GridSpec) -> list[GridJob]:
    """Every run, controller by controller."""
    return [
        GridJob(controller, phase, direction, impulse)
        for controller in spec.controllers
        for phase in spec.phases
        for impulse in spec.impulses
        for direction in spec.directions_deg()
    ]


def run_grid_job(spec: GridSpec, job: GridJob) -> dict:
    """One push; returns its JSON-ready record."""
    started = time.perf_counter()
    seed = push_reality_seed(job.direction_deg, job.phase, job.impulse)
    trial = PushRun(spec, job.controller, seed)
    t_push, sigma, since = push_timing(trial.config, spec.cycle, job.phase)
    angle = math.radians(job.direction_deg)
    bound = impulse_bound(trial.config, angle, sigma, since, spec.duration)
    push = Push(t_push, impulse_along(job.direction_deg, job.impulse), spec.duration)
    result = trial.run(push, t_push + spec.settle)
    return {
        **asdict(job),
        **describe(result, push, job.controller),
        "push_time": t_push,
        "stance": "left" if sigma > 0 else "right",
        "capture_bound": bound,
        "reality_seed": seed,
        "wall_time": time.perf_counter() - started,
    }


def _run_grid_job_args(args: tuple[GridSpec, GridJob]) -> dict:
    return run_grid_job(*args)


def run_grid(spec: GridSpec, workers: int = 1, progress: bool = True) -> list[dict]:
    """Run every job of ``spec``; returns the records in :func:`all_grid_jobs` order.

    Raises:
        ParameterError: Bad ``workers``.
    """
    check_workers(workers)
    jobs = all_grid_jobs(spec)
    bar = JobProgress(len(jobs), 0, progress, label="grid", unit="runs")
    records: dict[GridJob, dict] = {}
    arguments = [(spec, job) for job in jobs]
    for (_, job), record in run_in_processes(_run_grid_job_args, arguments, workers):
        records[job] = record
        bar.advance()
    return [records[job] for job in jobs]


def summarize(spec: GridSpec, records: list[dict]) -> dict:
    """Per controller and phase: counts of each outcome, in total and per impulse."""
    summary: dict = {}
    for controller in spec.controllers:
        for phase in spec.phases:
            rows = [r for r in records if r["controller"] == controller and r["phase"] == phase]
            per_impulse = {}
            for impulse in spec.impulses:
                chosen = [r for r in rows if r["impulse"] == impulse]
                per_impulse[f"{impulse:g}"] = _counts(chosen)
            summary.setdefault(controller, {})[f"{phase:g}"] = {
                "total": _counts(rows),
                "per_impulse": per_impulse,
            }
    return summary


def beyond_bound(record: dict) -> bool:
    """The push's impulse is above its capture bound (no stepping controller can
    recover it on the LIPM with the same parameters)."""
    return bool(record["impulse"] > record["capture_bound"])


def _counts(rows: list[dict]) -> dict[str, int]:
    counts = {outcome: sum(r["outcome"] == outcome for r in rows) for outcome in OUTCOMES}
    counts["not_fallen"] = counts["recovered"] + counts["survived"]
    counts["runs"] = len(rows)
    counts["beyond_bound"] = sum(beyond_bound(r) for r in rows)
    return counts


def write_grid(
    out: Path,
    spec: GridSpec,
    records: list[dict],
    wall_time: float,
    replays: list[dict] | None = None,
) -> list[Path]:
    """``grid.json`` (spec, summary, records, replays of the worst runs) and ``grid.csv``
    (one row per run)."""
    try:
        out.mkdir(parents=True, exist_ok=True)
        document = {
            "spec": asdict(spec),
            "outcomes": {
                "recovered": RECOVERED_MEANS,
                "survived": "no fall within settle after the push start",
                "fell": "fell",
            },
            "units": {
                "impulse": "N s",
                "direction_deg": "deg",
                "phase": "-",
                "capture_bound": "N s",
            },
            "summary": summarize(spec, records),
            "records": records,
            "replays": replays or [],
            "wall_time": wall_time,
        }
        json_path = out / "grid.json"
        json_path.write_text(json.dumps(document, indent=2) + "\n")
        csv_path = out / "grid.csv"
        columns = ["controller", "phase", "direction_deg", "impulse", "outcome", "push_time",
                   "stance", "capture_bound", "end_time", "adjusted_steps",
                   "fall_reason"]  # fmt: skip
        lines = [",".join(columns)]
        lines += [",".join(str(r[c]).replace(",", ";") for c in columns) for r in records]
        csv_path.write_text("\n".join(lines) + "\n")
    except OSError as exc:
        raise RsgError(f"cannot write the grid to {out}: {exc}") from exc
    return [json_path, csv_path]


def format_grid(spec: GridSpec, records: list[dict]) -> str:
    """Per controller and phase: not fallen (recovered) per impulse, and a row of symbols
    per impulse over the directions (o recovered, s survived, x fell; in capitals
    when the impulse is above the push's capture bound)."""
    symbol = {"recovered": "o", "survived": "s", "fell": "x"}
    directions = " ".join(f"{d:g}" for d in spec.directions_deg())
    lines = [
        f"outcome per direction ({directions} deg): o recovered, s survived, x fell; "
        "capitals: impulse above the LIPM capture bound (no stepping controller recovers it)"
    ]
    if spec.overrides:
        lines.insert(0, "with " + " ".join(f"--set {n}={v}" for n, v in spec.overrides))
    summary = summarize(spec, records)
    for controller in spec.controllers:
        for phase in spec.phases:
            part = summary[controller][f"{phase:g}"]
            total = part["total"]
            cells = []
            for impulse in spec.impulses:
                rows = [
                    r for r in records
                    if r["controller"] == controller and r["phase"] == phase
                    and r["impulse"] == impulse
                ]  # fmt: skip
                counts = part["per_impulse"][f"{impulse:g}"]
                marks = "".join(
                    symbol[r["outcome"]].upper() if beyond_bound(r) else symbol[r["outcome"]]
                    for r in rows
                )
                cells.append(f"{impulse:g} N s {counts['not_fallen']}/{counts['runs']} [{marks}]")
            beyond = f" ({total['beyond_bound']} above the bound)" if total["beyond_bound"] else ""
            lines.append(
                f"{controller:<13} phase {phase:g}: not fallen {total['not_fallen']}/"
                f"{total['runs']}{beyond}, recovered {total['recovered']}; " + "; ".join(cells)
            )
    return "\n".join(lines)
