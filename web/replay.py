"""``rsg replay DIR``: serve the page of a recorded run until Ctrl-C.

Loads ``DIR/replay.npz`` (:mod:`app.results.replay`; a bad folder or file is an
:class:`app.results.replay.ReplayError`, printed on one line with exit code 2) and serves
:class:`web.replay_page.ReplayPage` (:mod:`web.serve`).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import viser

from app.results.replay import load_replay

from .serve import check_address, serve


def _robot_urdf(robot: str) -> Path:
    from robots import get_robot
    from robots.urdf_cache import derived_urdf

    return derived_urdf(get_robot(robot))


def main(args: argparse.Namespace) -> int:
    """Serve the replay of ``args.folder``; returns the exit code (0 after Ctrl-C, 2 on a
    bad host or port). A bad folder raises :class:`app.results.replay.ReplayError`."""
    replay = load_replay(args.folder)
    refused = check_address("replay", args.host, args.port)
    if refused is not None:
        return refused
    from .replay_page import ReplayPage

    urdf = _robot_urdf(replay.meta["robot"]) if replay.robot is not None else None

    def start(server: viser.ViserServer):  # noqa: ANN202
        page = ReplayPage(server, replay, args.folder, urdf)
        page.start()
        return page.stop

    meta = replay.meta
    print(
        f"rsg replay: {args.folder}: {meta['model']} {meta['robot']} {meta['controller']}, "
        f"{meta['scenario']}, {replay.duration:.2f} s",
        flush=True,
    )
    return serve("replay", args.host, args.port, start, "rsg replay", checked=True)
