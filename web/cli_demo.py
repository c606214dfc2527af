"""The ``rsg demo`` subcommand, registered in the entry-point group ``rsg.commands``.

``add_parser`` adds its arguments to ``rsg``; ``run`` starts :func:`web.demo.main`.
"""

from __future__ import annotations

import argparse

from app.commands.arguments import add_reality_argument, add_robot_argument
from app.setup.overrides import ROBOT_MODELS
from planner.parameters import CONTROLLERS
from web.live import SLOW_MOTION_FACTORS

DEMO_EPILOG = """\
examples:
  rsg demo                                 # G1 in PyBullet, http://127.0.0.1:8080
  rsg demo --model lipm --port 8081        # point-mass LIPM, fast
  rsg demo --model mujoco                  # G1 in MuJoCo
  rsg demo --scenario paper-fig6           # the paper's two pushes, plus yours
  rsg demo --reality randomized --reality-seed 4   # G1 with drawn model errors and noise

The page shows the robot, its footholds, the ZMP window, ZMP/CoM/DCM, the DCM error
against the Lyapunov level sets (Fig. 6(c)), V_u / gamma_v on a log axis and the time
since the last step. Push from the page (button "Push", click the ground to aim). The
run goes on until you stop the server with Ctrl-C.
"""
DEMO_HELP = "live browser demo: watch the robot walk and push it"
DEMO_DESCRIPTION = (
    "Serve a live browser demo (viser) of the closed loop: the robot walks, you push it from "
    "the page and watch the step generator recover."
)


def _bounded(option: str, kind: type, low: float, high: float, unit: str):  # noqa: ANN202
    """An argparse type: a ``kind`` number in [low, high], with a message naming ``option``."""

    def parse(text: str):  # noqa: ANN202
        try:
            value = kind(text)
        except ValueError:
            raise argparse.ArgumentTypeError(
                f"{option}={text!r}: expected a number in [{low}, {high}] {unit}"
            ) from None
        if not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{option}={value}: expected [{low}, {high}] {unit}")
        return value

    return parse


PORT = _bounded("--port", int, 1, 65535, "(a TCP port)")
_frame_rate = _bounded("--frame-rate", float, 1.0, 60.0, "[Hz]")


def add_page_parser(
    sub: argparse._SubParsersAction, name: str, summary: str, description: str, epilog: str
) -> argparse.ArgumentParser:
    """A subcommand that serves a page (``rsg demo``, ``rsg replay``): its epilog as written."""
    return sub.add_parser(
        name,
        help=summary,
        description=description,
        epilog=epilog,
        formatter_class=argparse.RawDescriptionHelpFormatter,
    )


def add_address_arguments(parser: argparse.ArgumentParser, host_help: str) -> None:
    """``--host`` and ``--port``: where a page is served."""
    parser.add_argument("--host", default="127.0.0.1", help=host_help)
    parser.add_argument("--port", type=PORT, default=8080, help="port to serve on (default: 8080)")


def add_demo_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Add ``demo`` to the subcommands ``sub`` of ``rsg``; returns its parser."""
    demo = add_page_parser(sub, "demo", DEMO_HELP, DEMO_DESCRIPTION, DEMO_EPILOG)
    demo.add_argument(
        "--model",
        choices=(*ROBOT_MODELS, "lipm"),
        default="pybullet",
        help="pybullet or mujoco: the full robot on that engine (URDF meshes); lipm: point "
        "mass (default: pybullet)",
    )
    add_robot_argument(demo)
    add_reality_argument(demo, reality_seed=True)
    demo.add_argument(
        "--controller",
        choices=(*CONTROLLERS, "placo-wpg"),
        default="rsg",
        help="step controller at start; can be changed on the page (default: rsg). placo-wpg "
        "runs headless only (rsg run): it has no DCM-error Lyapunov level for the page to draw",
    )
    demo.add_argument(
        "--speed",
        type=float,
        choices=SLOW_MOTION_FACTORS,
        default=1.0,
        help="simulated seconds per wall second at start, one of "
        f"{', '.join(f'{f:g}' for f in SLOW_MOTION_FACTORS)} (default: 1, real time); "
        "can be changed on the page",
    )
    demo.add_argument(
        "--quiet",
        action="store_true",
        help="print no line per step (pushes, refusals, falls, resets and errors still print)",
    )
    demo.add_argument(
        "--scenario",
        default="walk",
        help="built-in scenario name or .toml file; its pushes are applied too (default: walk)",
    )
    add_address_arguments(
        demo,
        "address to serve on (default: 127.0.0.1, this machine only; any other "
        "address lets whoever reaches the port push the robot)",
    )
    demo.add_argument(
        "--frame-rate",
        type=_frame_rate,
        default=40.0,
        help="scene updates sent to the page per second, 1 to 60 (default: 40); a browser "
        "without GPU rendering draws fewer and answers a click within one of its frames",
    )
    return demo


def add_parser(sub: argparse._SubParsersAction) -> argparse.ArgumentParser:
    """Entry-point hook: add ``demo`` to ``rsg``."""
    return add_demo_parser(sub)


def run(args: argparse.Namespace) -> int:
    """Entry-point hook: run ``rsg demo``."""
    from web.demo import main

    if args.controller == "placo-wpg":
        from planner.exceptions import ParameterError

        raise ParameterError(
            "--controller",
            "placo-wpg",
            f"one of {', '.join(CONTROLLERS)} (placo-wpg has its own preview and IK and no "
            "DCM-error Lyapunov level for the page to draw; run it headless: rsg run "
            "--controller placo-wpg)",
        )

    return int(main(args))
