"""``rsg sweep``: command-line options and the command (see :mod:`app.experiments.sweep`)."""

from __future__ import annotations

import argparse
import time

from app.commands.arguments import (
    add_command,
    add_decimal,
    add_job_options,
    add_model_and_robot,
    csv_names,
    decimals_argument,
    job_run,
    spec_from_args,
)
from app.experiments.envelope import build_envelope, format_table, write_envelope
from app.experiments.plots import plot_envelope
from app.experiments.sweep import PLACO_WPG, SweepSpec, run_sweep
from app.results.folder import report_files
from app.results.worst_runs import (
    add_replays_argument,
    format_replays,
    worst_sweep_runs,
    write_worst_replays,
)
from app.setup.overrides import is_robot_model
from planner.parameters import CONTROLLERS

HELP = "robustness map: largest recovered impulse per controller, direction and phase"
DESCRIPTION = (
    "Bisect, for each controller, push direction and push phase, the largest "
    "impulse that is still recovered, next to the capture bound (an upper limit for any "
    "controller on the LIPM)."
)
EPILOG = """\
examples:
  rsg sweep --model lipm --directions 16 --out results/sweep
  rsg sweep --model lipm --controllers rsg,no-step --phases 0.5 --directions 8 --out /tmp/s
  rsg sweep --model pybullet --controllers rsg,placo-wpg --directions 4 --phases 0.25 --out r
  rsg sweep --model mujoco --controllers rsg --directions 4 --phases 0.25 --out results/s-mj
  rsg sweep --backend ray --workers 64 --out results/sweep   # on a Ray cluster (RAY_ADDRESS)
  rsg sweep --model lipm --directions 8 --out results/sweep --monotonicity  # then 1/4, 1/2, 3/4

outputs in --out:
  envelope.json, envelope.csv  largest recovered impulse and the bound per controller,
                               direction and phase
  envelope.png                 polar plot, one panel per phase
  jobs.jsonl, sweep_spec.json  finished jobs; running again on --out resumes (the same
                               settings; --overwrite starts over)
  replays/*/                   the worst failed runs per controller: rsg replay FOLDER
  monotonicity.json            with --monotonicity: runs at 0.25, 0.5, 0.75 of each largest
                               recovered impulse that fail the criterion (in monotonicity/)
"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg sweep`` to the subcommands."""
    p = add_command(sub, "sweep", HELP, DESCRIPTION, EPILOG)
    add_model_and_robot(p, "lipm")
    p.add_argument(
        "--controllers",
        type=csv_names,
        default=None,
        help=f"comma-separated, of {', '.join((*CONTROLLERS, PLACO_WPG))} (default: all that "
        "fit the model; placo-wpg needs a full-robot model)",
    )
    p.add_argument("--directions", type=int, default=16, help="push directions (default 16)")
    p.add_argument(
        "--phases",
        type=decimals_argument("--phases", "0,0.25,0.5"),
        default=(0.0, 0.25, 0.5, 0.75),
        help="push phases, fractions of the walking cycle (default 0,0.25,0.5,0.75)",
    )
    add_decimal(p, "--duration", 0.1, "push duration [s] (0.1)")
    p.add_argument("--cycle", type=int, default=3, help="walking cycle of the push (3)")
    add_decimal(p, "--settle", 6.0, "time after the push [s] (6)")
    add_decimal(p, "--tolerance", 0.25, "bisection [N s] (0.25)")
    p.add_argument(
        "--criterion",
        choices=("recovered", "no-fall"),
        default=None,
        help="recovered (lipm default) or no-fall (pybullet and mujoco default)",
    )
    p.add_argument(
        "--monotonicity",
        action="store_true",
        help="after the sweep, run each largest recovered impulse again at 0.25, 0.5 and "
        "0.75 of it and count the runs that fail the criterion",
    )
    add_replays_argument(p)
    add_job_options(p)


def run(args: argparse.Namespace) -> int:
    """Run ``rsg sweep``; returns 0."""
    controllers = args.controllers
    if controllers is None:
        with_wpg = is_robot_model(args.model)
        controllers = CONTROLLERS + ((PLACO_WPG,) if with_wpg else ())
    criterion = args.criterion or ("recovered" if args.model == "lipm" else "no-fall")
    spec = spec_from_args(SweepSpec, args, controllers=tuple(controllers), criterion=criterion)
    run_as = job_run(args, spec)
    started = time.perf_counter()
    records = run_sweep(spec, run_as)
    envelope = build_envelope(spec, records)
    worst = worst_sweep_runs(records, args.replays)
    if worst and not args.quiet:
        print(f"sweep: simulating the {len(worst)} worst failed runs again to replay them ...")
    envelope["replays"] = write_worst_replays(spec, worst, args.out)
    envelope["wall_time"] = time.perf_counter() - started
    paths = write_envelope(args.out, envelope)
    paths.append(plot_envelope(envelope, args.out / "envelope.png"))
    report_files(paths)
    print(format_table(envelope))
    print(format_replays(envelope["replays"]))
    print(f"sweep: {len(records)} jobs, {envelope['wall_time']:.0f} s wall time")
    if args.monotonicity:
        from app.experiments.monotonicity import (
            format_monotonicity,
            run_monotonicity,
            write_monotonicity,
        )

        report = run_monotonicity(spec, records, run_as)
        print(f"wrote {write_monotonicity(args.out, report)}")
        print(format_monotonicity(report))
    return 0
