"""``rsg protocol``: the largest push recovered forward, backward, inward and outward,
on the protocol of IHMC's push-recovery CI tests, beside Atlas's thresholds there.

Source: IHMC's open-robotics-software (github.com/ihmcrobotics/ihmc-open-robotics-software),
``ihmc-avatar-interfaces/src/test/java/us/ihmc/avatar/pushRecovery/``
``AvatarICPOptimizationPushRecoveryATest.java`` (timing, directions, duration) and
``AvatarICPOptimizationPushRecoveryTestSetup.java`` (magnitude = percentWeight x total
mass x 9.81 N; single support starts when the swing foot's state becomes SWING), and
``atlas/src/test/java/us/ihmc/atlas/pushRecovery/AtlasICPOptimizationPushRecoveryATest.java``
(Atlas's ``percentWeight`` per test). Walking forward, the right foot swinging:

* forward (+x), backward (-x) and inward (+y, towards the stance foot) at single-support
  start + half the swing time, a force of ``percentWeight`` m g for 0.1 s (Atlas: 0.8,
  0.5 and 0.22);
* outward at double-support start + half the transfer time, into the support of the
  right foot, +y: away from the foot taking the weight (Atlas: 0.25).

Here the same in the RSG's gait, cycle ``cycle`` (default 4: the left foot is the
stance foot, as in IHMC's tests), timed from the touchdown t_k of step k = ``cycle``
measured in the unpushed walk of each controller and model, as IHMC's tests trigger on
the gait state (:func:`app.experiments.trial.measured_touchdown`; on G1 in PyBullet t_4 is
3.1 s, its nominal time): double support is [t_k, t_k + T_DSP), the swing
[t_k + T_DSP, t_k + T^*). Forward (0 deg), backward (180 deg) and inward (90 deg) start
at t_k + T_DSP + T_SSP / 2 (sweep phase (T_DSP + T_SSP / 2) / T^*, 0.5625 on G1),
outward (270 deg) at t_k + T_DSP / 2 (phase 0.0625). A force of f m g over 0.1 s is an
impulse f m g 0.1 s and a velocity change f g 0.1 s (0.981 m/s per unit of f, whatever
the mass).

Differences, said once: IHMC pushes the chest (0.3 m above its joint) and passes a test
when the robot does not fall and its pelvis ends within a box around the end of its
six-step plan; here the push acts on the CoM (LIPM) or the pelvis (PyBullet) and the
verdict is the sweep's criterion (default ``recovered``). Atlas's figures are the
magnitudes its CI tests pass, not its largest; the largest fraction here is bisected
(:func:`app.experiments.sweep.run_job`: between 0 and 1.1 x the LIPM capture bound, to
``tolerance`` of m g).
"""

from __future__ import annotations

import csv
import json
import math
from dataclasses import asdict, dataclass
from pathlib import Path

from app.experiments.campaign import gait_config, robot_mass
from app.experiments.jobs import JobRun
from app.experiments.sweep import Job, SweepSpec, run_sweep
from app.reality import DEFAULT_PROFILE
from app.setup.build import resolve_robot
from app.setup.overrides import Overrides
from planner.exceptions import ParameterError, RsgError
from planner.parameters import PlannerConfig

GRAVITY = 9.81  # [m/s^2] as IHMC's tests
PUSH_DURATION = 0.1  # [s]
#: name -> (direction [deg] on a left stance foot, in double support, Atlas's percentWeight)
DIRECTIONS = {
    "forward": (0.0, False, 0.8),
    "backward": (180.0, False, 0.5),
    "inward": (90.0, False, 0.22),
    "outward": (270.0, True, 0.25),
}
SOURCE = (
    "IHMC open-robotics-software: ihmc-avatar-interfaces/src/test/java/us/ihmc/avatar/"
    "pushRecovery/AvatarICPOptimizationPushRecoveryATest.java (timing, directions, 0.1 s) and "
    "atlas/src/test/java/us/ihmc/atlas/pushRecovery/AtlasICPOptimizationPushRecoveryATest.java "
    "(Atlas's percentWeight)"
)


@dataclass(frozen=True)
class ProtocolSpec:
    """What the protocol runs.

    Attributes:
        model, robot, controllers, paper_rules, overrides, reality: As the sweep's.
        cycle: Walking cycle of the pushes (even: left stance, as IHMC's tests).
        settle: Simulated time after the push start [s].
        tolerance: Bisection tolerance on the fraction of m g [-].
        criterion: ``recovered`` or ``no-fall``.
    """

    model: str = "lipm"
    robot: str | None = None
    controllers: tuple[str, ...] = ("rsg",)
    cycle: int = 4
    settle: float = 8.0
    tolerance: float = 0.01
    criterion: str = "recovered"
    paper_rules: bool = False
    overrides: Overrides = ()
    reality: str = DEFAULT_PROFILE

    def __post_init__(self) -> None:
        if not (isinstance(self.cycle, int) and 2 <= self.cycle <= 20 and self.cycle % 2 == 0):
            raise ParameterError("cycle", self.cycle, "an even integer in [2, 20] (left stance)")
        if not (math.isfinite(self.tolerance) and 0.001 <= self.tolerance <= 0.5):
            raise ParameterError("tolerance", self.tolerance, "a fraction of m g in [0.001, 0.5]")
        object.__setattr__(self, "robot", resolve_robot(self.model, self.robot))
        self.sweep_spec()  # validates the rest

    def sweep_spec(self) -> SweepSpec:
        """The sweep whose jobs are the protocol's."""
        swing, transfer = push_phases(gait_config(self.robot, self.paper_rules, self.overrides))
        mass = robot_mass(self.robot)
        return SweepSpec(
            model=self.model,
            robot=self.robot,
            controllers=self.controllers,
            directions=4,
            phases=(swing, transfer),
            duration=PUSH_DURATION,
            cycle=self.cycle,
            settle=self.settle,
            tolerance=self.tolerance * mass * GRAVITY * PUSH_DURATION,
            criterion=self.criterion,
            paper_rules=self.paper_rules,
            overrides=self.overrides,
            timing="touchdown",
            reality=self.reality,
        )


def push_phases(config: PlannerConfig) -> tuple[float, float]:
    """Sweep phases [-] of the swing pushes (single-support start + half the swing)
    and of the outward push (double-support start + half of it)."""
    gait = config.gait
    swing = (gait.double_support_duration + gait.single_support_duration / 2) / gait.step_duration
    return swing, gait.double_support_duration / 2 / gait.step_duration


def protocol_jobs(spec: SweepSpec) -> list[Job]:
    """One sweep job per controller and direction."""
    swing, transfer = spec.phases
    return [
        Job(controller, math.radians(angle), transfer if in_transfer else swing)
        for controller in spec.controllers
        for angle, in_transfer, _ in DIRECTIONS.values()
    ]


def run_protocol(spec: ProtocolSpec, run: JobRun) -> dict:
    """Run (or resume) the protocol as ``run`` says; returns its table (:func:`table`)."""
    sweep = spec.sweep_spec()
    records = run_sweep(sweep, run, protocol_jobs(sweep), "protocol")
    return table(spec, records)


def table(spec: ProtocolSpec, records: list[dict]) -> dict:
    """Per controller and direction: largest fraction f of m g recovered, its impulse
    [N s] and velocity change [m/s], beside Atlas's CI threshold."""
    rows: dict = {}
    for record in records:
        name = next(
            n for n, (angle, _, _) in DIRECTIONS.items()
            if abs(angle - record["direction_deg"]) < 1e-6
        )  # fmt: skip
        weight_impulse = record["mass"] * GRAVITY * PUSH_DURATION  # [N s] of f = 1
        atlas = DIRECTIONS[name][2]
        rows.setdefault(record["controller"], {})[name] = {
            "direction_deg": record["direction_deg"],
            "push_time": record["push_time"],
            "phase": record["phase"],
            "stance": record["stance"],
            "fraction": record["impulse"] / weight_impulse,
            "impulse": record["impulse"],
            "velocity_change": record["impulse"] / record["mass"],
            "capped": record["capped"],
            "atlas_fraction": atlas,
            "atlas_velocity_change": atlas * GRAVITY * PUSH_DURATION,
        }
    return {
        "spec": asdict(spec),
        "source": SOURCE,
        "units": {
            "fraction": "of m g for 0.1 s",
            "impulse": "N s",
            "velocity_change": "m/s",
            "push_time": "s",
            "direction_deg": "deg",
        },  # fmt: skip
        "controllers": rows,
    }


def write_protocol(out: Path, document: dict) -> list[Path]:
    """``protocol.json`` and ``protocol.csv``; returns their paths.

    Raises:
        RsgError: If they cannot be written.
    """
    columns = ("fraction", "impulse", "velocity_change", "push_time", "phase", "capped",
               "atlas_fraction", "atlas_velocity_change")  # fmt: skip
    json_path, csv_path = out / "protocol.json", out / "protocol.csv"
    try:
        json_path.write_text(json.dumps(document, indent=2) + "\n")
        with csv_path.open("w", newline="") as handle:
            writer = csv.writer(handle)
            writer.writerow(("controller", "direction", *columns))
            for controller, rows in document["controllers"].items():
                for name, row in rows.items():
                    writer.writerow((controller, name, *(row[c] for c in columns)))
    except OSError as exc:
        raise RsgError(f"cannot write the protocol to {out}: {exc}") from exc
    return [json_path, csv_path]


def format_protocol(document: dict) -> str:
    """Largest fraction of m g (velocity change) per controller and direction, and Atlas's."""
    names = list(DIRECTIONS)
    lines = [f"{'largest f (dv [m/s])':<22}" + "".join(f"{n:>16}" for n in names)]
    for controller, rows in document["controllers"].items():
        cells = [
            f"{rows[n]['fraction']:.3f}{'+' if rows[n]['capped'] else ''} "
            f"({rows[n]['velocity_change']:.2f})"
            for n in names
        ]
        lines.append(f"{controller:<22}" + "".join(f"{c:>16}" for c in cells))
    atlas = [f"{DIRECTIONS[n][2]:.2f} ({DIRECTIONS[n][2] * GRAVITY * PUSH_DURATION:.2f})"
             for n in names]  # fmt: skip
    lines.append(f"{'Atlas (IHMC CI test)':<22}" + "".join(f"{c:>16}" for c in atlas))
    return "\n".join(lines)
