"""``rsg sweep``: the largest recovered impulse per controller, direction and push phase.

Jobs: one job is (controller, direction, phase). It bisects the impulse magnitude
[N s] of a single push along the direction between 0 and ``bracket`` times the
capture bound (:mod:`app.capturability`, an upper limit for any controller on the
LIPM) and returns the largest impulse that is still recovered, to ``tolerance``.
Recovery is assumed monotone in the magnitude.

Push phase: the LIPM walk starts in single support on the left foot at s~ = T_DSP,
so nominal step k (k = 1, 2, ...) lands at t_k = T_SSP + (k - 1) T^*. Cycle k is
[t_k, t_k + T^*) on the stance foot of step k (right for odd k). Phase p in [0, 1)
puts the push start at t = t_k + p T^* of cycle ``cycle`` (default 3, right stance),
i.e. at s~ = p T^* after the step; the run lasts ``settle`` seconds after that.

Directions: n directions at angle 2 pi i / n in the world frame, 0 = forward (+x),
90 deg = to the left (+y).

Workers: jobs run in worker processes (``concurrent.futures``) or on a Ray cluster
(``backend="ray"``, :mod:`app.sweep_ray`); at most :func:`max_workers` and never more
than there are jobs. A worker process ends when the process that started it does
(:func:`_die_with_parent`), so a killed sweep (SIGKILL) leaves no orphans behind.

Resume: every finished job is appended to ``jobs.jsonl`` in the output folder at once;
a sweep started again on the same folder skips the jobs found there, so an interrupted
sweep resumes where it stopped. The folder's ``sweep_spec.json`` must be one written by
``rsg sweep`` with the same result-defining settings and every line of ``jobs.jsonl`` a
job record of it, else the folder is refused (with the way out: another ``--out``, or
``--overwrite`` to start over); an unfinished last line (a sweep killed while writing
it) is dropped and its job runs again.
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
from typing import Any, Protocol, TypeVar

import numpy as np

from planner.exceptions import ParameterError, RsgError
from planner.parameters import CONTROLLERS
from planner.types import Push

from .bisection import bisect_threshold
from .capturability import impulse_bound
from .overrides import Overrides, check_overrides
from .result_folder import RESULT_FILES, ResultFolderError, prepare_out
from .scenarios import Scenario
from .setup import DEFAULT_ROBOT, resolve_robot
from .sweep_trial import SettledTrial, measured_touchdown, push_timing

PLACO_WPG = "placo-wpg"
T = TypeVar("T")
R = TypeVar("R")


class GridLike(Protocol):
    """What :func:`build_controller` reads of a specification."""

    @property
    def model(self) -> str: ...
    @property
    def robot(self) -> str | None: ...
    @property
    def paper_rules(self) -> bool: ...
    @property
    def fall_dcm_error(self) -> float: ...
    @property
    def overrides(self) -> Overrides: ...


SWEEP_CONTROLLERS = (*CONTROLLERS, PLACO_WPG)
JOBS_FILE = "jobs.jsonl"
SPEC_FILE = "sweep_spec.json"
MAX_PHASES = 100
MAX_RAY_WORKERS = 1024
PARENT_POLL_PERIOD = 0.5  # [s] how often a worker checks that its parent still runs
START_OVER = "use another --out, or add --overwrite to start the sweep over"
#: A job record's fields and their types (what the envelope and its plot read).
RECORD_FIELDS: dict[str, type | tuple[type, ...]] = {
    "key": str,
    "controller": str,
    "direction_deg": (int, float),
    "phase": (int, float),
    "impulse": (int, float),
    "bound": (int, float),
    "ratio": (int, float),
    "capped": bool,
    "runs": int,
    "stance": str,
    "push_time": (int, float),
}
# Fields that change a job's result: a resumed sweep must agree on them.
RESULT_FIELDS = ("model", "robot", "duration", "cycle", "settle", "tolerance", "bracket",
                 "qp_solver", "criterion", "fall_dcm_error", "paper_rules",
                 "overrides", "timing")  # fmt: skip


def check_pushes(
    model: str,
    controllers: tuple[str, ...],
    directions: int,
    phases: tuple[float, ...],
    overrides: Overrides = (),
    robot: str | None = None,
) -> None:
    """Validate what a sweep and a push grid share.

    Raises:
        ParameterError: naming the field, the value and what is allowed.
    """
    if model not in ("lipm", "pybullet"):
        raise ParameterError("model", model, "lipm or pybullet")
    bad = [c for c in controllers if c not in SWEEP_CONTROLLERS]
    if bad or not controllers or len(set(controllers)) != len(controllers):
        raise ParameterError(
            "controllers", ",".join(controllers), f"distinct of {SWEEP_CONTROLLERS}"
        )
    if PLACO_WPG in controllers and model != "pybullet":
        raise ParameterError(
            "controllers",
            PLACO_WPG,
            "placo-wpg only with --model pybullet (it drives the full robot's IK; "
            "on the LIPM it has no meaning)",
        )
    if isinstance(directions, bool) or not (isinstance(directions, int) and 1 <= directions <= 360):
        raise ParameterError("directions", directions, "an integer in [1, 360]")
    if not (
        0 < len(phases) <= MAX_PHASES
        and all(isinstance(p, float | int) and 0.0 <= p < 1.0 for p in phases)
        and len(set(phases)) == len(phases)
    ):
        raise ParameterError(
            "phases", phases, f"1 to {MAX_PHASES} distinct fractions in [0, 1) of the cycle"
        )
    for controller in controllers:  # every range, before any worker starts
        check_overrides(overrides, model, robot, "rsg" if controller == PLACO_WPG else controller)


@dataclass(frozen=True)
class SweepSpec:
    """What to sweep.

    Attributes:
        model: ``lipm`` or ``pybullet``.
        robot: The robot (:func:`app.setup.resolve_robot`: ``None`` is G1 on ``pybullet`` and
            the paper's point mass on ``lipm``).
        controllers: Controllers to compare.
        directions: Number of push directions, evenly spaced.
        phases: Push phases p in [0, 1) of the walking cycle.
        duration: Push duration Delta [s].
        cycle: Walking cycle (>= 1) in which the push starts.
        settle: Simulated time after the push start [s].
        tolerance: Bisection tolerance on the impulse [N s].
        bracket: Upper end of the bisection, times the capture bound [-].
        qp_solver: ``exact`` or ``proxqp`` for the QP (27) (equal results).
        criterion: ``recovered`` (RunResult.recovered) or ``no-fall``.
        fall_dcm_error: DCM error that counts as a fall on the LIPM [m]. The LIPM
            backend's own default (0.5 m) is a heuristic below the capturable DCM
            error of many pushes (up to ~1 m); the sweep keeps only its leg-reach
            rule in effect (CoM within 0.6 m of the stance ankle) by default.
        paper_rules: The paper's rules (:data:`app.setup.PAPER_RULES` off).
        overrides: ``--set`` (name, value) pairs (:mod:`app.overrides`).
        timing: ``nominal``: the push starts at t_k + phase T^* with t_k the nominal
            touchdown (:func:`app.sweep_trial.push_timing`); ``touchdown``: t_k is
            the touchdown measured in the unpushed walk of each controller and model
            (:func:`app.sweep_trial.measured_touchdown`; ``rsg protocol``).
    """

    model: str = "lipm"
    robot: str | None = None
    controllers: tuple[str, ...] = CONTROLLERS
    directions: int = 16
    phases: tuple[float, ...] = (0.0, 0.25, 0.5, 0.75)
    duration: float = 0.1
    cycle: int = 3
    settle: float = 6.0
    tolerance: float = 0.25
    bracket: float = 1.1
    qp_solver: str = "exact"
    criterion: str = "recovered"
    fall_dcm_error: float = 2.0
    paper_rules: bool = False
    overrides: Overrides = ()
    timing: str = "nominal"

    def __post_init__(self) -> None:
        object.__setattr__(self, "robot", resolve_robot(self.model, self.robot))
        check_pushes(
            self.model, self.controllers, self.directions, self.phases, self.overrides, self.robot
        )
        if self.timing not in ("nominal", "touchdown"):
            raise ParameterError("timing", self.timing, "nominal or touchdown")
        checks = {
            "duration": (self.duration, 1e-3, 1.0),
            "settle": (self.settle, 1.0, 60.0),
            "tolerance": (self.tolerance, 1e-3, 50.0),
            "bracket": (self.bracket, 0.1, 10.0),
            "fall_dcm_error": (self.fall_dcm_error, 0.05, 100.0),
        }
        for name, (value, low, high) in checks.items():
            if not (math.isfinite(value) and low <= value <= high):
                raise ParameterError(name, value, f"a number in [{low}, {high}]")
        if not (isinstance(self.cycle, int) and 1 <= self.cycle <= 20):
            raise ParameterError("cycle", self.cycle, "an integer in [1, 20]")
        if self.qp_solver not in ("exact", "proxqp"):
            raise ParameterError("qp_solver", self.qp_solver, "exact or proxqp")
        if self.criterion not in ("recovered", "no-fall"):
            raise ParameterError("criterion", self.criterion, "recovered or no-fall")

    def angles(self) -> list[float]:
        """Push directions [rad]."""
        return [2.0 * math.pi * i / self.directions for i in range(self.directions)]


@dataclass(frozen=True)
class Job:
    """One bisection: controller, direction [rad] and phase [-]."""

    controller: str
    angle: float
    phase: float

    @property
    def key(self) -> str:
        return f"{self.controller}|{math.degrees(self.angle):.4f}|{self.phase:.4f}"


def _build(spec: SweepSpec, controller: str):  # noqa: ANN202
    """Backend, configuration and initial condition (see :func:`build_controller`)."""
    return build_controller(spec, controller)[:3]


def build_controller(spec: SweepSpec | GridLike, controller: str):  # noqa: ANN202
    """Backend, configuration, initial condition and planner factory (None: the RSG's)
    of ``controller`` on ``spec``'s model and robot."""
    if controller == PLACO_WPG:
        from .placo_wpg import build_placo_wpg_backend

        return build_placo_wpg_backend(spec.robot or DEFAULT_ROBOT, spec.overrides)
    return (*_build_rsg(spec, controller), None)


def _build_rsg(spec: SweepSpec | GridLike, controller: str):  # noqa: ANN202
    from .setup import build_backend

    backend, config, initial = build_backend(
        spec.model, spec.robot, controller, spec.paper_rules, spec.overrides
    )
    if spec.model == "lipm":
        from .lipm_backend import LipmBackend

        backend = LipmBackend(config.model, fall_dcm_error=spec.fall_dcm_error)
    return backend, config, initial


def run_job(spec: SweepSpec, job: Job) -> dict:
    """Bisect one job; returns its JSON-ready record (what ``jobs.jsonl`` holds)."""
    from .runner import run_closed_loop

    started = time.perf_counter()
    backend, config, initial, planner = build_controller(spec, job.controller)
    runner = getattr(backend, "run_closed_loop", None) or run_closed_loop
    options = {} if planner is None else {"planner": planner}
    early = spec.model == "lipm" and spec.criterion == "recovered"
    try:
        t_push, sigma, since = push_timing(config, spec.cycle, job.phase)
        if spec.timing == "touchdown":
            touchdown = measured_touchdown(runner, backend, config, initial, spec.cycle, **options)
            t_push = touchdown + since
        bound = impulse_bound(config, job.angle, sigma, since, spec.duration)
        direction = np.array([math.cos(job.angle), math.sin(job.angle)])
        trial = None
        if early:
            trial = SettledTrial(
                backend, config, initial, t_push, t_push + spec.settle, spec.qp_solver
            )

        def recovered(impulse: float) -> bool:
            push = Push(t_push, impulse * direction, spec.duration)
            scenario = Scenario("sweep", t_push + spec.settle, (push,))
            if trial is not None:
                return trial.recovered(push)
            result = runner(backend, config, scenario, initial, qp_solver=spec.qp_solver, **options)
            if spec.criterion == "no-fall":
                return not result.fall.fell
            return bool(result.recovered)

        found = bisect_threshold(recovered, spec.bracket * bound, spec.tolerance)
    finally:
        backend.close()
    return {
        "key": job.key,
        "controller": job.controller,
        "direction_deg": math.degrees(job.angle),
        "phase": job.phase,
        "push_time": t_push,
        "stance": "left" if sigma > 0 else "right",
        "impulse": found.passed,
        "failed_at": found.failed,
        "capped": found.failed is None,
        "bound": bound,
        "ratio": found.passed / bound if bound > 0 else math.nan,
        "mass": config.model.mass,
        "runs": len(found.evaluations),
        "evaluations": found.evaluations,
        "wall_time": time.perf_counter() - started,
    }


def _run_job_args(args: tuple[SweepSpec, Job]) -> dict:
    return run_job(*args)


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


def load_finished(
    out: Path,
    spec: Any,
    spec_file: str = SPEC_FILE,
    fields: tuple[str, ...] = RESULT_FIELDS,
    sweep_records: bool = True,
) -> dict[str, dict]:
    """Jobs already finished in ``out`` (resume); checks the folder's files.

    Args:
        spec: A frozen dataclass with defaults (:class:`SweepSpec`, or another
            command's), stored in ``out / spec_file``; ``fields`` are those that
            change a job's result.
        sweep_records: The jobs are the sweep's bisections (their fields are checked);
            otherwise any JSON object with a ``key``.

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
        for name in fields:  # a field missing from an older spec had its default
            stored = old.get(name, defaults[name])
            if stored != new[name]:
                raise ParameterError(
                    f"--out {out} ({name})",
                    asdict(spec)[name],
                    f"the same {name} as the run stored there ({stored!r}), "
                    "or a new --out folder, or --overwrite to start that run over",
                )
    if not os.path.lexists(jobs_path):
        return {}
    return _read_jobs(jobs_path, _parse_record if sweep_records else _parse_keyed)


def _read_spec(path: Path, kind: type = SweepSpec) -> dict:
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


def _parse_keyed(line: bytes) -> tuple[dict | None, str]:
    """(record, "") for a JSON object with a string ``key``, else (None, what is wrong)."""
    try:
        record = json.loads(line.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        return None, type(exc).__name__
    if not isinstance(record, dict) or not isinstance(record.get("key"), str):
        return None, "not a JSON object with a key"
    return record, ""


def _parse_record(line: bytes) -> tuple[dict | None, str]:
    """(record, "") for a valid job record, else (None, what is wrong)."""
    try:
        record = json.loads(line.decode("utf-8"))
    except (UnicodeDecodeError, json.JSONDecodeError, RecursionError) as exc:
        return None, type(exc).__name__
    if not isinstance(record, dict):
        return None, f"a JSON {type(record).__name__}, not an object"
    for name, kind in RECORD_FIELDS.items():
        value = record.get(name)
        if not isinstance(value, kind) or (isinstance(value, bool) and kind is not bool):
            return None, f"field {name} missing or not a {getattr(kind, '__name__', 'number')}"
    job = Job(record["controller"], math.radians(record["direction_deg"]), record["phase"])
    if job.key != record["key"]:
        return None, f"key {record['key'][:40]!r} does not match its fields"
    return record, ""


def all_jobs(spec: SweepSpec) -> list[Job]:
    return [
        Job(controller, angle, phase)
        for controller in spec.controllers
        for phase in spec.phases
        for angle in spec.angles()
    ]


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


def run_sweep(
    spec: SweepSpec,
    out: Path,
    workers: int = 1,
    backend: str = "process",
    progress: bool = True,
    jobs: list[Job] | None = None,
    label: str = "sweep",
    overwrite: bool = False,
) -> list[dict]:
    """Run (or resume) the sweep into ``out``; returns the records of all its jobs
    (``jobs``, default :func:`all_jobs`; ``label`` names the progress bar).

    Raises:
        ParameterError: Bad workers/backend or a mismatching folder.
        RsgError: The folder cannot be written.
    """
    jobs = all_jobs(spec) if jobs is None else jobs
    arguments = {job.key: (spec, job) for job in jobs}
    finished = run_resumable(
        _run_job_args,
        arguments,
        out,
        spec,
        RESULT_FIELDS,
        SPEC_FILE,
        workers,
        backend,
        progress,
        label,
        overwrite=overwrite,
    )
    return [finished[job.key] for job in jobs]


def run_resumable(
    function: Callable[[T], dict],
    arguments: dict[str, T],
    out: Path,
    spec: Any,
    fields: tuple[str, ...],
    spec_file: str,
    workers: int,
    backend: str,
    progress: bool,
    label: str = "sweep",
    unit: str = "jobs",
    overwrite: bool = False,
) -> dict[str, dict]:
    """The records of ``function`` over ``arguments`` (key -> argument; each record
    carries its ``key``), run in ``workers`` or taken from ``out``'s ``jobs.jsonl``:
    each new record is appended there as soon as it is done, and ``spec`` is stored in
    ``spec_file`` (:func:`load_finished` checks ``fields`` on a resume). ``progress``:
    a bar labelled ``label`` counting ``unit`` on stderr.

    ``label`` is also the command whose files of :data:`app.result_folder.RESULT_FILES`
    are resumed; ``overwrite`` deletes them (and any other ``rsg`` results) first.

    Raises:
        ParameterError: Bad workers/backend or a mismatching folder.
        RsgError: The folder cannot be written, or holds files that are not this
            command's (:func:`app.result_folder.prepare_out`, :func:`load_finished`).
    """
    check_workers(workers, backend)
    if backend not in ("process", "ray"):
        raise ParameterError("--backend", backend, "process or ray")
    own = () if overwrite else RESULT_FILES[label]
    for path in prepare_out(out, label, overwrite, resumable=own):
        if progress:
            print(f"deleted {path} (--overwrite)", file=sys.stderr)
    try:
        out.mkdir(parents=True, exist_ok=True)
        finished = load_finished(out, spec, spec_file, fields, function is _run_job_args)
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
    :func:`app.sweep_ray.run_on_ray`)."""
    if not arguments:
        return
    if backend == "ray":
        from .sweep_ray import run_on_ray

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
