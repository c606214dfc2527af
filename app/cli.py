"""The ``rsg`` command line: ``rsg run``, ``sweep``, ``grid``, ``pushes``, ``protocol``, ``bench``,
plug-ins.

Each command is a module of :mod:`app.commands` with ``add_parser(subparsers)`` and
``run(args) -> int``. Packages that sit above ``app`` (the browser demo in ``web``) add
theirs, with the same two functions, through the entry-point group ``rsg.commands``
(see pyproject.toml), so ``app`` never imports ``web``.
"""

from __future__ import annotations

import argparse
import importlib
import importlib.metadata
import sys
from typing import Any

from app.commands.arguments import CommandParser
from planner.exceptions import RsgError

#: The built-in commands: verb -> module of :mod:`app.commands`, loaded when used.
COMMANDS = {
    "run": "app.commands.run",
    "sweep": "app.commands.sweep",
    "grid": "app.commands.grid",
    "pushes": "app.commands.pushes",
    "protocol": "app.commands.protocol",
    "bench": "app.commands.bench",
}
PLUGIN_GROUP = "rsg.commands"


def plugin_commands() -> dict[str, Any]:
    """Commands registered by other packages in the entry-point group ``rsg.commands``."""
    entries = importlib.metadata.entry_points(group=PLUGIN_GROUP)
    return {entry.name: entry.load() for entry in entries}


def all_commands() -> dict[str, Any]:
    """Every command's module, built-in then plug-ins, by verb."""
    built_in = {verb: importlib.import_module(name) for verb, name in COMMANDS.items()}
    return {**built_in, **plugin_commands()}


def build_parser(commands: dict[str, Any] | None = None) -> argparse.ArgumentParser:
    parser = CommandParser(
        prog="rsg",
        description="Reactive step generation for biped push recovery (Lyapunov-based hybrid "
        "tracking control of the DCM), on the LIPM and on a full humanoid in PyBullet.",
    )
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", required=True)
    for command in (commands or all_commands()).values():
        command.add_parser(sub)
    return parser


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``rsg``; returns the exit code (0 ok, 1 not recovered, 2 bad input,
    130 interrupted)."""
    commands = all_commands()
    args = build_parser(commands).parse_args(argv)
    try:
        return int(commands[args.command].run(args))
    except RsgError as exc:
        print(f"rsg {args.command}: error: {exc}", file=sys.stderr)
        return 2
    except KeyboardInterrupt:
        print(f"rsg {args.command}: interrupted", file=sys.stderr)
        return 130


if __name__ == "__main__":
    sys.exit(main())
