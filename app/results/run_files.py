"""Writing a run's results: summary.json, timeseries.csv and the Fig. 6 plots."""

from __future__ import annotations

import json
import math
from pathlib import Path

import numpy as np

from app.runner import TIMESERIES_COLUMNS, RunResult
from app.scenarios import delivered_fraction
from planner.exceptions import RsgError


def pushes_of(result: RunResult) -> tuple[list[dict], list[dict]]:
    """The scenario's pushes split into those that acted with their whole impulse and
    those that did not: cut short by a fall or an interruption (with the impulse they
    did deliver), or left out by ``--duration`` (``extra["pushes_left_out"]``)."""
    applied, cut = [], []
    end = result.sim_time
    if result.interrupted:
        why = f"the run was interrupted at t={end:g} s"
    else:
        why = f"the run ended at t={end:g} s ({result.fall.reason or 'fell'})"
    for push in result.scenario.pushes:
        fraction = delivered_fraction(push, end)
        if fraction >= 1.0:
            applied.append(push.as_dict())
        else:
            delivered = [float(v) * fraction for v in push.impulse]
            cut.append({**push.as_dict(), "impulse_applied": delivered, "reason": why})
    for push in result.extra.get("pushes_left_out", ()):
        reason = f"it starts after the end of the run (--duration {result.scenario.duration:g} s)"
        cut.append({**push.as_dict(), "impulse_applied": [0.0, 0.0], "reason": reason})
    return applied, cut


def summary_of(result: RunResult, controller: str) -> dict:
    """The run's summary as a JSON-ready dict (see the README for each field)."""
    config = result.config
    applied, cut = pushes_of(result)
    return {
        "recovered": bool(result.recovered),
        "interrupted": bool(result.interrupted),
        "fell": bool(result.fall.fell),
        "fall_reason": result.fall.reason,
        "model": result.backend,
        "controller": controller,
        "scenario": result.scenario.name,
        "mass": float(result.mass),
        "com_height": float(result.com_height),
        "gamma_v": float(result.lyapunov_threshold),
        "final_lyapunov": result.final_lyapunov,
        "max_lyapunov": result.max_lyapunov,
        "impulse_scale": float(result.impulse_scale),
        "impulse_scale_note": (
            f"impulses scaled by {result.impulse_scale:.4f} = robot mass / "
            f"{result.scenario.reference_mass} kg so the velocity change matches"
            if result.impulse_scale != 1.0
            else ""
        ),
        "pushes": applied,
        "pushes_not_applied": cut,
        "steps": [dict(s.event, step=s.step) for s in result.steps],
        "adjusted_steps": int(sum(s.event["adjusted"] for s in result.steps)),
        "qp_infeasible": int(result.qp_infeasible),
        "constraint_violations": result.constraint_violations,
        "constraint_violations_by_kind": dict(result.violations),
        "sim_time": float(result.sim_time),
        "wall_time": float(result.wall_time),
        "real_time_factor": float(result.sim_time / result.wall_time)
        if result.wall_time > 0
        else None,
        "parameters": {
            "stride_length": config.gait.stride_length,
            "step_width": config.gait.step_width,
            "double_support_duration": config.gait.double_support_duration,
            "single_support_duration": config.gait.single_support_duration,
            "theta": config.rsg.filter_time_constant,
            "mu_1": config.rsg.step_decrease_margin,
            "mu_2": config.rsg.crossing_margin,
            "mu_3": config.rsg.com_margin,
            "swing_preparation_time": config.rsg.swing_preparation_time,
            "step_reaction_time": config.rsg.step_reaction_time,
            "push_hold_time": config.rsg.push_hold_time,
            "dcm_inset": config.rsg.dcm_inset,
            "com_reach": None
            if math.isinf(config.constraints.com_reach)
            else config.constraints.com_reach,
            "zmp_window_min": list(config.constraints.zmp_window_min),
            "zmp_window_max": list(config.constraints.zmp_window_max),
            "angular_momentum_rate_max": config.constraints.angular_momentum_rate_max,
            "step_min": list(config.constraints.step_min),
            "step_max": list(config.constraints.step_max),
            "lyapunov_matrix": result.extra.get("lyapunov_matrix"),
            "feedback_gain": result.extra.get("feedback_gain"),
        },
        **{
            k: v
            for k, v in result.extra.items()
            if k not in ("lyapunov_matrix", "feedback_gain", "pushes_left_out")
        },
    }


def write_results(result: RunResult, controller: str, out_dir: Path, plots: bool = True) -> dict:
    """Write summary.json, timeseries.csv and (optionally, with two ticks or more) PNG
    plots into ``out_dir`` (checked beforehand by :func:`app.results.folder.prepare_out`).

    Returns:
        The summary dict.

    Raises:
        RsgError: If the folder cannot be written.
    """
    try:
        out_dir.mkdir(parents=True, exist_ok=True)
        summary = summary_of(result, controller)
        (out_dir / "summary.json").write_text(json.dumps(summary, indent=2) + "\n")
        np.savetxt(
            out_dir / "timeseries.csv",
            result.timeseries,
            delimiter=",",
            header=",".join(TIMESERIES_COLUMNS),
            comments="",
            fmt="%.6g",
        )
    except OSError as exc:
        raise RsgError(f"cannot write results to {out_dir}: {exc}") from exc
    if plots and len(result.timeseries) >= 2:
        from app.results.fig6_plots import plot_fig6

        plot_fig6(result, out_dir)
    return summary
