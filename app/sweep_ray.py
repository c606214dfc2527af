"""Running the jobs of ``rsg sweep`` on a Ray cluster (``pip install rsg[ray]``).

Connects to the cluster named by ``RAY_ADDRESS`` (or starts a local instance) unless
Ray is already initialised, and runs :func:`app.sweep.run_job` as Ray tasks, at most
``workers`` at a time; results are yielded as they finish, so the caller records
them (and can resume) exactly as with the process backend.
"""

from __future__ import annotations

import os
from collections.abc import Iterator

from planner.exceptions import RsgError

from .sweep import Job, SweepSpec, run_job


def execute_on_ray(spec: SweepSpec, jobs: list[Job], workers: int) -> Iterator[dict]:
    """Run ``jobs`` as Ray tasks, ``workers`` in flight; yield each record when done.

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
    remote = ray.remote(num_cpus=1)(run_job)
    pending: list = []
    queue = list(jobs)
    try:
        while queue or pending:
            while queue and len(pending) < workers:
                pending.append(remote.remote(spec, queue.pop(0)))
            done, pending = ray.wait(pending, num_returns=1)
            for ref in done:
                yield ray.get(ref)
    finally:
        for ref in pending:
            ray.cancel(ref)
