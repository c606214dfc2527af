"""``rsg demo``: serve the live browser demo until Ctrl-C.

Builds the live simulation (:mod:`web.live`), the page (:mod:`web.page`) on a viser
server, prints the URL, and on Ctrl-C (or SIGTERM) stops the page, the simulation
and the server, releasing the port.
"""

from __future__ import annotations

import argparse
import signal
import socket
import sys
import threading
from pathlib import Path
from types import FrameType

from .live import LiveSimulation

GIL_SWITCH_INTERVAL = 0.001  # [s]


def port_is_free(host: str, port: int) -> bool:
    """Whether a server could listen on ``host``:``port`` now."""
    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as probe:
        probe.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            probe.bind((host, port))
        except OSError:
            return False
    return True


def _robot_urdf(model: str, robot: str | None) -> Path | None:
    if model != "pybullet":
        return None
    from app.setup import DEFAULT_ROBOT
    from robots import get_robot
    from robots.urdf_cache import derived_urdf

    return derived_urdf(get_robot(robot or DEFAULT_ROBOT))


def _interrupt(signum: int, frame: FrameType | None) -> None:
    raise KeyboardInterrupt


def main(args: argparse.Namespace) -> int:
    """Run the demo for the parsed ``rsg demo`` arguments; returns the exit code.

    Returns:
        0 after Ctrl-C, 2 when the port is in use. Bad model, robot, controller or
        scenario raise :class:`planner.exceptions.RsgError` (the CLI prints it).
    """
    if not port_is_free(args.host, args.port):
        print(
            f"rsg demo: error: port {args.port} on {args.host} is in use "
            "(another demo?); choose another one with --port",
            file=sys.stderr,
        )
        return 2
    import viser

    from .page import DemoPage

    # The simulation thread holds the GIL in long C calls (physics, IK): hand it over
    # more often so the page keeps its frame rate (measured: +10-20 % page updates).
    sys.setswitchinterval(GIL_SWITCH_INTERVAL)
    print(f"rsg demo: building the {args.model} simulation ...", flush=True)
    live = LiveSimulation(args.model, args.robot, args.controller, args.scenario)
    urdf = _robot_urdf(args.model, args.robot)
    server = viser.ViserServer(host=args.host, port=args.port, label="rsg demo", verbose=False)
    page: DemoPage | None = None
    if threading.current_thread() is threading.main_thread():
        # SIGINT explicitly too: a process started as a background job of a
        # non-interactive shell inherits SIGINT ignored, and Python then raises no
        # KeyboardInterrupt (measured: CI started that way killed the demos after 30 s).
        signal.signal(signal.SIGINT, _interrupt)
        signal.signal(signal.SIGTERM, _interrupt)
    try:
        if server.get_port() != args.port:
            print(
                f"rsg demo: error: port {args.port} on {args.host} was taken while starting; "
                "choose another one with --port",
                file=sys.stderr,
            )
            return 2
        page = DemoPage(server, live, urdf, frame_rate=getattr(args, "frame_rate", 40.0))
        live.start()
        page.start()
        shown = "127.0.0.1" if args.host in ("0.0.0.0", "") else args.host
        print(f"rsg demo: open http://{shown}:{args.port} (Ctrl-C to stop)", flush=True)
        stop = threading.Event()
        while not stop.wait(0.5):
            pass
    except KeyboardInterrupt:
        print("rsg demo: stopping ...", flush=True)
    finally:
        if page is not None:
            page.stop()
        live.stop()
        server.stop()
    print("rsg demo: stopped", flush=True)
    return 0
