"""``rsg sweep``: the largest recovered impulse per controller, direction and push phase.

Jobs: one job is (controller, direction, phase). It bisects the impulse magnitude
[N s] of a single push along the direction between 0 and ``bracket`` times the
capture bound (:mod:`app.experiments.capturability`, an upper limit for any controller on the
LIPM) and returns the largest impulse that is still recovered, to ``tolerance``.
Recovery is assumed monotone in the magnitude.

Push phase: the LIPM walk starts in single support on the left foot at s~ = T_DSP,
so nominal step k (k = 1, 2, ...) lands at t_k = T_SSP + (k - 1) T^*. Cycle k is
[t_k, t_k + T^*) on the stance foot of step k (right for odd k). Phase p in [0, 1)
puts the push start at t = t_k + p T^* of cycle ``cycle`` (default 3, right stance),
i.e. at s~ = p T^* after the step; the run lasts ``settle`` seconds after that.

Directions: n directions at angle 2 pi i / n in the world frame, 0 = forward (+x),
90 deg = to the left (+y).

Jobs run in parallel and resume after an interruption (:mod:`app.experiments.jobs`);
a resumed sweep must agree on :data:`RESULT_FIELDS`, and every line of its
``jobs.jsonl`` must be a job record of it.
"""

from __future__ import annotations

import json
import math
import time
from dataclasses import dataclass

import numpy as np

from app.experiments.bisection import bisect_threshold
from app.experiments.capture_bound import impulse_bound
from app.experiments.jobs import JobRun, run_resumable
from app.experiments.trial import SettledTrial, measured_touchdown, push_timing
from app.reality import DEFAULT_PROFILE, check_profile, trial_seed
from app.scenarios import Scenario
from app.setup.build import resolve_robot
from app.setup.overrides import (
    MODELS,
    ROBOT_MODELS,
    Overrides,
    check_overrides,
    is_robot_model,
)
from planner.exceptions import ParameterError
from planner.parameters import CONTROLLERS
from planner.types import Push
from robots import DEFAULT_ROBOT

PLACO_WPG = "placo-wpg"


@dataclass(frozen=True)
class PushExperiment:
    """What every push experiment (sweep, grid, campaign) shares: the controllers, the
    model and robot they run on, and how they are built (:func:`build_controller`).

    Attributes:
        model: ``lipm`` or a full robot's engine (:data:`app.setup.overrides.ROBOT_MODELS`:
            ``pybullet``, ``mujoco``).
        robot: The robot (:func:`app.setup.build.resolve_robot`: ``None`` is G1 on a
            full-robot model and the paper's point mass on ``lipm``).
        controllers: Controllers to compare.
        paper_rules: The paper's rules (:data:`app.setup.paper_rules.PAPER_RULES` off).
        fall_dcm_error: DCM error that counts as a fall on the LIPM [m]. The LIPM
            backend's own default (0.5 m) is a heuristic below the capturable DCM error
            of many pushes (up to ~1 m); by default only its leg-reach rule decides (CoM
            within 0.6 m of the stance ankle).
        overrides: ``--set`` (name, value) pairs (:mod:`app.setup.overrides`).
        reality: Profile of :mod:`app.reality` (``--reality``) of the full robot; each
            trial draws its own from its seed (:func:`push_reality_seed`, the campaign's
            :func:`app.experiments.campaign.push_seed`); ignored on ``lipm``.
    """

    model: str = "lipm"
    robot: str | None = None
    controllers: tuple[str, ...] = CONTROLLERS
    paper_rules: bool = False
    fall_dcm_error: float = 2.0
    overrides: Overrides = ()
    reality: str = DEFAULT_PROFILE

    def __post_init__(self) -> None:
        object.__setattr__(self, "robot", resolve_robot(self.model, self.robot))
        check_profile(self.reality)


#: Seed of the sweep's and the grid's reality draws (they have no seed of their own).
REALITY_SEED = 0
#: Digits of a direction [deg], phase [-] or impulse [N s] in a trial's key: the job keys'.
KEY_SCALE = 10_000


def push_reality_seed(direction_deg: float, phase: float, impulse: float | None = None) -> int:
    """Seed of the reality of the push trial at ``direction_deg``, ``phase`` (and
    ``impulse`` [N s], for a grid's single runs; a sweep's bisection is one trial over its
    impulses): :func:`app.reality.trial_seed` of :data:`REALITY_SEED` and the values to 4
    decimals. Every controller meets the same robot on the same push."""
    keys = [round(direction_deg * KEY_SCALE), round(phase * KEY_SCALE)]
    if impulse is not None:
        keys.append(round(impulse * KEY_SCALE))
    return trial_seed(REALITY_SEED, *keys)


def result_fields(fields: tuple[str, ...], spec: PushExperiment) -> tuple[str, ...]:
    """``fields`` that change a result of ``spec``: without ``reality`` on the LIPM (which
    ignores it), so an LIPM folder resumes whatever its profile."""
    return fields if is_robot_model(spec.model) else tuple(f for f in fields if f != "reality")


SWEEP_CONTROLLERS = (*CONTROLLERS, PLACO_WPG)
SPEC_FILE = "sweep_spec.json"
MAX_PHASES = 100
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
                 "overrides", "timing", "reality")  # fmt: skip


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
    if model not in MODELS:
        raise ParameterError("model", model, f"one of {', '.join(MODELS)}")
    bad = [c for c in controllers if c not in SWEEP_CONTROLLERS]
    if bad or not controllers or len(set(controllers)) != len(controllers):
        raise ParameterError(
            "controllers", ",".join(controllers), f"distinct of {SWEEP_CONTROLLERS}"
        )
    if PLACO_WPG in controllers and not is_robot_model(model):
        raise ParameterError(
            "controllers",
            PLACO_WPG,
            f"placo-wpg only with --model {' or '.join(ROBOT_MODELS)} (it drives the full "
            "robot's IK; on the LIPM it has no meaning)",
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
class SweepSpec(PushExperiment):
    """What to sweep.

    Attributes:
        model, robot, controllers, paper_rules, fall_dcm_error, overrides: As
            :class:`PushExperiment`'s.
        directions: Number of push directions, evenly spaced.
        phases: Push phases p in [0, 1) of the walking cycle.
        duration: Push duration Delta [s].
        cycle: Walking cycle (>= 1) in which the push starts.
        settle: Simulated time after the push start [s].
        tolerance: Bisection tolerance on the impulse [N s].
        bracket: Upper end of the bisection, times the capture bound [-].
        qp_solver: ``exact`` or ``proxqp`` for the QP (27) (equal results).
        criterion: ``recovered`` (RunResult.recovered) or ``no-fall``.
        timing: ``nominal``: the push starts at t_k + phase T^* with t_k the nominal
            touchdown (:func:`app.experiments.trial.push_timing`); ``touchdown``: t_k is
            the touchdown measured in the unpushed walk of each controller and model
            (:func:`app.experiments.trial.measured_touchdown`; ``rsg protocol``).
    """

    directions: int = 16
    phases: tuple[float, ...] = (0.0, 0.25, 0.5, 0.75)
    duration: float = 0.1
    cycle: int = 3
    settle: float = 6.0
    tolerance: float = 0.25
    bracket: float = 1.1
    qp_solver: str = "exact"
    criterion: str = "recovered"
    timing: str = "nominal"

    def __post_init__(self) -> None:
        super().__post_init__()
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


def _build(spec: SweepSpec, controller: str, seed: int = 0):  # noqa: ANN202
    """Backend, configuration and initial condition (see :func:`build_controller`)."""
    return build_controller(spec, controller, seed)[:3]


def build_controller(spec: PushExperiment, controller: str, seed: int = 0):  # noqa: ANN202
    """Backend, configuration, initial condition and planner factory (None: the RSG's)
    of ``controller`` on ``spec``'s model and robot, the full robot with ``spec``'s
    reality drawn from ``seed``."""
    if controller == PLACO_WPG:
        from app.baselines.placo_wpg import build_placo_wpg_backend

        return build_placo_wpg_backend(
            spec.robot or DEFAULT_ROBOT, spec.overrides, reality=spec.reality, seed=seed,
            engine=spec.model,
        )  # fmt: skip
    return (*_build_rsg(spec, controller, seed), None)


def _build_rsg(spec: PushExperiment, controller: str, seed: int = 0):  # noqa: ANN202
    from app.setup.build import build_backend

    backend, config, initial = build_backend(
        spec.model, spec.robot, controller, spec.paper_rules, spec.overrides,
        reality=spec.reality, seed=seed,
    )  # fmt: skip
    if spec.model == "lipm":
        from app.backends.lipm import LipmBackend

        backend = LipmBackend(config.model, fall_dcm_error=spec.fall_dcm_error)
    return backend, config, initial


def run_job(spec: SweepSpec, job: Job) -> dict:
    """Bisect one job; returns its JSON-ready record (what ``jobs.jsonl`` holds)."""
    from app.runner import run_closed_loop

    started = time.perf_counter()
    seed = push_reality_seed(math.degrees(job.angle), job.phase)
    backend, config, initial, planner = build_controller(spec, job.controller, seed)
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
        "reality_seed": seed,
        "runs": len(found.evaluations),
        "evaluations": found.evaluations,
        "wall_time": time.perf_counter() - started,
    }


def _run_job_args(args: tuple[SweepSpec, Job]) -> dict:
    return run_job(*args)


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


def run_sweep(
    spec: SweepSpec, run: JobRun, jobs: list[Job] | None = None, label: str = "sweep"
) -> list[dict]:
    """Run (or resume) the sweep as ``run`` says; returns the records of all its jobs
    (``jobs``, default :func:`all_jobs`; ``label`` names the progress bar).

    Raises:
        ParameterError: Bad workers/backend or a mismatching folder.
        RsgError: The folder cannot be written.
    """
    jobs = all_jobs(spec) if jobs is None else jobs
    arguments = {job.key: (spec, job) for job in jobs}
    fields = result_fields(RESULT_FIELDS, spec)
    finished = run_resumable(
        _run_job_args, arguments, spec, fields, SPEC_FILE, run, label, parse=_parse_record
    )
    return [finished[job.key] for job in jobs]
