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
    csv_names,
)
from app.experiments.bench import (
    QP_AGREEMENT,
    bench_placo_wpg,
    bench_robot,
    bench_rsg_ticks,
    bench_step_qp,
    compare_engines,
    format_bench,
    tick_breakdown,
)
from app.results.folder import prepare_out
from app.setup.build import check_robot_overrides
from app.setup.overrides import ROBOT_MODELS, check_overrides
from planner.exceptions import ParameterError, RsgError

HELP = "time the planner tick, the step QP, IK, physics and the whole loop"
DESCRIPTION = (
    "Median and 95th percentile time per call of each part of the loop; "
    "prints a table and writes bench.json."
)
EPILOG = """\
examples:
  rsg bench --out results/bench                          # G1 on PyBullet
  rsg bench --model mujoco --duration 10 --out results/bench-mujoco
  rsg bench --model pybullet,mujoco --out results/bench-engines   # side by side
"""


def engines_argument(text: str) -> tuple[str, ...]:
    """argparse type of ``--model`` of ``rsg bench``: distinct engines of
    :data:`ROBOT_MODELS`, comma-separated."""
    names = csv_names(text)
    if not names or len(set(names)) != len(names) or not set(names) <= set(ROBOT_MODELS):
        raise argparse.ArgumentTypeError(
            f"--model={text[:60]!r}: distinct of {', '.join(ROBOT_MODELS)}, comma-separated "
            "(e.g. pybullet,mujoco)"
        )
    return names


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg bench`` to the subcommands."""
    p = add_command(sub, "bench", HELP, DESCRIPTION, EPILOG)
    p.add_argument(
        "--model",
        type=engines_argument,
        default=("pybullet",),
        metavar="ENGINE[,ENGINE]",
        help=f"engine(s) of the full-robot part, of {', '.join(ROBOT_MODELS)}; several are "
        "timed one after the other in this process, side by side (default: pybullet)",
    )
    p.add_argument("--robot", default="g1", help="robot for the full-robot part (default g1)")
    add_reality_argument(p)
    add_decimal(p, "--duration", 4.0, "full-robot walk [s] (4)")
    p.add_argument("--samples", type=int, default=1000, help="sampled step QPs (1000)")
    p.add_argument("--no-robot", action="store_true", help="skip the full-robot part")
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
    models: tuple[str, ...] = args.model
    for model in models:
        check_overrides(overrides, model, args.robot)
    if not args.no_robot:
        for model in models:
            check_robot_overrides(args.robot, overrides, model)
    for deleted in prepare_out(args.out, "bench", args.overwrite):
        print(f"deleted {deleted} (--overwrite)")
    report: dict = {
        "units": "seconds per call; real_time_factor = simulated / wall time",
        "overrides": [f"{name}={value}" for name, value in overrides],
        "reality": args.reality,
    }
    report.update(bench_rsg_ticks())
    report.update(bench_step_qp(args.samples))
    by_model: dict[str, dict] = {}
    for model in () if args.no_robot else models:
        figures = bench_robot(
            args.robot, args.duration, overrides=overrides, reality=args.reality, engine=model
        )
        figures["placo_wpg"] = bench_placo_wpg(
            args.robot, args.duration, overrides, args.reality, model
        )
        by_model[model] = figures
    if by_model:
        report.update(by_model[models[0]])  # the first engine's at the top level, as with one
        report["by_model"] = by_model
    table = _tables(report, by_model)
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
    for model, figures in by_model.items():
        print(f"{model}: {tick_breakdown(figures)}")
    print(f"wrote {path}")
    return 0


def _tables(report: dict, by_model: dict[str, dict]) -> str:
    """The table of each engine (one: as before), then the engines side by side."""
    if len(by_model) <= 1:
        model = next(iter(by_model), None)
        return format_bench(report) if model is None else f"{model}:\n{format_bench(report)}"
    parts = [
        f"{model}:\n{format_bench({**report, **figures})}" for model, figures in by_model.items()
    ]
    parts.append(compare_engines(by_model))
    return "\n\n".join(parts)
