"""``rsg bench``: command-line options and the command (see :mod:`app.experiments.bench`)."""

from __future__ import annotations

import argparse
import json

from app.commands.arguments import (
    add_command,
    add_decimal,
    add_out_arguments,
    add_reality_argument,
    add_set_argument,
)
from app.experiments.bench import (
    QP_AGREEMENT,
    bench_placo_wpg,
    bench_robot,
    bench_rsg_ticks,
    bench_step_qp,
    format_bench,
    tick_breakdown,
)
from app.results.folder import prepare_out
from app.setup.build import check_robot_overrides
from app.setup.overrides import check_overrides
from planner.exceptions import ParameterError, RsgError

HELP = "time the planner tick, the step QP, IK, physics and the whole loop"
DESCRIPTION = (
    "Median and 95th percentile time per call of each part of the loop; "
    "prints a table and writes bench.json."
)


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg bench`` to the subcommands."""
    p = add_command(sub, "bench", HELP, DESCRIPTION)
    p.add_argument("--robot", default="g1", help="robot for the full-robot part (default g1)")
    add_reality_argument(p)
    add_decimal(p, "--duration", 4.0, "full-robot walk [s] (4)")
    p.add_argument("--samples", type=int, default=1000, help="sampled step QPs (1000)")
    p.add_argument("--no-robot", action="store_true", help="skip the PyBullet part")
    add_set_argument(p)
    add_out_arguments(p, "bench.json")


def run(args: argparse.Namespace) -> int:
    """Run ``rsg bench``; returns 0."""
    if not 0.05 <= args.duration <= 600.0:
        raise ParameterError("--duration", args.duration, "seconds in [0.05, 600]")
    if not 10 <= args.samples <= 1_000_000:
        raise ParameterError("--samples", args.samples, "an integer in [10, 1000000]")
    overrides = tuple(args.overrides)
    if args.no_robot and overrides:
        raise ParameterError(
            "--set",
            " ".join(f"{n}={v}" for n, v in overrides),
            "no --set with --no-robot (the overrides change only the robot's part)",
        )
    check_overrides(overrides, "pybullet", args.robot)
    if not args.no_robot:
        check_robot_overrides(args.robot, overrides)
    for deleted in prepare_out(args.out, "bench", args.overwrite):
        print(f"deleted {deleted} (--overwrite)")
    report: dict = {
        "units": "seconds per call; real_time_factor = simulated / wall time",
        "overrides": [f"{name}={value}" for name, value in overrides],
        "reality": args.reality,
    }
    report.update(bench_rsg_ticks())
    report.update(bench_step_qp(args.samples))
    if not args.no_robot:
        report.update(
            bench_robot(args.robot, args.duration, overrides=overrides, reality=args.reality)
        )
        report["placo_wpg"] = bench_placo_wpg(args.robot, args.duration, overrides, args.reality)
    table = format_bench(report)
    report["table"] = table
    try:
        path = args.out / "bench.json"
        path.write_text(json.dumps(report, indent=2) + "\n")
    except OSError as exc:
        raise RsgError(f"cannot write {args.out}/bench.json: {exc}") from exc
    print(table)
    print(
        f"step QP: proxqp and exact agree within {QP_AGREEMENT:g} m on "
        f"{100 * report['qp_agree_fraction']:.1f}% of {report['qp_samples']} sampled problems "
        f"(largest difference {report['qp_max_difference']:.2e} m); the exact method's "
        f"objective is {'never' if report['qp_exact_objective_not_worse'] else 'sometimes'} "
        "worse than proxqp's"
    )
    if not args.no_robot:
        print(tick_breakdown(report))
    print(f"wrote {path}")
    return 0
