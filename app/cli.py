"""The ``rsg`` command line: ``rsg run``, ``sweep``, ``grid``, ``pushes``, ``protocol``, ``bench``,
plug-ins.

Packages that sit above ``app`` (the browser demo in ``web``) add their commands
through the entry-point group ``rsg.commands`` (see pyproject.toml): each entry is a
module with ``add_parser(subparsers)`` and ``run(args) -> int``. So ``app`` never
imports ``web``; ``web`` depends on ``app``.
"""

from __future__ import annotations

import argparse
import importlib.metadata
import sys
from typing import Any, NoReturn

from planner.exceptions import RsgError
from planner.parameters import CONTROLLERS

from .overrides import add_robot_argument, add_set_argument, parse_decimal
from .result_folder import add_out_arguments
from .scenarios import BUILT_IN, MAX_DURATION, parse_push
from .setup import PAPER_RULES_HELP

MODELS = ("lipm", "pybullet")
DEFAULT_MODEL = "pybullet"

RUN_EPILOG = """\
examples:
  rsg run --scenario walk --duration 20 --out results/g1-walk       # G1 in PyBullet
  rsg run --model lipm --scenario paper-fig6 --out results/fig6
  rsg run --model lipm --controller no-step --scenario walk --push 3:0,25 --out results/side
  rsg run --model lipm --scenario my_pushes.toml --out results/mine
  rsg run --model pybullet --controller placo-wpg --scenario walk --duration 4 --out results/wpg

outputs in --out (a folder with an earlier run's results is refused without --overwrite):
  summary.json     verdict (recovered, fell, interrupted), steps, pushes, Lyapunov levels
  timeseries.csv   CoM, ZMP, hdot, stance foot, DCM error, V_u, s~, push force (SI units)
  fig6*.png        the paper's Fig. 6: top view, time since step, DCM error
  replay.npz       the run for the browser: rsg replay FOLDER

exit code: 0 recovered, 1 not recovered, 2 bad input, 130 interrupted (Ctrl-C: what was
simulated is written, summary.json says "interrupted": true)
"""


def _push(text: str):
    try:
        return parse_push(text)
    except RsgError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def _positive_seconds(text: str) -> float:
    value = parse_decimal(text.strip())
    if value is None or not 0.0 < value <= MAX_DURATION:
        raise argparse.ArgumentTypeError(
            f"--duration={text[:60]!r}: expected seconds in (0, {MAX_DURATION:g}]"
        )
    return value


class CommandParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line (no usage block), with a pointer to
    ``--help``."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


PLUGIN_GROUP = "rsg.commands"


def plugin_commands() -> dict[str, Any]:
    """Commands registered by other packages in the entry-point group ``rsg.commands``."""
    commands = {}
    for entry in importlib.metadata.entry_points(group=PLUGIN_GROUP):
        commands[entry.name] = entry.load()
    return commands


def build_parser() -> argparse.ArgumentParser:
    parser = CommandParser(
        prog="rsg",
        description="Reactive step generation for biped push recovery (Lyapunov-based hybrid "
        "tracking control of the DCM), on the LIPM and on a full humanoid in PyBullet.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    run = sub.add_parser(
        "run",
        help="simulate one scenario headless and write summary, time series and plots",
        description="Simulate one scenario with a step controller in the loop, headless, and "
        "write summary.json, timeseries.csv and the paper's Fig. 6 plots to --out.",
        epilog=RUN_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    run.add_argument(
        "--model",
        choices=MODELS,
        default=DEFAULT_MODEL,
        help=f"simulation backend (default: {DEFAULT_MODEL})",
    )
    add_robot_argument(run)
    run.add_argument(
        "--controller",
        choices=(*CONTROLLERS, "placo-wpg"),
        default="rsg",
        help="rsg: step time and location adjusted; fixed-timing: location only; "
        "no-step: nominal steps; placo-wpg: placo's WalkPatternGenerator with "
        "update_supports (--model pybullet only) (default: rsg)",
    )
    run.add_argument(
        "--scenario",
        default="paper-fig6",
        help=f"built-in ({', '.join(BUILT_IN)}) or a .toml file (default: paper-fig6)",
    )
    run.add_argument(
        "--push",
        type=_push,
        action="append",
        default=[],
        metavar="T:IX,IY[:D]",
        help="add a push: start time [s], impulse [N s], duration [s] (default 0.1); repeatable",
    )
    run.add_argument(
        "--duration",
        type=_positive_seconds,
        default=None,
        help="simulated time [s] (default: the scenario's)",
    )
    add_out_arguments(run)
    run.add_argument(
        "--paper-rules",
        action="store_true",
        help=PAPER_RULES_HELP,
    )
    add_set_argument(run)
    run.add_argument("--no-plots", action="store_true", help="skip the PNG plots")
    run.add_argument(
        "--physics-log",
        action="store_true",
        help="also write physics.csv: CoM, foot forces and CoPs, soles at every "
        "physics step (--model pybullet; touchdowns and impacts)",
    )
    run.add_argument("--quiet", action="store_true", help="no progress bar")
    for command in plugin_commands().values():
        command.add_parser(sub)
    from .bench import add_bench_parser
    from .campaign_command import add_campaign_parser
    from .grid_command import add_grid_parser
    from .protocol_command import add_protocol_parser
    from .sweep_command import add_sweep_parser

    add_sweep_parser(sub)
    add_grid_parser(sub)
    add_campaign_parser(sub)
    add_protocol_parser(sub)
    add_bench_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``rsg``; returns the exit code (0 ok, 1 not recovered, 2 bad input)."""
    parser = build_parser()
    args = parser.parse_args(argv)
    try:
        if args.command == "run":
            from .run_command import run_command

            return run_command(args)
        plugins = plugin_commands()
        if args.command in plugins:
            return int(plugins[args.command].run(args))
        if args.command == "sweep":
            from .sweep_command import sweep_command

            return sweep_command(args)
        if args.command == "grid":
            from .grid_command import grid_command

            return grid_command(args)
        if args.command == "pushes":
            from .campaign_command import campaign_command

            return campaign_command(args)
        if args.command == "protocol":
            from .protocol_command import protocol_command

            return protocol_command(args)
        if args.command == "bench":
            from .bench import bench_command

            return bench_command(args)
    except RsgError as exc:
        print(f"rsg {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"rsg {args.command}: interrupted", file=sys.stderr)
        return 130
    parser.error(f"unknown command {args.command}")
    return 2


if __name__ == "__main__":
    sys.exit(main())
