"""``rsg sweep --monotonicity``: does a fraction of the largest recovered impulse recover?

The sweep's bisection assumes recovery is monotone in the impulse. For each of its
jobs with a largest recovered impulse I > 0 (controller, direction, phase), this runs
the same push (same start and duration) with 0.25 I, 0.5 I and 0.75 I, once each, and
counts those that fail the sweep's criterion (``recovered``: not
:attr:`app.runner.RunResult.recovered`; ``no-fall``: fell). A count above zero is a
push weaker than one the sweep reports recovered that is not: the envelope
overstates that controller there.

Runs are recorded in ``monotonicity/jobs.jsonl`` under the sweep's folder and resume
as the sweep's do.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import replace
from pathlib import Path

from app.experiments.jobs import JobRun, run_resumable
from app.experiments.outcome import PushRun, describe, impulse_along
from app.experiments.sweep import RESULT_FIELDS, SPEC_FILE, SweepSpec, result_fields
from planner.exceptions import RsgError
from planner.types import Push

FRACTIONS = (0.25, 0.5, 0.75)
FOLDER = "monotonicity"


def check_key(record: dict, fraction: float) -> str:
    return f"{record['key']}|{fraction:g}"


def run_check(spec: SweepSpec, record: dict, fraction: float) -> dict:
    """One push of ``fraction`` times the job ``record``'s largest recovered impulse."""
    started = time.perf_counter()
    impulse = fraction * record["impulse"]
    push = Push(record["push_time"], impulse_along(record["direction_deg"], impulse), spec.duration)
    seed = record.get("reality_seed", 0)  # the bisection's robot (0: a folder of before)
    result = PushRun(spec, record["controller"], seed).run(push, push.time + spec.settle)
    figures = describe(result, push, record["controller"])
    passed = figures["outcome"] == "recovered" or (
        spec.criterion == "no-fall" and figures["outcome"] != "fell"
    )
    return {
        "key": check_key(record, fraction),
        "controller": record["controller"],
        "direction_deg": record["direction_deg"],
        "phase": record["phase"],
        "fraction": fraction,
        "largest_impulse": record["impulse"],
        "impulse": impulse,
        "passed": passed,
        **figures,
        "wall_time": time.perf_counter() - started,
    }


def _run_check_args(args: tuple[SweepSpec, dict, float]) -> dict:
    return run_check(*args)


def run_monotonicity(spec: SweepSpec, records: list[dict], run: JobRun) -> dict:
    """Run (or resume) the checks of the sweep ``records`` into ``run.out / monotonicity``;
    returns the report (:func:`summarize`)."""
    arguments = {
        check_key(record, fraction): (spec, record, fraction)
        for record in records
        if record["impulse"] > 0.0
        for fraction in FRACTIONS
    }
    into = replace(run, out=run.out / FOLDER)
    fields = result_fields(RESULT_FIELDS, spec)
    done = run_resumable(
        _run_check_args, arguments, spec, fields, SPEC_FILE, into, "monotonicity", "runs"
    )
    return summarize(spec, [done[key] for key in arguments])


def summarize(spec: SweepSpec, checks: list[dict]) -> dict:
    """Per controller: runs, how many failed the criterion, and those runs."""
    controllers = {}
    for controller in spec.controllers:
        mine = [c for c in checks if c["controller"] == controller]
        failed = [c for c in mine if not c["passed"]]
        controllers[controller] = {
            "runs": len(mine),
            "not_passed": len(failed),
            "per_fraction": {
                f"{f:g}": sum(not c["passed"] for c in mine if math.isclose(c["fraction"], f))
                for f in FRACTIONS
            },
            "failed": [
                {
                    k: c[k]
                    for k in (
                        "direction_deg",
                        "phase",
                        "fraction",
                        "impulse",
                        "largest_impulse",
                        "outcome",
                        "fall_reason",
                    )
                }  # fmt: skip
                for c in failed
            ],
        }
    return {
        "criterion": spec.criterion,
        "fractions": FRACTIONS,
        "note": "each job's largest recovered impulse I > 0 run again at these fractions of "
        "I; not_passed counts the runs that fail the sweep's criterion",
        "controllers": controllers,
    }


def write_monotonicity(out: Path, report: dict) -> Path:
    """``monotonicity.json`` in ``out``; returns its path.

    Raises:
        RsgError: If it cannot be written.
    """
    path = out / "monotonicity.json"
    try:
        path.write_text(json.dumps(report, indent=2) + "\n")
    except OSError as exc:
        raise RsgError(f"cannot write {path}: {exc}") from exc
    return path


def format_monotonicity(report: dict) -> str:
    """One line per controller: runs not passed, per fraction."""
    word = "not recovered" if report["criterion"] == "recovered" else "fell"
    lines = [f"monotonicity (0.25, 0.5, 0.75 of each largest recovered impulse): {word}"]
    for controller, part in report["controllers"].items():
        per = ", ".join(f"{n} at {f}" for f, n in part["per_fraction"].items())
        lines.append(f"{controller:<13} {part['not_passed']}/{part['runs']} ({per})")
    return "\n".join(lines)
