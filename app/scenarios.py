"""Scenarios: how long to walk and which pushes to apply.

Built in:

- ``walk``: nominal walking, no push.
- ``paper-fig6``: the paper's two pushes (Section VI): (8, -6) N s over 0.1 s at
  3.8 s and (-6, 8) N s over 0.2 s at 6.8 s.

A scenario can also be a TOML file::

    name = "side-push"
    duration = 10.0          # [s]
    description = "one push to the left"
    reference_mass = 60.0    # [kg] optional: impulses are for a robot of this mass

    [[push]]
    t = 3.0                  # start [s]
    impulse = [0.0, 15.0]    # [N s]
    duration = 0.1           # [s], default 0.1

Impulses given for ``reference_mass`` are scaled by ``mass / reference_mass`` on a
robot of another mass, so the velocity change (and the DCM jump) is the same.
"""

from __future__ import annotations

import math
import tomllib
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from planner.exceptions import ParameterError
from planner.parameters import LipmModel
from planner.types import Push

PAPER_MASS = LipmModel().mass  # [kg] mass the paper's impulses are taken for
MAX_IMPULSE = 500.0  # [N s] sanity bound on one push
MAX_PUSH_DURATION = 2.0  # [s]


@dataclass(frozen=True)
class Scenario:
    """A run's script.

    Attributes:
        name: Scenario name.
        duration: Simulated time [s].
        pushes: Pushes, sorted by start time.
        description: One line for humans.
        reference_mass: Mass [kg] the impulses are given for, or None (absolute).
    """

    name: str
    duration: float
    pushes: tuple[Push, ...] = ()
    description: str = ""
    reference_mass: float | None = None

    def with_pushes(self, extra: list[Push]) -> Scenario:
        """This scenario with more pushes."""
        pushes = tuple(sorted((*self.pushes, *extra), key=lambda p: p.time))
        return replace(self, pushes=pushes)

    def scaled_to(self, mass: float) -> tuple[Scenario, float]:
        """Impulses scaled for a robot of ``mass`` [kg]; returns (scenario, factor)."""
        if self.reference_mass is None:
            return self, 1.0
        factor = mass / self.reference_mass
        pushes = tuple(
            Push(p.time, np.asarray(p.impulse) * factor, p.duration) for p in self.pushes
        )
        return replace(self, pushes=pushes), factor

    def force_average(self, start: float, period: float) -> np.ndarray:
        """Push force [N] averaged over [start, start + period], so impulses are exact."""
        total = np.zeros(2)
        end = start + period
        for push in self.pushes:
            overlap = min(end, push.time + push.duration) - max(start, push.time)
            if overlap > 0.0:
                total += np.asarray(push.impulse, dtype=float) / push.duration * overlap
        return total / period


BUILT_IN: dict[str, Scenario] = {
    "walk": Scenario("walk", 12.0, (), "nominal walking, no push"),
    "paper-fig6": Scenario(
        "paper-fig6",
        12.0,
        (
            Push(3.8, np.array([8.0, -6.0]), 0.1),
            Push(6.8, np.array([-6.0, 8.0]), 0.2),
        ),
        "the paper's Fig. 6: (8,-6) N s over 0.1 s at 3.8 s, (-6,8) N s over 0.2 s at 6.8 s",
        reference_mass=PAPER_MASS,
    ),
}


def _check_push(push: Push, source: str) -> Push:
    if not (math.isfinite(push.time) and push.time >= 0.0):
        raise ParameterError(f"{source} time", push.time, "a time >= 0 [s]")
    if not (math.isfinite(push.duration) and 0.0 < push.duration <= MAX_PUSH_DURATION):
        raise ParameterError(
            f"{source} duration", push.duration, f"a duration in (0, {MAX_PUSH_DURATION}] [s]"
        )
    impulse = np.asarray(push.impulse, dtype=float)
    if impulse.shape != (2,) or not np.all(np.isfinite(impulse)):
        raise ParameterError(f"{source} impulse", push.impulse, "two finite numbers [N s]")
    if float(np.linalg.norm(impulse)) > MAX_IMPULSE:
        raise ParameterError(f"{source} impulse", impulse.tolist(), f"a norm <= {MAX_IMPULSE} N s")
    return push


def parse_push(text: str) -> Push:
    """Parse ``T:IX,IY[:DURATION]`` (time [s], impulse [N s], duration [s], default 0.1).

    Raises:
        ParameterError: Naming the field and what is allowed.
    """
    allowed = "T:IX,IY[:DURATION], e.g. 3.8:8,-6:0.1 (time [s], impulse [N s], duration [s])"
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise ParameterError("--push", text, allowed)
    try:
        time = float(parts[0])
        components = [float(v) for v in parts[1].split(",")]
        duration = float(parts[2]) if len(parts) == 3 else 0.1
    except ValueError:
        raise ParameterError("--push", text, allowed) from None
    if len(components) != 2:
        raise ParameterError("--push impulse", parts[1], "two numbers IX,IY [N s]")
    return _check_push(Push(time, np.array(components), duration), "--push")


def load_scenario(name_or_path: str) -> Scenario:
    """A built-in scenario by name, or a scenario TOML file by path.

    Raises:
        ParameterError: Unknown name, unreadable file or bad field.
    """
    if name_or_path in BUILT_IN:
        return BUILT_IN[name_or_path]
    path = Path(name_or_path)
    if path.suffix != ".toml" or not path.is_file():
        raise ParameterError(
            "--scenario",
            name_or_path,
            f"one of {', '.join(BUILT_IN)} or the path of an existing .toml file",
        )
    try:
        data = tomllib.loads(path.read_text())
    except (OSError, tomllib.TOMLDecodeError) as exc:
        raise ParameterError("--scenario", str(path), f"a readable TOML file ({exc})") from exc
    known = {"name", "duration", "description", "reference_mass", "push"}
    unknown = set(data) - known
    if unknown:
        raise ParameterError(f"{path.name} keys", sorted(unknown), f"only {sorted(known)}")
    pushes = []
    for index, entry in enumerate(data.get("push", [])):
        source = f"{path.name} push[{index}]"
        try:
            push = Push(
                float(entry["t"]),
                np.array(entry["impulse"], dtype=float),
                float(entry.get("duration", 0.1)),
            )
        except (KeyError, TypeError, ValueError) as exc:
            raise ParameterError(
                source, entry, "t [s], impulse [IX, IY] [N s], duration [s]"
            ) from exc
        pushes.append(_check_push(push, source))
    duration = data.get("duration", 12.0)
    if not (isinstance(duration, int | float) and 0.0 < duration <= 3600.0):
        raise ParameterError(f"{path.name} duration", duration, "a duration in (0, 3600] [s]")
    reference_mass = data.get("reference_mass")
    if reference_mass is not None and not (
        isinstance(reference_mass, int | float) and reference_mass > 0
    ):
        raise ParameterError(f"{path.name} reference_mass", reference_mass, "a mass > 0 [kg]")
    return Scenario(
        name=str(data.get("name", path.stem)),
        duration=float(duration),
        pushes=tuple(sorted(pushes, key=lambda p: p.time)),
        description=str(data.get("description", "")),
        reference_mass=None if reference_mass is None else float(reference_mass),
    )
