"""``rsg protocol``: command-line options and the command (see :mod:`app.experiments.protocol`)."""

from __future__ import annotations

import argparse
import time

from app.commands.arguments import (
    add_command,
    add_controllers,
    add_job_options,
    add_model_and_robot,
    job_run,
    spec_from_args,
)
from app.experiments.protocol import ProtocolSpec, format_protocol, run_protocol, write_protocol
from app.experiments.sweep import SWEEP_CONTROLLERS
from app.results.folder import report_files

HELP = (
    "IHMC-style pushes forward, backward, inward and outward: largest fraction of "
    "m g over 0.1 s recovered, beside Atlas's thresholds"
)
DESCRIPTION = (
    "The push-recovery protocol of IHMC's CI tests: a push of f m g for 0.1 s "
    "at mid swing (forward, backward, inward) or mid double support (outward); bisect "
    "the largest f recovered per direction and compare with IHMC's Atlas thresholds."
)
EPILOG = """\
examples:
  rsg protocol --model lipm --out results/protocol-lipm                  # the paper's point mass
  rsg protocol --model lipm --robot g1 --out results/protocol-g1-lipm    # G1's planner alone
  rsg protocol --model pybullet --controllers rsg,no-step --out results/protocol-g1
  rsg protocol --model pybullet --robot talos --out results/protocol-talos
  rsg protocol --model mujoco --out results/protocol-g1-mujoco

pushes (IHMC's push-recovery CI tests; left stance foot, cycle 4):
  forward 0 deg, backward 180 deg, inward 90 deg (towards the stance foot): single-support
  start + half the swing time; outward 270 deg: double-support start + half of it.
  A force of f m g for 0.1 s; the largest f recovered is bisected.

outputs in --out:
  protocol.json, protocol.csv  largest fraction f, impulse [N s], velocity change [m/s] per
                               controller and direction, beside Atlas's CI thresholds
  jobs.jsonl, sweep_spec.json  finished bisections; the same command again resumes
"""


def add_parser(sub: argparse._SubParsersAction) -> None:
    """Add ``rsg protocol`` to the subcommands."""
    p = add_command(sub, "protocol", HELP, DESCRIPTION, EPILOG)
    add_model_and_robot(p, "lipm")
    add_controllers(p, SWEEP_CONTROLLERS, "rsg")
    p.add_argument("--tolerance", type=float, default=0.01, help="bisection tolerance on f (0.01)")
    p.add_argument(
        "--criterion",
        choices=("recovered", "no-fall"),
        default="recovered",
        help="success: recovered (default) or no fall",
    )
    p.add_argument("--settle", type=float, default=8.0, help="time after the push [s] (8)")
    add_job_options(p)


def run(args: argparse.Namespace) -> int:
    """Run ``rsg protocol``; returns 0."""
    spec = spec_from_args(ProtocolSpec, args)
    run_as = job_run(args, spec)
    started = time.perf_counter()
    document = run_protocol(spec, run_as)
    document["wall_time"] = time.perf_counter() - started
    report_files(write_protocol(args.out, document))
    print(format_protocol(document))
    print(f"protocol: {document['wall_time']:.0f} s wall time; source: {document['source']}")
    return 0
