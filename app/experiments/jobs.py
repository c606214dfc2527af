"""Resumable jobs in parallel: the engine of ``rsg sweep``, ``pushes``, ``protocol``
and the monotonicity check.

Workers: jobs run in worker processes (``concurrent.futures``) or on a Ray cluster
(``backend="ray"``, :mod:`app.experiments.ray_pool`); at most :func:`max_workers` and
never more than there are jobs. A worker process ends when the process that started
it does (:func:`_die_with_parent`), so a killed command (SIGKILL) leaves no orphans.

Resume: every finished job is appended to ``jobs.jsonl`` in the output folder at once;
the same command started again on the folder skips the jobs found there. The folder's
specification file must be one the command wrote with the same result-defining
settings and every line of ``jobs.jsonl`` a job record of it, else the folder is
refused (with the way out: another ``--out``, or ``--overwrite``); an unfinished last
line (a command killed while writing it) is dropped and its job runs again.
"""

from __future__ import annotations

import ctypes
import json
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import ProcessPoolExecutor, as_completed
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Any, TypeVar

from app.results.folder import RESULT_FILES, ResultFolderError, prepare_out
from planner.exceptions import ParameterError, RsgError

T = TypeVar("T")
R = TypeVar("R")
JOBS_FILE = "jobs.jsonl"
MAX_RAY_WORKERS = 1024
PARENT_POLL_PERIOD = 0.5  # [s] how often a worker checks that its parent still runs
START_OVER = "use another --out, or add --overwrite to start over"
#: Result-defining fields added to the specifications later -> the value the runs stored
#: before had (``reality``: the full robot ran ideal before the profiles existed).
FIELDS_ADDED = {"reality": "ideal"}


class JobProgress:
    """``done/total`` bar with elapsed time and estimate, on stderr."""

    def __init__(
        self,
        total: int,
        done: int = 0,
        enabled: bool = True,
        label: str = "sweep",
        unit: str = "jobs",
    ) -> None:
        self.total, self.done, self.enabled = total, done, enabled
        self.label, self.unit = label, unit
        self.started = time.perf_counter()
        self.new = 0
        self.show()

    def advance(self) -> None:
        self.done += 1
        self.new += 1
        self.show()

    def show(self) -> None:
        if not self.enabled:
            return
        elapsed = time.perf_counter() - self.started
        left = (self.total - self.done) * elapsed / self.new if self.new else math.nan
        bar = "#" * int(25 * self.done / max(self.total, 1))
        eta = f"~{left:.0f} s left" if math.isfinite(left) else ""
        end = "\n" if self.done >= self.total else ""
        sys.stderr.write(
            f"\r{self.label} [{bar:<25}] {self.done}/{self.total} {self.unit} {elapsed:.0f} s "
            f"{eta:<16}{end}"
        )
        sys.stderr.flush()


def max_workers(backend: str = "process") -> int:
    """The most workers a sweep or grid starts: 4 per CPU of this machine for processes
    (more only share the CPUs and multiply the memory), :data:`MAX_RAY_WORKERS` tasks in
    flight on a Ray cluster."""
    return MAX_RAY_WORKERS if backend == "ray" else 4 * (os.cpu_count() or 1)


def check_workers(workers: int, backend: str = "process") -> None:
    """Raise a ParameterError naming ``--workers`` unless 1 <= workers <= max_workers."""
    most = max_workers(backend)
    if isinstance(workers, bool) or not (isinstance(workers, int) and 1 <= workers <= most):
        raise ParameterError(
            "--workers", workers, f"an integer in [1, {most}] ({backend} backend on this machine)"
        )


def load_finished(
    out: Path,
    spec: Any,
    spec_file: str,
    fields: tuple[str, ...],
    parse: Callable[[bytes], tuple[dict | None, str]],
) -> dict[str, dict]:
    """Jobs already finished in ``out`` (resume); checks the folder's files.

    Args:
        spec: A frozen dataclass with defaults (:class:`SweepSpec`, or another
            command's), stored in ``out / spec_file``; ``fields`` are those that
            change a job's result.
        parse: A line of ``jobs.jsonl`` -> (record, "") or (None, what is wrong).

    Raises:
        ParameterError: The folder holds a run with other result-defining settings.
        ResultFolderError: ``spec_file`` or ``jobs.jsonl`` is not one ``rsg`` wrote (not
            UTF-8 JSON, not a specification, a line that is not a job record, a
            folder), or ``jobs.jsonl`` has no specification beside it.
    """
    spec_path, jobs_path = out / spec_file, out / JOBS_FILE
    if os.path.lexists(jobs_path) and not os.path.lexists(spec_path):
        raise ResultFolderError(
            jobs_path, f"has no {spec_file} beside it to check its jobs against", START_OVER
        )
    if os.path.lexists(spec_path):
        old = _read_spec(spec_path, type(spec))
        # Tuples as JSON lists, as stored.
        new, defaults = (json.loads(json.dumps(asdict(s))) for s in (spec, type(spec)()))
        for name in fields:  # a field missing from an older spec had its default then
            stored = old.get(name, FIELDS_ADDED.get(name, defaults[name]))
            if stored != new[name]:
                raise ParameterError(
                    f"--out {out} ({name})",
                    asdict(spec)[name],
                    f"the same {name} as the run stored there ({stored!r}), "
                    "or a new --out folder, or --overwrite to start that run over",
                )
    if not os.path.lexists(jobs_path):
        return {}
    return _read_jobs(jobs_path, parse)


def _read_spec(path: Path, kind: type) -> dict:
    """The stored specification (a JSON object with ``kind``'s fields)."""
    try:
        old = json.loads(path.read_bytes().decode("utf-8"))
    except (OSError, UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        reason = exc.strerror if isinstance(exc, OSError) else type(exc).__name__
        raise ResultFolderError(
            path, f"is not a sweep specification rsg sweep wrote ({reason})", START_OVER
        ) from None
    known = set(asdict(kind()))
    if not isinstance(old, dict) or "model" not in old or not set(old) <= known:
        raise ResultFolderError(
            path, "is not a sweep specification rsg sweep wrote (other fields)", START_OVER
        )
    return old


def _read_jobs(path: Path, parse: Callable[[bytes], tuple[dict | None, str]]) -> dict[str, dict]:
    """The records of ``jobs.jsonl``; an unfinished last line (no newline: the sweep was
    killed while writing it) is dropped from the file, with a note on stderr."""
    try:
        data = path.read_bytes()
    except OSError as exc:
        raise ResultFolderError(path, f"cannot be read ({exc.strerror})", START_OVER) from None
    lines = data.split(b"\n")
    complete, last = lines[:-1], lines[-1]
    finished: dict[str, dict] = {}
    for number, line in enumerate(complete, start=1):
        if not line.strip():
            continue
        record, problem = parse(line)
        if record is None:
            raise ResultFolderError(
                path, f"line {number} is not a job record of rsg sweep ({problem})", START_OVER
            )
        finished[record["key"]] = record
    if last.strip():
        record, _ = parse(last)
        if record is not None:
            finished[record["key"]] = record
            keep = len(data)
        else:
            keep = len(data) - len(last)
            print(
                f"{path}: dropped its unfinished last line (a sweep stopped while writing "
                "it); that job runs again",
                file=sys.stderr,
            )
        try:
            with path.open("r+b") as file:
                file.truncate(keep)
                if keep == len(data):
                    file.seek(keep)
                    file.write(b"\n")
        except OSError as exc:
            raise ResultFolderError(
                path, f"cannot be repaired ({exc.strerror})", START_OVER
            ) from exc
    return finished


def parse_keyed(line: bytes) -> tuple[dict | None, str]:
    """(record, "") for a JSON object with a string ``key``, else (None, what is wrong)."""
    try:
        record = json.loads(line.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        return None, type(exc).__name__
    if not isinstance(record, dict) or not isinstance(record.get("key"), str):
        return None, "not a JSON object with a key"
    return record, ""


@dataclass(frozen=True)
class JobRun:
    """Where and how a command's jobs run.

    Attributes:
        out: The results folder; it holds ``jobs.jsonl`` and the specification, so the
            same command on it resumes.
        workers: Parallel workers, at most :func:`max_workers`.
        backend: ``process`` (worker processes) or ``ray`` (a Ray cluster).
        progress: A progress bar on stderr.
        overwrite: Delete the folder's earlier ``rsg`` results first.
    """

    out: Path
    workers: int = 1
    backend: str = "process"
    progress: bool = True
    overwrite: bool = False


def run_resumable(
    function: Callable[[T], dict],
    arguments: dict[str, T],
    spec: Any,
    fields: tuple[str, ...],
    spec_file: str,
    run: JobRun,
    label: str = "sweep",
    unit: str = "jobs",
    parse: Callable[[bytes], tuple[dict | None, str]] = parse_keyed,
) -> dict[str, dict]:
    """The records of ``function`` over ``arguments`` (key -> argument; each record
    carries its ``key``), run as ``run`` says or taken from its folder's ``jobs.jsonl``:
    each new record is appended there as soon as it is done, and ``spec`` is stored in
    ``spec_file`` (:func:`load_finished` checks ``fields`` on a resume). The progress
    bar is labelled ``label`` and counts ``unit``; ``parse`` reads a line of
    ``jobs.jsonl`` back (default: any JSON object with a ``key``).

    ``label`` is also the command whose files of :data:`app.results.folder.RESULT_FILES`
    are resumed; ``run.overwrite`` deletes them (and any other ``rsg`` results) first.

    Raises:
        ParameterError: Bad workers/backend or a mismatching folder.
        RsgError: The folder cannot be written, or holds files that are not this
            command's (:func:`app.results.folder.prepare_out`, :func:`load_finished`).
    """
    out, workers, backend, progress = run.out, run.workers, run.backend, run.progress
    check_workers(workers, backend)
    if backend not in ("process", "ray"):
        raise ParameterError("--backend", backend, "process or ray")
    own = () if run.overwrite else RESULT_FILES[label]
    for path in prepare_out(out, label, run.overwrite, resumable=own):
        if progress:
            print(f"deleted {path} (--overwrite)", file=sys.stderr)
    try:
        out.mkdir(parents=True, exist_ok=True)
        finished = load_finished(out, spec, spec_file, fields, parse)
        (out / spec_file).write_text(json.dumps(asdict(spec), indent=2) + "\n")
    except OSError as exc:
        raise RsgError(f"cannot write the results to {out}: {exc}") from exc
    todo = [argument for key, argument in arguments.items() if key not in finished]
    workers = min(workers, max(len(todo), 1))
    bar = JobProgress(len(arguments), len(arguments) - len(todo), progress, label, unit)
    with (out / JOBS_FILE).open("a") as sink:
        for _, record in run_jobs(function, todo, workers, backend):
            sink.write(json.dumps(record) + "\n")
            sink.flush()
            finished[record["key"]] = record
            bar.advance()
    return finished


def run_jobs(
    function: Callable[[T], R], arguments: list[T], workers: int, backend: str = "process"
) -> Iterator[tuple[T, R]]:
    """(argument, result) of ``function`` for each argument, in the order they finish,
    in worker processes (:func:`run_in_processes`) or as Ray tasks (``backend="ray"``,
    :func:`app.experiments.ray_pool.run_on_ray`)."""
    if not arguments:
        return
    if backend == "ray":
        from app.experiments.ray_pool import run_on_ray

        yield from run_on_ray(function, arguments, workers)
        return
    yield from run_in_processes(function, arguments, workers)


def run_in_processes(
    function: Callable[[T], R], arguments: list[T], workers: int
) -> Iterator[tuple[T, R]]:
    """(argument, result) of ``function`` for each argument, in the order they finish:
    in this process for one worker, else in a pool of at most one worker per argument
    whose workers end with this process (pending work is cancelled on error)."""
    workers = min(workers, len(arguments))
    if workers <= 1:
        for argument in arguments:
            yield argument, function(argument)
        return
    with ProcessPoolExecutor(
        max_workers=workers, initializer=_die_with_parent, initargs=(os.getpid(),)
    ) as pool:
        futures = {pool.submit(function, argument): argument for argument in arguments}
        try:
            for future in as_completed(futures):
                yield futures[future], future.result()
        except BaseException:
            for future in futures:
                future.cancel()
            raise


PR_SET_PDEATHSIG = 1  # linux/prctl.h


def _die_with_parent(parent: int) -> None:
    """Worker initializer: end this worker when the process that started it ends, so a
    sweep or grid killed by SIGKILL (which it cannot catch) leaves no orphan computing
    for minutes. On Linux the kernel sends SIGKILL at the parent's death
    (``prctl(PR_SET_PDEATHSIG)``, called through ctypes); everywhere, and as a backup, a
    daemon thread checks every :data:`PARENT_POLL_PERIOD` that the parent is still the
    parent (an orphan is re-parented)."""
    if sys.platform.startswith("linux"):
        try:
            libc = ctypes.CDLL(None, use_errno=True)
            libc.prctl(PR_SET_PDEATHSIG, signal.SIGKILL, 0, 0, 0)
        except (OSError, AttributeError):
            pass  # the thread below still watches
    if os.getppid() != parent:  # the parent died before the line above
        os._exit(1)
    threading.Thread(target=_watch_parent, args=(parent,), daemon=True).start()


def _watch_parent(parent: int) -> None:
    while os.getppid() == parent:
        time.sleep(PARENT_POLL_PERIOD)
    os._exit(1)
