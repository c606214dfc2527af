"""The ``rsg demo`` subcommand, registered in the entry-point group ``rsg.commands``.

``add_parser`` adds its arguments to ``rsg``; ``run`` starts :func:`web.demo.main`.
"""

from __future__ import annotations

import argparse

from planner.parameters import CONTROLLERS

DEMO_EPILOG = """\
examples:
  rsg demo                                 # G1 in PyBullet, http://127.0.0.1:8080
  rsg demo --model lipm --port 8081        # point-mass LIPM, fast
  rsg demo --scenario paper-fig6           # the paper's two pushes, plus yours

The page shows the robot, its footholds, the ZMP window, ZMP/CoM/DCM, the DCM error
against the Lyapunov level sets, and plots of V_u and of the time since the last step.
Push from the page (button "Push", click the ground to aim). Ctrl-C stops the server.
"""


def _port(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--port={text!r}: expected an integer") from None
    if not 1 <= value <= 65535:
        raise argparse.ArgumentTypeError(f"--port={value}: expected a port in [1, 65535]")
    return value


def _frame_rate(text: str) -> float:
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"--frame-rate={text!r}: expected a number") from None
    if not 1.0 <= value <= 60.0:
        raise argparse.ArgumentTypeError(f"--frame-rate={value}: expected 1 to 60 [Hz]")
    return value


def add_demo_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add ``demo`` to the subcommands ``sub`` of ``rsg``; returns its parser."""
    demo = sub.add_parser(
        "demo",
        help="live browser demo: watch the robot walk and push it",
        description="Serve a live browser demo (viser) of the closed loop: the robot walks, "
        "you push it from the page and watch the step generator recover.",
        epilog=DEMO_EPILOG,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )
    demo.add_argument(
        "--model",
        choices=("pybullet", "lipm"),
        default="pybullet",
        help="pybullet: full robot (URDF meshes); lipm: point mass (default: pybullet)",
    )
    demo.add_argument("--robot", default="g1", help="robot for --model pybullet (default: g1)")
    demo.add_argument(
        "--controller",
        choices=CONTROLLERS,
        default="rsg",
        help="step controller at start; can be changed on the page (default: rsg)",
    )
    demo.add_argument(
        "--scenario",
        default="walk",
        help="built-in scenario name or .toml file; its pushes are applied too (default: walk)",
    )
    demo.add_argument(
        "--host", default="127.0.0.1", help="address to serve on (default: 127.0.0.1)"
    )
    demo.add_argument("--port", type=_port, default=8080, help="port to serve on (default: 8080)")
    demo.add_argument(
        "--frame-rate",
        type=_frame_rate,
        default=40.0,
        help="scene updates sent to the page per second, 1 to 60 (default: 40); lower it for "
        "browsers without GPU rendering, which otherwise fall behind and answer clicks late",
    )
    return demo


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Entry-point hook: add ``demo`` to ``rsg``."""
    return add_demo_parser(sub)


def run(args: argparse.Namespace) -> int:
    """Entry-point hook: run ``rsg demo``."""
    from web.demo import main

    return int(main(args))
