"""Running the jobs of ``rsg sweep`` (and of the other job commands) on a Ray cluster
(``pip install rsg[ray]``).

Connects to the cluster named by ``RAY_ADDRESS`` (or starts a local instance) unless
Ray is already initialised, and runs a job function as Ray tasks, at most ``workers``
at a time; results are yielded as they finish, so the caller records them (and can
resume) exactly as with the process backend.
"""

from __future__ import annotations

import os
from collections.abc import Callable, Iterator
from typing import TypeVar

from planner.exceptions import RsgError

T = TypeVar("T")
R = TypeVar("R")


def run_on_ray(
    function: Callable[[T], R], arguments: list[T], workers: int
) -> Iterator[tuple[T, R]]:
    """(argument, result) of ``function`` (a module-level function) for each argument,
    as Ray tasks, ``workers`` in flight, in the order they finish.

    Raises:
        RsgError: Ray is not installed.
    """
    try:
        import ray
    except ImportError as exc:
        raise RsgError("--backend ray needs Ray: pip install 'rsg[ray]'") from exc
    if not ray.is_initialized():
        address = os.environ.get("RAY_ADDRESS")
        ray.init(address=address, num_cpus=None if address else workers,
                 include_dashboard=False, log_to_driver=False)  # fmt: skip
    remote = ray.remote(num_cpus=1)(function)
    pending: dict = {}
    queue = list(arguments)
    try:
        while queue or pending:
            while queue and len(pending) < workers:
                argument = queue.pop(0)
                pending[remote.remote(argument)] = argument
            done, _ = ray.wait(list(pending), num_returns=1)
            for ref in done:
                yield pending.pop(ref), ray.get(ref)
    finally:
        for ref in pending:
            ray.cancel(ref)
