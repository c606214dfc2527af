"""The options the ``rsg`` commands share, and the argparse types that check them.

Every type turns bad text into a one-line error that names the option, the value and
what is allowed (docs/input-validation.md); none raises a traceback.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from dataclasses import fields
from pathlib import Path
from typing import Any, NoReturn, TypeVar

from app.experiments.jobs import JobRun, check_workers
from app.reality import DEFAULT_PROFILE, PROFILES, PROFILES_HELP
from app.results.folder import MAX_PATH_LENGTH
from app.scenarios import MAX_DURATION, parse_push
from app.setup.build import check_robot_overrides
from app.setup.overrides import (
    MAX_VALUE_LENGTH,
    MODELS,
    ROBOT_MODELS,
    is_robot_model,
    parse_decimal,
)
from app.setup.paper_rules import PAPER_RULES_HELP
from planner.exceptions import RsgError
from planner.types import Push

S = TypeVar("S")


class CommandParser(argparse.ArgumentParser):
    """An argparse parser whose errors are one line (no usage block), with a pointer to
    ``--help``."""

    def error(self, message: str) -> NoReturn:
        self.exit(2, f"{self.prog}: error: {message} (see {self.prog} --help)\n")


def add_command(
    sub: argparse._SubParsersAction, name: str, help: str, description: str, epilog: str = ""
) -> argparse.ArgumentParser:
    """Add the command ``name`` to ``sub``; ``epilog`` (examples, outputs) keeps its lines."""
    return sub.add_parser(  # type: ignore[no-any-return]
        name,
        help=help,
        description=description,
        epilog=epilog or None,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def add_decimal(parser: argparse.ArgumentParser, name: str, default: float, help: str) -> None:
    """A number option ``name`` (:func:`decimal_argument`); ``help`` gives its unit."""
    parser.add_argument(name, type=decimal_argument(name), default=default, help=help)


def csv_names(text: str) -> tuple[str, ...]:
    """``a, b,c`` -> ``("a", "b", "c")`` (empty parts dropped)."""
    return tuple(part.strip() for part in text.split(",") if part.strip())


def decimal_argument(name: str) -> Callable[[str], float]:
    """argparse type of a number option ``name``: a finite ASCII decimal."""

    def parse(text: str) -> float:
        value = parse_decimal(text.strip())
        if value is None:
            raise argparse.ArgumentTypeError(f"{name}={text[:60]!r}: a finite decimal number")
        return value

    return parse


def decimals_argument(name: str, example: str, count: int | None = None) -> Callable:
    """argparse type of a comma-separated list of finite decimals (``count`` of them
    when given), e.g. ``--impulses 4,6,8``; ``example`` shows one in the error."""

    def parse(text: str) -> tuple[float, ...]:
        values = tuple(parse_decimal(part) for part in csv_names(text))
        if not values or any(v is None for v in values) or count not in (None, len(values)):
            raise argparse.ArgumentTypeError(f"{name}={text[:60]!r}: numbers like {example}")
        return values  # type: ignore[return-value]

    return parse


def push_argument(text: str) -> Push:
    """argparse type of ``--push T:IX,IY[:D]``."""
    try:
        return parse_push(text)
    except RsgError as exc:
        raise argparse.ArgumentTypeError(str(exc)) from None


def simulated_seconds(text: str) -> float:
    """argparse type of ``--duration`` of a run: seconds in (0, MAX_DURATION]."""
    value = parse_decimal(text.strip())
    if value is None or not 0.0 < value <= MAX_DURATION:
        raise argparse.ArgumentTypeError(
            f"--duration={text[:60]!r}: expected seconds in (0, {MAX_DURATION:g}]"
        )
    return value


def parse_assignment(text: str) -> tuple[str, str]:
    """argparse type of ``--set``: ``NAME=VALUE`` -> (name, value text)."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise argparse.ArgumentTypeError(
            f"--set {text[:60]!r}: NAME=VALUE, e.g. --set swing_preparation_time=0.3"
        )
    if len(value) > MAX_VALUE_LENGTH:
        raise argparse.ArgumentTypeError(
            f"--set {name.strip()[:60]}: a value of {len(value)} characters; at most "
            f"{MAX_VALUE_LENGTH}"
        )
    return name.strip(), value.strip()


def out_argument(text: str) -> Path:
    """argparse type of ``--out``: a non-empty path without NUL bytes."""
    if not text.strip():
        raise argparse.ArgumentTypeError(
            f"--out {text!r}: expected a folder path (an empty one would write into the "
            "current directory; use --out . for that)"
        )
    if "\0" in text or len(text) > MAX_PATH_LENGTH:
        raise argparse.ArgumentTypeError(
            f"--out {text[:60]!r}...: expected a path without NUL bytes, at most "
            f"{MAX_PATH_LENGTH} characters"
        )
    return Path(text)


def add_model_and_robot(
    parser: argparse.ArgumentParser,
    default_model: str,
    reality_seed: bool = False,
    models: tuple[str, ...] = MODELS,
) -> None:
    """``--model`` (one of ``models``), ``--robot`` and ``--reality`` (with
    ``--reality-seed`` when ``reality_seed``: a command that runs once)."""
    parser.add_argument(
        "--model",
        choices=models,
        default=default_model,
        help=f"simulation backend: lipm (the point mass) or a full robot on "
        f"{' or '.join(ROBOT_MODELS)} (default: {default_model})",
    )
    add_robot_argument(parser)
    add_reality_argument(parser, reality_seed)


def add_reality_argument(parser: argparse.ArgumentParser, reality_seed: bool = False) -> None:
    """``--reality`` (:mod:`app.reality`) and, when ``reality_seed``, ``--reality-seed``."""
    parser.add_argument(
        "--reality",
        choices=PROFILES,
        default=DEFAULT_PROFILE,
        help=f"the full robot's sensor noise, control delay and model errors: {PROFILES_HELP} "
        f"(default: {DEFAULT_PROFILE}; the LIPM ignores it)",
    )
    if reality_seed:
        parser.add_argument(
            "--reality-seed",
            type=seed_argument("--reality-seed"),
            default=0,
            metavar="N",
            help="seed of the --reality draw (noise, and with randomized the robot's errors) "
            "(default: 0)",
        )


def seed_argument(name: str) -> Callable[[str], int]:
    """argparse type of a seed option ``name``: an integer >= 0."""

    def parse(text: str) -> int:
        try:
            value = int(text.strip())
        except ValueError:
            value = -1
        if value < 0:
            raise argparse.ArgumentTypeError(f"{name}={text[:60]!r}: an integer >= 0")
        return value

    return parse


def add_robot_argument(parser: argparse.ArgumentParser) -> None:
    """``--robot`` (default ``None``: G1 on a full-robot model, the paper's point mass on
    ``lipm``)."""
    parser.add_argument(
        "--robot",
        default=None,
        help=f"robot (default: g1 on --model {' or '.join(ROBOT_MODELS)}; on --model lipm "
        "the paper's point "
        "mass, or with --robot that robot's planner: its mass, sole, gait and timing on "
        "the point mass)",
    )


def add_controllers(
    parser: argparse.ArgumentParser, allowed: tuple[str, ...], default: str
) -> None:
    """``--controllers a,b``: comma-separated names of ``allowed``."""
    parser.add_argument(
        "--controllers",
        type=csv_names,
        default=csv_names(default),
        help=f"comma-separated, of {', '.join(allowed)} (default: {default})",
    )


def add_set_argument(parser: argparse.ArgumentParser) -> None:
    """The repeatable ``--set NAME=VALUE``."""
    parser.add_argument(
        "--set",
        dest="overrides",
        type=parse_assignment,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change one parameter: a robot description field, a full-robot backend option "
        "or an RSG parameter, e.g. --set swing_preparation_time=0.3 --set landing_depth=0.003 "
        "(repeatable; a wrong name lists the allowed ones, a value out of range gives the "
        "range)",
    )


def add_paper_rules(parser: argparse.ArgumentParser) -> None:
    """``--paper-rules``: the paper's algorithm, every extension off."""
    parser.add_argument("--paper-rules", action="store_true", help=PAPER_RULES_HELP)


def add_out_arguments(parser: argparse.ArgumentParser, what: str = "the results") -> None:
    """``--out`` (required) and ``--overwrite``."""
    parser.add_argument("--out", type=out_argument, required=True, help=f"folder for {what}")
    parser.add_argument(
        "--overwrite",
        action="store_true",
        help="--out may hold an earlier run's results: they are deleted first (without it "
        "such a folder is refused, so results are never mixed)",
    )


def add_workers(parser: argparse.ArgumentParser, backends: bool = True) -> None:
    """``--workers`` and, when ``backends``, ``--backend process|ray``."""
    parser.add_argument(
        "--workers",
        type=int,
        default=None,
        help="parallel workers (default: the CPU count; at most 4 per CPU, and never more "
        "than there are jobs)",
    )
    if backends:
        parser.add_argument(
            "--backend",
            choices=("process", "ray"),
            default="process",
            help="process (default) or ray (needs the 'ray' extra)",
        )


def add_job_options(parser: argparse.ArgumentParser) -> None:
    """The options of every command that runs resumable jobs (``sweep``, ``pushes``,
    ``protocol``): ``--paper-rules``, ``--workers``, ``--backend``, ``--out``, ``--set``,
    ``--quiet``."""
    add_paper_rules(parser)
    add_workers(parser)
    add_out_arguments(parser, "the results (a folder of the same command is resumed)")
    add_set_argument(parser)
    parser.add_argument("--quiet", action="store_true", help="no progress bar")


def workers_of(args: argparse.Namespace) -> int:
    """``--workers``, by default the CPU count."""
    return args.workers if args.workers is not None else os.cpu_count() or 1


def spec_from_args(kind: type[S], args: argparse.Namespace, **given: Any) -> S:
    """The specification ``kind`` (a dataclass) from the options of the same names,
    ``--set`` as its ``overrides``, and ``given``; the other fields keep their defaults."""
    names = [f.name for f in fields(kind)]  # type: ignore[arg-type]
    values = {name: getattr(args, name) for name in names if hasattr(args, name)}
    values["overrides"] = tuple(args.overrides)
    return kind(**{**values, **given})


def job_workers(args: argparse.Namespace, spec: Any) -> int:
    """The workers of a job command, after checking ``--workers`` and, on the full robot,
    its ``--set`` (the robot is built once, so a bad value is reported before any worker
    starts)."""
    workers = workers_of(args)
    check_workers(workers, getattr(args, "backend", "process"))
    if is_robot_model(spec.model):
        check_robot_overrides(spec.robot, spec.overrides, spec.model)
    return workers


def job_run(args: argparse.Namespace, spec: Any) -> JobRun:
    """Where and how the jobs of ``spec`` run (``--out``, ``--workers``, ``--backend``,
    ``--quiet``, ``--overwrite``), after :func:`job_workers`' checks."""
    workers = job_workers(args, spec)
    return JobRun(args.out, workers, args.backend, not args.quiet, args.overwrite)
