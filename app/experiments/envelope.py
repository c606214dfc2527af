"""The robustness envelope of a sweep: ``envelope.json``, ``envelope.csv`` and its table."""

from __future__ import annotations

import csv
import json
import math
from dataclasses import asdict
from pathlib import Path

import numpy as np

from app.experiments.sweep import SweepSpec
from planner.exceptions import RsgError

CSV_COLUMNS = ("controller", "phase", "direction_deg", "impulse", "bound", "ratio", "capped",
               "runs", "stance", "push_time")  # fmt: skip

BOUND_NOTE = (
    "bound: an upper limit on the impulse [N s] along the direction that any controller "
    "can capture on the LIPM with the controller's CMP window (ZMP window + hdot_max/(m g), "
    "both feet in double support), step bounds, crossing constraint (27b), minimum step "
    "time T_DSP + T_SP and the 0.6 m leg reach, stepping during the push if that helps "
    "and knowing the push in advance (app/experiments/capturability.py, docs/bound.md)"
)


def build_envelope(spec: SweepSpec, records: list[dict]) -> dict:
    """Per controller and phase: directions, largest recovered impulse, bound, ratio.

    Args:
        spec: The sweep.
        records: One record per job (:func:`app.experiments.sweep.run_job`).
    """
    controllers: dict[str, dict] = {}
    for controller in spec.controllers:
        mine = [r for r in records if r["controller"] == controller]
        phases = {}
        for phase in spec.phases:
            rows = sorted(
                (r for r in mine if abs(r["phase"] - phase) < 1e-9),
                key=lambda r: r["direction_deg"],
            )
            phases[f"{phase:g}"] = [
                {k: r[k] for k in CSV_COLUMNS if k not in ("controller", "phase")} for r in rows
            ]
        ratios = [r["ratio"] for r in mine if math.isfinite(r["ratio"])]
        controllers[controller] = {
            "mean_ratio": float(np.mean(ratios)) if ratios else None,
            "min_ratio": float(np.min(ratios)) if ratios else None,
            "mean_impulse": float(np.mean([r["impulse"] for r in mine])) if mine else None,
            "phases": phases,
        }
    return {
        "spec": asdict(spec),
        "units": {"impulse": "N s", "bound": "N s", "direction_deg": "deg", "phase": "-"},
        "bound_note": BOUND_NOTE,
        "phase_note": (
            f"push starts at s~ = phase * T^* after nominal step {spec.cycle} "
            "(t = T_SSP + (cycle - 1) T^* + phase T^*)"
        ),
        "controllers": controllers,
    }


def write_envelope(out: Path, envelope: dict) -> list[Path]:
    """Write ``envelope.json`` and ``envelope.csv`` into ``out``; returns their paths.

    Raises:
        RsgError: If they cannot be written.
    """
    json_path, csv_path = out / "envelope.json", out / "envelope.csv"
    try:
        json_path.write_text(json.dumps(envelope, indent=2) + "\n")
        with csv_path.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(CSV_COLUMNS)
            for controller, data in envelope["controllers"].items():
                for phase, rows in data["phases"].items():
                    for row in rows:
                        writer.writerow(
                            [controller, phase, *(_fmt(row[c]) for c in CSV_COLUMNS[2:])]
                        )
    except OSError as exc:
        raise RsgError(f"cannot write the envelope to {out}: {exc}") from exc
    return [json_path, csv_path]


def _fmt(value: object) -> object:
    return f"{value:.4g}" if isinstance(value, float) else value


def format_table(envelope: dict) -> str:
    """Each controller's mean and smallest ratio to the bound, and its mean impulse."""
    lines = [
        f"{'controller':<14} {'mean ratio':>10} {'min ratio':>10} {'mean impulse [N s]':>19}",
    ]
    for controller, data in envelope["controllers"].items():
        mean, low, impulse = data["mean_ratio"], data["min_ratio"], data["mean_impulse"]
        lines.append(
            f"{controller:<14} {_num(mean, '.3f'):>10} {_num(low, '.3f'):>10} "
            f"{_num(impulse, '.1f'):>19}"
        )
    return "\n".join(lines)


def _num(value: float | None, spec: str) -> str:
    return "-" if value is None else format(value, spec)
