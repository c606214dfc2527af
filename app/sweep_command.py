"""``rsg sweep``: command-line options and the command (see :mod:`app.sweep`)."""

from __future__ import annotations

import argparse
import os
import time

from planner.parameters import CONTROLLERS

from .envelope import build_envelope, format_table, write_envelope
from .overrides import add_robot_argument, add_set_argument, decimal_argument, parse_decimal
from .replay_keep import (
    add_replays_argument,
    format_replays,
    worst_sweep_runs,
    write_worst_replays,
)
from .result_folder import add_out_arguments
from .robot_setup import check_robot_overrides
from .setup import PAPER_RULES_HELP
from .sweep import PLACO_WPG, SweepSpec, check_workers, run_sweep
from .sweep_plot import plot_envelope

EPILOG = """\
examples:
  rsg sweep --model lipm --directions 16 --out results/sweep
  rsg sweep --model lipm --controllers rsg,no-step --phases 0.5 --directions 8 --out /tmp/s
  rsg sweep --model pybullet --controllers rsg,placo-wpg --directions 4 --phases 0.25 --out r
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


def csv_names(text: str) -> tuple[str, ...]:
    return tuple(part.strip() for part in text.split(",") if part.strip())


def _phases(text: str) -> tuple[float, ...]:
    values = tuple(parse_decimal(p) for p in csv_names(text))
    if not values or any(v is None for v in values):
        raise argparse.ArgumentTypeError(f"--phases={text[:60]!r}: fractions like 0,0.25,0.5")
    return values  # type: ignore[return-value]


def add_sweep_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg sweep`` to the subcommands."""
    p = sub.add_parser(
        "sweep",
        help="robustness map: largest recovered impulse per controller, direction and phase",
        description="Bisect, for each controller, push direction and push phase, the largest "
        "impulse that is still recovered, next to the capture bound (an upper limit for any "
        "controller on the LIPM).",
        epilog=EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    p.add_argument("--model", choices=("lipm", "pybullet"), default="lipm")
    add_robot_argument(p)
    p.add_argument(
        "--controllers",
        type=csv_names,
        default=None,
        help=f"comma-separated, of {', '.join((*CONTROLLERS, PLACO_WPG))} (default: all that "
        "fit the model; placo-wpg needs --model pybullet)",
    )
    p.add_argument("--directions", type=int, default=16, help="push directions (default 16)")
    p.add_argument(
        "--phases",
        type=_phases,
        default=(0.0, 0.25, 0.5, 0.75),
        help="push phases, fractions of the walking cycle (default 0,0.25,0.5,0.75)",
    )
    p.add_argument("--duration", type=decimal_argument("--duration"), default=0.1,
                   help="push duration [s] (0.1)")  # fmt: skip
    p.add_argument("--cycle", type=int, default=3, help="walking cycle of the push (3)")
    p.add_argument("--settle", type=decimal_argument("--settle"), default=6.0,
                   help="time after the push [s] (6)")  # fmt: skip
    p.add_argument("--tolerance", type=decimal_argument("--tolerance"), default=0.25,
                   help="bisection [N s] (0.25)")  # fmt: skip
    p.add_argument("--criterion", choices=("recovered", "no-fall"), default=None,
                   help="recovered (lipm default) or no-fall (pybullet default)")  # fmt: skip
    p.add_argument(
        "--monotonicity",
        action="store_true",
        help="after the sweep, run each largest recovered impulse again at 0.25, 0.5 and "
        "0.75 of it and count the runs that fail the criterion",
    )
    add_replays_argument(p)
    add_job_options(p)


def add_job_options(p: argparse.ArgumentParser) -> None:
    """The options of every command that runs jobs (``sweep``, ``pushes``, ``protocol``):
    ``--paper-rules``, ``--workers``, ``--backend``, ``--out``, ``--set``, ``--quiet``."""
    p.add_argument(
        "--paper-rules",
        action="store_true",
        help=PAPER_RULES_HELP,
    )
    p.add_argument("--workers", type=int, default=None,
                   help="parallel workers (default: the CPU count; at most 4 per CPU, and "
                   "never more than there are jobs)")  # fmt: skip
    p.add_argument("--backend", choices=("process", "ray"), default="process",
                   help="process (default) or ray (needs the 'ray' extra)")  # fmt: skip
    add_out_arguments(p, "the results (a sweep's folder is resumed)")
    add_set_argument(p)
    p.add_argument("--quiet", action="store_true", help="no progress bar")


def workers_of(args: argparse.Namespace) -> int:
    """``--workers``, by default the CPU count."""
    return args.workers if args.workers is not None else os.cpu_count() or 1


def sweep_command(args: argparse.Namespace) -> int:
    """Run ``rsg sweep``; returns 0."""
    controllers = args.controllers
    if controllers is None:
        with_wpg = args.model == "pybullet"
        controllers = CONTROLLERS + ((PLACO_WPG,) if with_wpg else ())
    criterion = args.criterion or ("recovered" if args.model == "lipm" else "no-fall")
    spec = SweepSpec(
        model=args.model,
        robot=args.robot,
        controllers=tuple(controllers),
        directions=args.directions,
        phases=args.phases,
        duration=args.duration,
        cycle=args.cycle,
        settle=args.settle,
        tolerance=args.tolerance,
        criterion=criterion,
        paper_rules=args.paper_rules,
        overrides=tuple(args.overrides),
    )
    workers = workers_of(args)
    check_workers(workers, args.backend)
    if spec.model == "pybullet":
        check_robot_overrides(spec.robot, spec.overrides)
    started = time.perf_counter()
    records = run_sweep(
        spec, args.out, workers, args.backend, progress=not args.quiet, overwrite=args.overwrite
    )
    envelope = build_envelope(spec, records)
    worst = worst_sweep_runs(records, args.replays)
    if worst and not args.quiet:
        print(f"sweep: simulating the {len(worst)} worst failed runs again to replay them ...")
    envelope["replays"] = write_worst_replays(spec, worst, args.out)
    envelope["wall_time"] = time.perf_counter() - started
    paths = write_envelope(args.out, envelope)
    paths.append(plot_envelope(envelope, args.out / "envelope.png"))
    for path in paths:
        print(f"wrote {path}")
    print(format_table(envelope))
    print(format_replays(envelope["replays"]))
    print(f"sweep: {len(records)} jobs, {envelope['wall_time']:.0f} s wall time")
    if args.monotonicity:
        from .monotonicity import format_monotonicity, run_monotonicity, write_monotonicity

        report = run_monotonicity(
            spec, records, args.out, workers, args.backend, not args.quiet, args.overwrite
        )
        print(f"wrote {write_monotonicity(args.out, report)}")
        print(format_monotonicity(report))
    return 0
