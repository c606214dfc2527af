"""``rsg pushes``: command-line options and the command (see :mod:`app.experiments.campaign`)."""

from __future__ import annotations

import argparse
import time

from app.commands.arguments import (
    add_command,
    add_controllers,
    add_job_options,
    add_model_and_robot,
    decimals_argument,
    job_run,
    spec_from_args,
)
from app.experiments.campaign import SEEDS, CampaignSpec, campaign_jobs, parse_seed, run_campaign
from app.experiments.campaign_report import format_summary, push_rows, summarize, write_campaign
from app.experiments.plots import plot_campaign
from app.experiments.sweep import SWEEP_CONTROLLERS
from app.results.folder import report_files
from planner.exceptions import RsgError

HELP = "push campaign: random pushes over a whole gait cycle, each beside its LIPM twin"
DESCRIPTION = (
    "Draw N random pushes from a seed (direction uniform, start time uniform "
    "over one gait cycle after a settled walk, impulse and duration uniform in ranges), run "
    "each with every controller and on the LIPM with the same robot's planner (the twin), "
    "and report recovered / survived / fell, adjusted steps and steps to settle."
)
EPILOG = """\
examples:
  rsg pushes --seed dev --out results/pushes-g1-dev          # G1: 100 pushes, rsg and no-step
  rsg pushes --seed eval --out results/pushes-g1-eval        # reported figures only
  rsg pushes --robot talos --controllers rsg --pushes 24 --seed eval --out results/talos
  rsg pushes --model lipm --robot g1 --pushes 200 --out results/pushes-g1-lipm
  rsg pushes --model mujoco --seed dev --out results/pushes-g1-mujoco   # G1 on MuJoCo

seeds: dev (= 1) for development and tuning, eval (= 2) for reported figures only.

outputs in --out:
  campaign.json    specification, definitions, summary per controller, every push
  campaign.csv     one row per push: draw, velocity change, per controller and twin:
                   outcome, fall reason, adjusted steps, steps until V_u < gamma_v
  campaign.png     outcome by direction (angle) and phase (radius), robot and twin
  jobs.jsonl, campaign_spec.json   finished runs; the same command again resumes
"""


def _seed(text: str) -> int:
    try:
        return parse_seed(text)
    except RsgError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg pushes`` to the subcommands."""
    p = add_command(sub, "pushes", HELP, DESCRIPTION, EPILOG)
    add_model_and_robot(p, "pybullet")
    add_controllers(p, SWEEP_CONTROLLERS, "rsg,no-step")
    p.add_argument(
        "--pushes", type=int, default=CampaignSpec.pushes, help="number of pushes (default 100)"
    )
    p.add_argument(
        "--seed",
        type=_seed,
        default=SEEDS["dev"],
        metavar="dev|eval|N",
        help="seed of the draws: dev (1, default) to develop, eval (2) to report",
    )
    p.add_argument(
        "--impulse",
        type=decimals_argument("--impulse", "5,10", count=2),
        default=None,
        metavar="LOW,HIGH",
        help="impulse range [N s] (default 5,10 on G1, times m / 33.3 kg on other robots)",
    )
    p.add_argument(
        "--duration",
        type=decimals_argument("--duration", "0.05,0.2", count=2),
        default=CampaignSpec.duration,
        metavar="LOW,HIGH",
        help="push duration range [s] (default 0.05,0.2)",
    )
    p.add_argument(
        "--cycle",
        type=int,
        default=CampaignSpec.cycle,
        help="the push starts after the touchdown of this step (default 4: 3.1 s on G1)",
    )
    p.add_argument(
        "--settle",
        type=float,
        default=CampaignSpec.settle,
        help="simulated time after the push start [s] (default 8)",
    )
    p.add_argument("--no-plots", action="store_true", help="skip campaign.png")
    add_job_options(p)


def run(args: argparse.Namespace) -> int:
    """Run ``rsg pushes``; returns 0."""
    spec = spec_from_args(CampaignSpec, args)
    run_as = job_run(args, spec)
    started = time.perf_counter()
    pushes, records = run_campaign(spec, run_as)
    wall_time = time.perf_counter() - started
    rows = push_rows(spec, pushes, records)
    summary = summarize(spec, rows)
    paths = write_campaign(args.out, spec, rows, summary, wall_time)
    if not args.no_plots:
        paths.append(plot_campaign(spec, rows, args.out / "campaign.png"))
    report_files(paths)
    print(format_summary(spec, summary))
    print(f"pushes: {len(campaign_jobs(spec))} runs, {wall_time:.0f} s wall time")
    return 0
