"""The push campaign's report: a row per push, the summary, ``campaign.json`` and
``campaign.csv`` (see :mod:`app.experiments.campaign`)."""

from __future__ import annotations

import csv
import json
from dataclasses import asdict
from pathlib import Path

from app.experiments.campaign import CampaignJob, CampaignPush, CampaignSpec, seed_name
from app.experiments.outcome import OUTCOMES, RECOVERED_MEANS
from app.setup.overrides import is_robot_model
from planner.exceptions import RsgError

FIGURES = ("push_time", "outcome", "fall_reason", "adjusted_steps", "settle_steps",
           "stance_offset_y")  # fmt: skip
DEFINITIONS = {
    "phase": "fraction of the gait cycle T^* since the touchdown of step `cycle` in the "
    "unpushed walk (double support below T_DSP / T^*)",
    "delay": "phase T^*: the push starts this long after that touchdown [s]",
    "push_time": "start of the push in that run [s] (its model's touchdown + delay)",
    "velocity_change": "impulse / mass [m/s]",
    "recovered": RECOVERED_MEANS,
    "survived": "no fall within settle after the push start, not recovered",
    "adjusted_steps": "adjusted steps landing at or after the push start",
    "settle_steps": "touchdowns from the push start up to the last instant with V_u >= "
    "gamma_v (0: V_u stayed below; null: V_u not below gamma_v for good by the end)",
    "stance_offset_y": "largest lateral (world y) distance between the CoM and the stance "
    "sole in single support after the push start [m] (null for placo-wpg): on the twin, "
    "how far the plan swings the CoM over the stance leg",
    "twin": "the same push on the LIPM with the robot's planner (--model lipm --robot NAME)",
    "reality": "sensor noise, control delay and model errors of the full robot "
    "(--reality, app/reality.py); a push's row holds the draw all its robot runs met "
    "(null on the LIPM, which stays ideal)",
    "adjusted_step_ratio": "sum of the robot's adjusted steps / the twin's, over all pushes "
    "(_both: over the pushes both recovered)",
}


def push_argument(push: CampaignPush, start: float) -> str:
    """The push, starting at ``start`` [s], as ``rsg run --push T:IX,IY:D``."""
    ix, iy = push.push(start - push.delay).impulse
    return f"{start:.4f}:{ix:.4f},{iy:.4f}:{push.duration:g}"


def push_rows(spec: CampaignSpec, pushes: list[CampaignPush], records: dict[str, dict]) -> list:
    """One row per push: the draw, its velocity change, the ``rsg run --push`` argument
    of the first controller's run and each controller's figures on the robot (``runs``)
    and on the twin (``twins``; on the LIPM, the runs), and the reality drawn for its
    runs on the full robot (``reality``, :meth:`app.reality.RealityDraw.as_dict`)."""
    twin = spec.twin()
    rows = []
    for push in pushes:
        runs = {c: _figures(records, CampaignJob(push.index, c)) for c in spec.controllers}
        if spec.model == "lipm":
            twins = dict(runs)
        else:
            names = twin.controllers if twin is not None else ()
            twins = {c: _figures(records, CampaignJob(push.index, c, twin=True)) for c in names}
        first = runs[spec.controllers[0]]["push_time"]
        # The robot every controller met on this push (None on the LIPM, or a folder of
        # before the reality profiles).
        reality = records[CampaignJob(push.index, spec.controllers[0]).key].get("reality")
        rows.append({**asdict(push), "velocity_change": round(push.impulse / spec.mass, 4),
                     "push": push_argument(push, first), "reality": reality, "runs": runs,
                     "twins": twins})  # fmt: skip
    return rows


def _figures(records: dict[str, dict], job: CampaignJob) -> dict:
    record = records[job.key]
    return {name: record.get(name) for name in FIGURES}  # folders of earlier versions lack some


def summarize(spec: CampaignSpec, rows: list[dict]) -> dict:
    """Per controller: counts and rates of each outcome, the twin's, and the
    adjusted-step ratio robot / twin (over all pushes and over those both recovered)."""
    summary = {}
    for controller in spec.controllers:
        runs = [row["runs"][controller] for row in rows]
        twins = [row["twins"].get(controller) for row in rows]
        part: dict = {"pushes": len(rows)}
        part.update({o: sum(r["outcome"] == o for r in runs) for o in OUTCOMES})
        part["recovery_rate"] = part["recovered"] / len(rows)
        part["survival_rate"] = (part["recovered"] + part["survived"]) / len(rows)
        part["adjusted_steps"] = sum(r["adjusted_steps"] for r in runs)
        if all(t is not None for t in twins):
            both = [(r, t) for r, t in zip(runs, twins, strict=True)
                    if r["outcome"] == t["outcome"] == "recovered"]  # fmt: skip
            part["twin_recovered"] = sum(t["outcome"] == "recovered" for t in twins)
            part["twin_recovery_rate"] = part["twin_recovered"] / len(rows)
            part["twin_adjusted_steps"] = sum(t["adjusted_steps"] for t in twins)
            part["adjusted_step_ratio"] = _ratio(
                part["adjusted_steps"], part["twin_adjusted_steps"]
            )
            part["both_recovered"] = len(both)
            part["adjusted_steps_both"] = sum(r["adjusted_steps"] for r, _ in both)
            part["twin_adjusted_steps_both"] = sum(t["adjusted_steps"] for _, t in both)
            part["adjusted_step_ratio_both"] = _ratio(
                part["adjusted_steps_both"], part["twin_adjusted_steps_both"]
            )
        summary[controller] = part
    return summary


def _ratio(numerator: float, denominator: float) -> float | None:
    return numerator / denominator if denominator else None


def write_campaign(
    out: Path, spec: CampaignSpec, rows: list[dict], summary: dict, wall_time: float
) -> list[Path]:
    """``campaign.json`` (specification, definitions, summary, every push) and
    ``campaign.csv`` (one row per push); returns their paths.

    Raises:
        RsgError: If they cannot be written.
    """
    json_path, csv_path = out / "campaign.json", out / "campaign.csv"
    document = {
        "spec": asdict(spec),
        "seed": seed_name(spec.seed),
        "reality": spec.reality,
        "mass": spec.mass,
        "units": {
            "direction_deg": "deg",
            "phase": "-",
            "delay": "s",
            "push_time": "s",
            "impulse": "N s",
            "duration": "s",
            "velocity_change": "m/s",
            "stance_offset_y": "m",
            "mass": "kg",
        },
        "definitions": DEFINITIONS,
        "summary": summary,
        "pushes": rows,
        "wall_time": wall_time,
    }
    push_columns = ("index", "direction_deg", "phase", "delay", "impulse", "duration",
                    "velocity_change", "push")  # fmt: skip
    twin_names = list(rows[0]["twins"]) if rows else []
    header = [*push_columns]
    header += [f"{c}_{f}" for c in spec.controllers for f in FIGURES]
    header += [f"twin_{c}_{f}" for c in twin_names for f in FIGURES]
    try:
        json_path.write_text(json.dumps(document, indent=2) + "\n")
        with csv_path.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(header)
            for row in rows:
                line = [row[c] for c in push_columns]
                line += [_cell(row["runs"][c][f]) for c in spec.controllers for f in FIGURES]
                line += [_cell(row["twins"][c][f]) for c in twin_names for f in FIGURES]
                writer.writerow(line)
    except OSError as exc:
        raise RsgError(f"cannot write the campaign to {out}: {exc}") from exc
    return [json_path, csv_path]


def _cell(value: object) -> object:
    return "" if value is None else value


def format_summary(spec: CampaignSpec, summary: dict) -> str:
    """The summary as a table: outcomes, the twin's recoveries and the step ratio."""
    low, high = spec.impulse or (0.0, 0.0)
    where = f"{spec.robot or 'the paper point mass'} on {spec.model}"
    if is_robot_model(spec.model):
        where += f" (reality {spec.reality})"
    lines = [
        f"{spec.pushes} pushes, seed {seed_name(spec.seed)}, {where}: {low:g}-{high:g} N s over "
        f"{spec.duration[0]:g}-{spec.duration[1]:g} s, any direction, start uniform over cycle "
        f"{spec.cycle}",
        f"{'controller':<13} {'recovered':>10} {'survived':>9} {'fell':>5} "
        f"{'twin recovered':>15} {'adjusted robot/twin':>20} {'same, both recovered':>21}",
    ]
    for controller, part in summary.items():
        n = part["pushes"]
        twin, ratio, both = "-", "-", "-"
        if "twin_recovered" in part:
            twin = f"{part['twin_recovered']}/{n}"
            ratio = _ratio_text(part["adjusted_steps"], part["twin_adjusted_steps"])
            both = _ratio_text(part["adjusted_steps_both"], part["twin_adjusted_steps_both"])
        lines.append(
            f"{controller:<13} {part['recovered']:>6}/{n:<3} {part['survived']:>9} "
            f"{part['fell']:>5} {twin:>15} {ratio:>20} {both:>21}"
        )
    return "\n".join(lines)


def _ratio_text(robot: int, twin: int) -> str:
    value = _ratio(robot, twin)
    return f"{robot}/{twin}" + (f" = {value:.2f}" if value is not None else "")
