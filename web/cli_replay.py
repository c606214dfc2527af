"""The ``rsg replay`` subcommand, registered in the entry-point group ``rsg.commands``.

``add_parser`` adds its arguments to ``rsg``; ``run`` starts :func:`web.replay.main`.
"""

from __future__ import annotations

import argparse
from pathlib import Path

from .cli_demo import add_address_arguments, add_page_parser

REPLAY_EPILOG = """\
examples:
  rsg run --scenario paper-fig6 --out results/fig6-g1
  rsg replay results/fig6-g1               # http://127.0.0.1:8080
  rsg replay results/sweep/replays/rsg-45deg-phase0.5-12.3Ns --port 8081

The page is the demo's (robot, footholds, ZMP window, DCM-error plot, V_u plot, push
arrows) for the recorded run, with a time slider, Play/Pause and the speed; nothing is
simulated. rsg sweep and rsg grid keep their worst runs replayable (their reports say
where). Ctrl-C stops the server.
"""
REPLAY_HELP = "replay a recorded run in the browser (the --out folder of rsg run)"
REPLAY_DESCRIPTION = (
    "Serve the browser page of a recorded run: the robot, its footholds and the plots at any "
    "time of the run, with a time slider, Play/Pause and speed."
)


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Entry-point hook: add ``replay`` to ``rsg``."""
    replay = add_page_parser(sub, "replay", REPLAY_HELP, REPLAY_DESCRIPTION, REPLAY_EPILOG)
    replay.add_argument("folder", type=Path, metavar="DIR", help="a run folder (with replay.npz)")
    add_address_arguments(replay, "address to serve on (default: 127.0.0.1, this machine only)")
    return replay


def run(args: argparse.Namespace) -> int:
    """Entry-point hook: run ``rsg replay``."""
    from web.replay import main

    return int(main(args))
