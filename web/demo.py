"""``rsg demo``: serve the live browser demo until Ctrl-C.

Builds the live simulation (:mod:`web.live`) and its page (:mod:`web.demo_page`) on
a viser server (:mod:`web.serve`: address checks, the URL, a clean stop that
releases the port).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import viser

from app.reality import DEFAULT_PROFILE
from app.setup.overrides import is_robot_model

from .live import LiveSimulation
from .serve import check_address, serve


def _robot_urdf(model: str, robot: str | None) -> Path | None:
    if not is_robot_model(model):
        return None
    from robots import DEFAULT_ROBOT, get_robot
    from robots.urdf_cache import derived_urdf

    return derived_urdf(get_robot(robot or DEFAULT_ROBOT))


def main(args: argparse.Namespace) -> int:
    """Run the demo for the parsed ``rsg demo`` arguments; returns the exit code.

    Returns:
        0 after Ctrl-C, 2 when the host or the port cannot be used. Bad model, robot,
        controller or scenario raise :class:`planner.exceptions.RsgError` (the CLI
        prints it).
    """
    refused = check_address("demo", args.host, args.port)
    if refused is not None:
        return refused
    from .demo_page import FRAME_RATE, DemoPage

    print(f"rsg demo: building the {args.model} simulation ...", flush=True)
    live = LiveSimulation(
        args.model,
        args.robot,
        args.controller,
        args.scenario,
        log_steps=not getattr(args, "quiet", False),
        slow_motion=getattr(args, "speed", 1.0),
        reality=getattr(args, "reality", DEFAULT_PROFILE),
        reality_seed=getattr(args, "reality_seed", 0),
    )
    draw = live.reality_draw()  # before the simulation thread starts
    if draw is not None:
        print(f"rsg demo: {draw.describe()}", flush=True)
    urdf = _robot_urdf(args.model, args.robot)

    def start(server: viser.ViserServer):  # noqa: ANN202
        page = DemoPage(server, live, urdf, frame_rate=getattr(args, "frame_rate", FRAME_RATE))
        live.start()
        page.start()

        def stop() -> None:
            page.stop()
            live.stop()

        return stop

    try:
        return serve("demo", args.host, args.port, start, "rsg demo", checked=True)
    finally:
        live.stop()
