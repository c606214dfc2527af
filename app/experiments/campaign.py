"""``rsg pushes``: random pushes over a whole gait cycle, each beside its LIPM twin.

Draws: push i (0, 1, ...) of seed s comes from its own generator
``numpy.random.default_rng([s, i])``, so the draws do not depend on the workers or on
the order of the runs, and a campaign of N pushes is the first N of a longer one with
the same seed. In this order, each floored to a grid so that it is written exactly:

* direction uniform in [0, 360) deg (0 forward, 90 to the left), 0.1 deg;
* phase uniform in [0, 1), 0.001: the push starts ``phase`` T^* after the touchdown
  of step k = ``cycle`` in the unpushed walk, measured once per model and controller
  (:func:`app.experiments.trial.measured_touchdown`). So the phase is the fraction of the
  gait cycle T^* since the last touchdown of the nominal walk, and a push hits the robot
  and its twin at the same point of their gaits (the loop steps at the first tick in
  the nominal jump set: at the nominal t_k = T_SSP + (k - 1) T^* when the ticks fall
  on it, step 4 at 3.1 s on G1 and on its twin, later otherwise). Below
  T_DSP / T^* (0.125 on G1) the push starts in double support. The default cycle 4 is
  three nominal steps after the start, on the left stance foot;
* impulse uniform in ``impulse`` [N s], 0.01 N s; by default 5-10 N s on G1
  (33.3 kg) and the same velocity change on other robots: 5-10 N s times
  m / 33.3 kg (Talos, 90.27 kg: 13.55-27.11 N s);
* duration uniform in ``duration`` [s], 1 ms (default 0.05-0.2 s).

Seeds (:data:`SEEDS`): ``dev`` (1) is for development and tuning; ``eval`` (2) is for
reported figures only, never for choosing a parameter.

Reality (``--reality``, :mod:`app.reality`): push i's runs on the full robot, every
controller's, meet the robot drawn from :func:`push_seed` (seed s, index i), from a
stream of its own (the pushes' draws are unchanged); each run's record holds its draw.
The touchdowns the pushes are timed from are measured once per model and controller, on
the campaign's reference robot, drawn from ``push_seed(s, REFERENCE_ROBOT)`` (an index no
push has): with ``randomized`` a push's own robot may land a tick earlier or later.

The twin: each push also runs on the LIPM with the same robot's planner
(``--model lipm --robot NAME``: its mass, sole, gait and timing on the point mass,
the same controller, and the ``--set`` values that apply there), with the same push
and timing: what the planner promises if the robot realised the LIPM. On
``--model lipm`` the run is its own twin (no second run). placo-wpg has no twin.

Jobs: one run per (push, controller, robot or twin), recorded in ``jobs.jsonl`` as
soon as it is done; the same command on the same ``--out`` skips finished runs (more
pushes or controllers may be added), and a different seed, range, robot or setting
is refused (:func:`app.experiments.jobs.run_resumable`).
"""

from __future__ import annotations

import math
import time
from dataclasses import asdict, dataclass, replace

import numpy as np

from app.experiments.jobs import JobRun, run_resumable
from app.experiments.outcome import PushRun, describe, impulse_along, stance_offset_after
from app.experiments.sweep import PLACO_WPG, PushExperiment, check_pushes, result_fields
from app.reality import trial_seed
from app.scenarios import MAX_IMPULSE
from app.setup.build import build_backend
from app.setup.overrides import Overrides, allowed_names
from planner.exceptions import ParameterError
from planner.parameters import LipmModel, PlannerConfig
from planner.types import Push
from robots import get_robot

SEEDS = {"dev": 1, "eval": 2}
#: Mass [kg] the default impulse range is given for (G1's).
REFERENCE_MASS = 33.3
DEFAULT_IMPULSE = (5.0, 10.0)  # [N s] on REFERENCE_MASS
SPEC_FILE = "campaign_spec.json"
# Fields that change a run's result: a resumed campaign must agree on them.
RESULT_FIELDS = ("model", "robot", "seed", "impulse", "duration", "cycle", "settle",
                 "paper_rules", "fall_dcm_error", "overrides", "reality")  # fmt: skip


def parse_seed(text: str) -> int:
    """``dev``, ``eval`` or an integer >= 0.

    Raises:
        ParameterError: Anything else.
    """
    if text in SEEDS:
        return SEEDS[text]
    try:
        seed = int(text)
    except ValueError:
        seed = -1
    if seed < 0:
        raise ParameterError("--seed", text, "dev, eval or an integer >= 0")
    return seed


def seed_name(seed: int) -> str:
    """``dev (1)``, ``eval (2)`` or the number."""
    names = {value: name for name, value in SEEDS.items()}
    return f"{names[seed]} ({seed})" if seed in names else str(seed)


def robot_mass(robot: str | None) -> float:
    """Mass [kg] of ``robot`` (its URDF's), or of the paper's point mass for ``None``."""
    return get_robot(robot).total_mass if robot is not None else LipmModel().mass


@dataclass(frozen=True)
class CampaignSpec(PushExperiment):
    """What the campaign runs.

    Attributes:
        model, robot, controllers, paper_rules, fall_dcm_error, overrides: As
            :class:`app.experiments.sweep.PushExperiment`'s.
        pushes: Number of pushes N.
        seed: Seed of the draws (:data:`SEEDS`).
        impulse: (low, high) impulse [N s]; ``None``: 5-10 N s times m / 33.3 kg.
        duration: (low, high) push duration [s].
        cycle: Step (>= 1) whose touchdown in the unpushed walk starts the gait cycle the
            pushes are drawn over.
        settle: Simulated time after the push start [s].
    """

    model: str = "pybullet"
    controllers: tuple[str, ...] = ("rsg", "no-step")
    pushes: int = 100
    seed: int = SEEDS["dev"]
    impulse: tuple[float, float] | None = None
    duration: tuple[float, float] = (0.05, 0.2)
    cycle: int = 4
    settle: float = 8.0

    def __post_init__(self) -> None:
        super().__post_init__()
        check_pushes(self.model, self.controllers, 1, (0.0,), self.overrides, self.robot)
        if self.impulse is None:
            scale = robot_mass(self.robot) / REFERENCE_MASS
            default = tuple(round(value * scale, 2) for value in DEFAULT_IMPULSE)
            object.__setattr__(self, "impulse", default)
        ranges: dict[str, tuple[object, float, float]] = {
            "impulse": (self.impulse, 0.0, MAX_IMPULSE),
            "duration": (self.duration, 1e-3, 1.0),
        }
        for name, (given, low, high) in ranges.items():
            object.__setattr__(self, name, _check_range(name, given, low, high))
        if not (isinstance(self.pushes, int) and 1 <= self.pushes <= 100_000):
            raise ParameterError("pushes", self.pushes, "an integer in [1, 100000]")
        if not (isinstance(self.seed, int) and self.seed >= 0):
            raise ParameterError("seed", self.seed, "dev, eval or an integer >= 0")
        if not (isinstance(self.cycle, int) and 1 <= self.cycle <= 20):
            raise ParameterError("cycle", self.cycle, "an integer in [1, 20]")
        if not (math.isfinite(self.settle) and 1.0 <= self.settle <= 60.0):
            raise ParameterError("settle", self.settle, "a number in [1, 60] s")
        if not (math.isfinite(self.fall_dcm_error) and 0.05 <= self.fall_dcm_error <= 100.0):
            raise ParameterError("fall_dcm_error", self.fall_dcm_error, "a number in [0.05, 100]")

    @property
    def mass(self) -> float:
        """Mass [kg] the velocity change is computed with (the robot's URDF mass)."""
        return robot_mass(self.robot)

    def twin(self) -> CampaignSpec | None:
        """The same campaign on the LIPM with the robot's planner (``None`` on
        ``--model lipm``, or when no controller runs on the LIPM)."""
        controllers = tuple(c for c in self.controllers if c != PLACO_WPG)
        if self.model == "lipm" or not controllers:
            return None
        overrides = lipm_overrides(self.robot, self.overrides)
        return replace(self, model="lipm", controllers=controllers, overrides=overrides)


def _check_range(name: str, given: object, low: float, high: float) -> tuple[float, float]:
    """``given`` as (LOW, HIGH) floats with ``low < LOW <= HIGH <= high``.

    Raises:
        ParameterError: Otherwise, naming ``name``.
    """
    allowed = f"LOW,HIGH with {low:g} < LOW <= HIGH <= {high:g}"
    try:
        first, second = (float(v) for v in given)  # type: ignore[attr-defined]
    except (TypeError, ValueError):
        raise ParameterError(name, given, allowed) from None
    if not (math.isfinite(first) and math.isfinite(second) and low < first <= second <= high):
        raise ParameterError(name, given, allowed)
    return first, second


def lipm_overrides(robot: str | None, overrides: Overrides) -> Overrides:
    """The ``--set`` pairs that apply on the LIPM with ``robot``'s planner."""
    allowed = set(allowed_names("lipm", robot))
    return tuple((name, value) for name, value in overrides if name in allowed)


def gait_config(robot: str | None, paper_rules: bool, overrides: Overrides) -> PlannerConfig:
    """``robot``'s planner configuration on the LIPM (its gait times the pushes)."""
    return build_backend("lipm", robot, "rsg", paper_rules, lipm_overrides(robot, overrides))[1]


@dataclass(frozen=True)
class CampaignPush:
    """One drawn push: index, direction [deg], phase [-], delay after the touchdown
    [s] (phase T^*), impulse [N s] and duration [s]."""

    index: int
    direction_deg: float
    phase: float
    delay: float
    impulse: float
    duration: float

    def push(self, touchdown: float) -> Push:
        """The push on a walk whose step ``cycle`` lands at ``touchdown`` [s]."""
        vector = impulse_along(self.direction_deg, self.impulse)
        return Push(round(touchdown + self.delay, 9), vector, self.duration)


def _floor(value: float, step: float) -> float:
    """``value`` floored to a multiple of ``step`` (so a draw below a range's end stays below)."""
    return round(math.floor(value / step) * step, 9)


def draw_pushes(spec: CampaignSpec, config: PlannerConfig | None = None) -> list[CampaignPush]:
    """The campaign's N pushes (module docstring); ``config`` gives the gait (default
    :func:`gait_config`)."""
    config = config or gait_config(spec.robot, spec.paper_rules, spec.overrides)
    pushes = []
    for index in range(spec.pushes):
        rng = np.random.default_rng([spec.seed, index])
        direction, phase, unit_impulse, unit_duration = rng.uniform(0.0, 1.0, 4)
        low, high = spec.impulse or DEFAULT_IMPULSE
        shortest, longest = spec.duration
        phase = _floor(phase, 0.001)
        duration = _floor(shortest + (longest - shortest) * unit_duration, 0.001)
        pushes.append(
            CampaignPush(
                index=index,
                direction_deg=_floor(360.0 * direction, 0.1),
                phase=phase,
                delay=round(phase * config.gait.step_duration, 9),
                impulse=min(_floor(low + (high - low) * unit_impulse, 0.01), high),
                duration=min(duration, longest),
            )
        )
    return pushes


@dataclass(frozen=True)
class CampaignJob:
    """One run: push ``index`` with ``controller``, on the robot or on its twin."""

    index: int
    controller: str
    twin: bool = False

    @property
    def model_key(self) -> str:
        """``robot|CONTROLLER`` or ``twin|CONTROLLER``."""
        return f"{'twin' if self.twin else 'robot'}|{self.controller}"

    @property
    def key(self) -> str:
        return f"{self.index}|{self.controller}|{'twin' if self.twin else 'robot'}"


def campaign_jobs(spec: CampaignSpec) -> list[CampaignJob]:
    """Every run, push by push: the robot's controllers, then their twins."""
    twin = spec.twin()
    twins = twin.controllers if twin is not None else ()
    return [
        job
        for index in range(spec.pushes)
        for job in (
            *(CampaignJob(index, c) for c in spec.controllers),
            *(CampaignJob(index, c, twin=True) for c in twins),
        )
    ]


#: The index of the campaign's reference robot, whose walk times the pushes: no push's
#: (a campaign has at most 100000 pushes, indices 0 to 99999).
REFERENCE_ROBOT = 100_000


def push_seed(spec: CampaignSpec, index: int) -> int:
    """Seed of the reality of push ``index``'s runs (:func:`app.reality.trial_seed` of the
    campaign's seed and the index)."""
    return trial_seed(spec.seed, index)


def touchdowns(spec: CampaignSpec) -> dict[str, float]:
    """Time [s] of the touchdown of step ``cycle`` in the unpushed walk, per model
    (``robot``, ``twin``) and controller: ``"robot|rsg"`` -> 3.1 on G1 (on the reference
    robot of ``spec``'s reality, the draw of :data:`REFERENCE_ROBOT`)."""
    found = {}
    for job in campaign_jobs(replace(spec, pushes=1)):
        on = spec.twin() if job.twin else spec
        if on is not None:
            run = PushRun(on, job.controller, push_seed(spec, REFERENCE_ROBOT))
            found[job.model_key] = run.touchdown(spec.cycle)
            run.backend.close()
    return found


def run_campaign_job(
    spec: CampaignSpec, push: CampaignPush, job: CampaignJob, touchdown: float
) -> dict:
    """One run, the push ``push.delay`` after ``touchdown`` [s]; returns its JSON-ready
    record (what ``jobs.jsonl`` holds)."""
    started = time.perf_counter()
    on = spec.twin() if job.twin else spec
    if on is None:
        raise ParameterError("twin", job.key, "a campaign with a twin (a full-robot --model)")
    pushed = push.push(touchdown)
    seed = push_seed(spec, push.index)
    trial = PushRun(on, job.controller, seed)
    result = trial.run(pushed, pushed.time + spec.settle)
    return {
        "key": job.key,
        **asdict(job),
        "touchdown": touchdown,
        "push_time": pushed.time,
        "reality_seed": seed,
        "reality": trial.reality.as_dict() if trial.reality is not None else None,
        **describe(result, pushed, job.controller),
        "stance_offset_y": (
            None if job.controller == PLACO_WPG else stance_offset_after(result, pushed.time)
        ),
        "wall_time": time.perf_counter() - started,
    }


def _run_campaign_job_args(args: tuple[CampaignSpec, CampaignPush, CampaignJob, float]) -> dict:
    return run_campaign_job(*args)


def run_campaign(spec: CampaignSpec, run: JobRun) -> tuple[list[CampaignPush], dict[str, dict]]:
    """Run (or resume) the campaign as ``run`` says; returns the pushes and the record
    of every run by its key.

    Raises:
        ParameterError: Bad workers/backend or a folder holding another campaign.
        RsgError: The folder cannot be written, or a walk does not reach the cycle.
    """
    pushes = draw_pushes(spec)
    times = touchdowns(spec)
    arguments = {
        job.key: (spec, pushes[job.index], job, times[job.model_key]) for job in campaign_jobs(spec)
    }
    fields = result_fields(RESULT_FIELDS, spec)
    records = run_resumable(
        _run_campaign_job_args, arguments, spec, fields, SPEC_FILE, run, "pushes", "runs"
    )
    return pushes, records
