"""``rsg grid``: command-line options and the command (see :mod:`app.experiments.grid`)."""

from __future__ import annotations

import argparse
import time

from app.commands.arguments import (
    add_command,
    add_controllers,
    add_decimal,
    add_model_and_robot,
    add_out_arguments,
    add_paper_rules,
    add_set_argument,
    add_workers,
    decimals_argument,
    job_workers,
    spec_from_args,
)
from app.experiments.grid import GridSpec, format_grid, run_grid, write_grid
from app.experiments.plots import plot_grid
from app.experiments.sweep import SWEEP_CONTROLLERS
from app.results.folder import prepare_out, report_files
from app.results.worst_runs import (
    add_replays_argument,
    format_replays,
    worst_grid_runs,
    write_worst_replays,
)

HELP = "push grid: every controller against the same fixed pushes, one run each"
DESCRIPTION = (
    "Run each controller once per push impulse, direction and phase and "
    "report recovered / survived / fell: a comparison that, unlike the sweep's "
    "bisection, does not assume recovery is monotonic in the impulse."
)
EPILOG = """\
examples:
  rsg grid --out results/grid-g1          # G1: rsg, fixed-timing, no-step; 4,6,8,10 N s; 8 dirs
  rsg grid --phases 0.25 --controllers rsg --out results/grid-g1-early
  rsg grid --controllers rsg --set swing_preparation_time=0.3 --out results/grid-g1-tsp03
  rsg grid --model lipm --impulses 20,40,60 --directions 16 --out results/grid-lipm
  rsg grid --model mujoco --controllers rsg --out results/grid-g1-mujoco   # G1 on MuJoCo

outputs in --out:
  grid.json   the specification, counts per controller, phase and impulse, every run
  grid.csv    one row per run: controller, phase, direction, impulse, outcome, ...
  grid.png    outcome per impulse and direction, one panel per controller and phase
  replays/*/  the worst failed runs per controller: rsg replay FOLDER
"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg grid`` to the subcommands."""
    p = add_command(sub, "grid", HELP, DESCRIPTION, EPILOG)
    add_model_and_robot(p, "pybullet")
    add_controllers(p, SWEEP_CONTROLLERS, "rsg,fixed-timing,no-step")
    p.add_argument(
        "--impulses",
        type=decimals_argument("--impulses", "4,6,8"),
        default=(4.0, 6.0, 8.0, 10.0),
        help="push impulses [N s] (default 4,6,8,10)",
    )
    p.add_argument("--directions", type=int, default=8, help="push directions (default 8)")
    p.add_argument(
        "--phases",
        type=decimals_argument("--phases", "0,0.25,0.5"),
        default=(0.5625,),
        help="push phases, fractions of the walking cycle (default 0.5625: mid single support)",
    )
    add_decimal(p, "--duration", 0.1, "push duration [s] (0.1)")
    add_decimal(
        p,
        "--settle",
        GridSpec.settle,
        "time after the push [s] (8: on G1 many runs still standing at 4 s fall later)",
    )
    add_paper_rules(p)
    add_workers(p, backends=False)
    add_out_arguments(p)
    add_set_argument(p)
    p.add_argument("--no-plots", action="store_true", help="skip grid.png")
    add_replays_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def run(args: argparse.Namespace) -> int:
    """Run ``rsg grid``; returns 0."""
    spec = spec_from_args(GridSpec, args)
    workers = job_workers(args, spec)
    for path in prepare_out(args.out, "grid", args.overwrite):
        print(f"deleted {path} (--overwrite)")
    started = time.perf_counter()
    records = run_grid(spec, workers, progress=not args.quiet)
    worst = worst_grid_runs(records, args.replays)
    if worst and not args.quiet:
        print(f"grid: simulating the {len(worst)} worst failed runs again to replay them ...")
    replays = write_worst_replays(spec, worst, args.out)
    wall_time = time.perf_counter() - started
    paths = write_grid(args.out, spec, records, wall_time, replays)
    if not args.no_plots:
        paths.append(plot_grid(spec, records, args.out / "grid.png"))
    report_files(paths)
    print(format_grid(spec, records))
    print(format_replays(replays))
    print(f"grid: {len(records)} runs, {wall_time:.0f} s wall time")
    return 0
