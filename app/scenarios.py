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

Every input is checked here, before anything runs (docs/input-validation.md): the
file is UTF-8 TOML (a UTF-8 byte-order mark is skipped) of at most 1 MB; every key is
known; numbers are numbers (not booleans, strings or dates) in their ranges; a push
is a table with ``t``, ``impulse`` and optionally ``duration``. Against the run
(:meth:`Scenario.check_fits`): the run lasts at least one control tick and every push
ends before the run does, so each listed push acts with its whole impulse. A push
shorter than a control tick is delivered within its tick (the tick's mean force is
impulse / tick): :meth:`Scenario.impulse_between` splits each push's impulse over the
ticks exactly.
"""

from __future__ import annotations

import bisect
import math
import tomllib
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any

import numpy as np

from app.setup.overrides import parse_decimal
from planner.exceptions import ParameterError
from planner.parameters import LipmModel, Range
from planner.types import Push

PAPER_MASS = LipmModel().mass  # [kg] mass the paper's impulses are taken for
MAX_IMPULSE = 500.0  # [N s] sanity bound on one push (8 m/s on the paper's 60 kg)
MAX_PUSH_DURATION = 2.0  # [s]
MAX_DURATION = 3600.0  # [s] of simulated time
MAX_PUSHES = 1000  # per scenario: more than one push per 4 s of the longest run
MAX_FILE_BYTES = 1_000_000  # a scenario file is a few hundred bytes
PUSH_TIME = Range(0.0, MAX_DURATION, "s")
PUSH_DURATION = Range(0.0, MAX_PUSH_DURATION, "s", low_open=True)
DURATION = Range(0.0, MAX_DURATION, "s", low_open=True)
REFERENCE_MASS = Range(0.1, 1000.0, "kg")
TIME_SLACK = 1e-9  # [s] rounding allowed when a push ends exactly with the run
TOP_KEYS = ("name", "duration", "description", "reference_mass", "push")
PUSH_KEYS = ("t", "impulse", "duration")


def delivered_fraction(push: Push, time: float) -> float:
    """Fraction [0, 1] of ``push``'s impulse delivered by ``time`` [s] (its force is
    constant over its duration; the end counts from :data:`TIME_SLACK` before it, so
    a push shorter than that, 5e-324 s included, acts at once)."""
    if time <= push.time:
        return 0.0
    if time >= push.time + push.duration - TIME_SLACK:
        return 1.0
    return min((time - push.time) / push.duration, 1.0)


def describe_push(push: Push) -> str:
    """``push at t=3.8 s, impulse (8, -6) N s over 0.1 s``."""
    ix, iy = (float(v) for v in push.impulse)
    return f"push at t={push.time:g} s, impulse ({ix:g}, {iy:g}) N s over {push.duration:g} s"


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
    # Start times [s] and the longest duration [s], to find the pushes of a tick.
    _starts: tuple[float, ...] = field(default=(), init=False, repr=False, compare=False)
    _longest: float = field(default=0.0, init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        pushes = tuple(sorted(self.pushes, key=lambda p: p.time))
        object.__setattr__(self, "pushes", pushes)
        object.__setattr__(self, "_starts", tuple(p.time for p in pushes))
        object.__setattr__(self, "_longest", max((p.duration for p in pushes), default=0.0))

    def with_pushes(self, extra: list[Push]) -> Scenario:
        """This scenario with more pushes."""
        return replace(self, pushes=(*self.pushes, *extra))

    def scaled_to(self, mass: float) -> tuple[Scenario, float]:
        """Impulses scaled for a robot of ``mass`` [kg]; returns (scenario, factor).

        Raises:
            ParameterError: A scaled impulse exceeds :data:`MAX_IMPULSE`.
        """
        if self.reference_mass is None:
            return self, 1.0
        factor = mass / self.reference_mass
        pushes = tuple(
            Push(p.time, np.asarray(p.impulse, dtype=float) * factor, p.duration)
            for p in self.pushes
        )
        for push in pushes:
            size = math.hypot(*(float(v) for v in push.impulse))
            if size > MAX_IMPULSE:
                raise ParameterError(
                    f"reference_mass of {self.name}",
                    self.reference_mass,
                    f"a mass that keeps each push <= {MAX_IMPULSE:g} N s on this "
                    f"{mass:.1f} kg robot ({describe_push(push)} after scaling by {factor:.3g})",
                )
        return replace(self, pushes=pushes), factor

    def check_fits(self, period: float) -> int:
        """Check the scenario against a loop of control ``period`` [s]; returns the
        number of ticks the run will have.

        Raises:
            ParameterError: The run is shorter than one tick, there are more than
                :data:`MAX_PUSHES` pushes, or a push does not end before the run does
                (its whole impulse could not act).
        """
        ticks = int(round(self.duration / period))
        if ticks < 1:
            raise ParameterError(
                "duration",
                self.duration,
                f"at least one control tick ({period:g} s on this model)",
            )
        if len(self.pushes) > MAX_PUSHES:
            raise ParameterError("pushes", len(self.pushes), f"at most {MAX_PUSHES} pushes")
        end = ticks * period
        for push in self.pushes:
            if push.time + push.duration > end + TIME_SLACK:
                raise ParameterError(
                    f"{describe_push(push)}, ending at t",
                    float(f"{push.time + push.duration:.9g}"),
                    f"t <= {end:g} s, the end of the run, so that its whole impulse acts "
                    "(a longer --duration, or an earlier push)",
                )
        return ticks

    def impulse_between(self, start: float, end: float) -> np.ndarray:
        """Impulse [N s] the pushes deliver in [start, end); over consecutive intervals
        these add up to each push's whole impulse, however short the push."""
        total = np.zeros(2)
        first = bisect.bisect_left(self._starts, start - self._longest)
        last = bisect.bisect_left(self._starts, end)
        for push in self.pushes[first:last]:
            fraction = delivered_fraction(push, end) - delivered_fraction(push, start)
            if fraction > 0.0:
                total += np.asarray(push.impulse, dtype=float) * fraction
        return total

    def force_average(self, start: float, period: float) -> np.ndarray:
        """Push force [N] averaged over [start, start + period], so impulses are exact."""
        return self.impulse_between(start, start + period) / period


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
    PUSH_TIME.check(f"{source} time", push.time)
    PUSH_DURATION.check(f"{source} duration", push.duration)
    impulse = np.asarray(push.impulse, dtype=float)
    if impulse.shape != (2,) or not all(math.isfinite(v) for v in impulse):
        raise ParameterError(f"{source} impulse", push.impulse, "two finite numbers [N s]")
    # math.hypot: no overflow warning for huge components
    if math.hypot(float(impulse[0]), float(impulse[1])) > MAX_IMPULSE:
        raise ParameterError(
            f"{source} impulse", impulse.tolist(), f"a norm <= {MAX_IMPULSE:g} N s"
        )
    return push


def parse_push(text: str) -> Push:
    """Parse ``T:IX,IY[:DURATION]`` (time [s], impulse [N s], duration [s], default 0.1).

    Raises:
        ParameterError: Naming the field and what is allowed.
    """
    allowed = "T:IX,IY[:DURATION], e.g. 3.8:8,-6:0.1 (time [s], impulse [N s], duration [s])"
    shown = text if len(text) <= 60 else text[:57] + "..."
    parts = text.split(":")
    if len(parts) not in (2, 3):
        raise ParameterError("--push", shown, allowed)
    numbers = [parse_decimal(v.strip()) for v in (parts[0], *parts[1].split(","), *parts[2:])]
    if any(v is None for v in numbers):
        raise ParameterError("--push", shown, allowed + ", finite decimal numbers")
    if len(numbers) != len(parts) + 1:
        raise ParameterError("--push impulse", parts[1][:60], "two numbers IX,IY [N s]")
    time, ix, iy = numbers[:3]
    duration = numbers[3] if len(parts) == 3 else 0.1
    return _check_push(Push(time, np.array([ix, iy]), duration), "--push")  # type: ignore[arg-type]


def load_scenario(name_or_path: str) -> Scenario:
    """A built-in scenario by name, or a scenario TOML file by path.

    Raises:
        ParameterError: Unknown name, unreadable file or bad field.
    """
    if name_or_path in BUILT_IN:
        return BUILT_IN[name_or_path]
    expected = f"one of {', '.join(BUILT_IN)} or the path of an existing .toml file"
    shown = name_or_path if len(name_or_path) <= 200 else name_or_path[:197] + "..."
    try:
        path = Path(name_or_path)
        if path.suffix != ".toml" or not path.is_file():
            raise ParameterError("--scenario", shown, expected)
        size = path.stat().st_size
        if size > MAX_FILE_BYTES:
            raise ParameterError(
                "--scenario", shown, f"a file of at most {MAX_FILE_BYTES} bytes (it has {size})"
            )
        raw = path.read_bytes()
    except (OSError, ValueError) as exc:  # ValueError: a NUL byte in the path
        if isinstance(exc, ParameterError):
            raise
        raise ParameterError("--scenario", shown, f"a readable TOML file ({exc})") from None
    try:
        text = raw.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise ParameterError(
            "--scenario",
            shown,
            f"a UTF-8 text file (byte {exc.start} is not UTF-8: save it as UTF-8)",
        ) from None
    try:
        data = tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise ParameterError("--scenario", shown, f"valid TOML ({exc})") from None
    except RecursionError:
        raise ParameterError("--scenario", shown, "TOML without arrays or tables nested "
                             "hundreds deep") from None  # fmt: skip
    return scenario_from_toml(data, path.name, path.stem)


def _number(source: str, value: Any, valid: Range) -> float:
    """``value`` as a float: a TOML integer or float (not a bool, string or date) in ``valid``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise ParameterError(source, _shown(value), valid.describe())
    valid.check(source, value)
    return float(value)


def _shown(value: Any) -> Any:
    """``value`` for a message: long or nested values cut to 80 characters."""
    text = repr(value)
    return value if len(text) <= 80 else text[:77] + "..."


def _text(source: str, value: Any, longest: int, shortest: int = 0) -> str:
    if not (isinstance(value, str) and shortest <= len(value) <= longest and value.isprintable()):
        raise ParameterError(
            source,
            _shown(value),
            f"a string of {shortest} to {longest} printable characters",
        )
    return value


def scenario_from_toml(data: dict[str, Any], source: str, default_name: str) -> Scenario:
    """The scenario of a parsed TOML document (``source``: the file name, for messages).

    Raises:
        ParameterError: An unknown key, a value of the wrong type or out of range.
    """
    unknown = sorted(set(data) - set(TOP_KEYS))
    if unknown:
        raise ParameterError(f"{source} keys", _shown(unknown), f"only {', '.join(TOP_KEYS)}")
    name = _text(f"{source} name", data.get("name", default_name), 100, shortest=1)
    description = _text(f"{source} description", data.get("description", ""), 1000)
    duration = _number(f"{source} duration", data.get("duration", 12.0), DURATION)
    reference_mass = data.get("reference_mass")
    if reference_mass is not None:
        reference_mass = _number(f"{source} reference_mass", reference_mass, REFERENCE_MASS)
    entries = data.get("push", [])
    if not isinstance(entries, list) or not all(isinstance(e, dict) for e in entries):
        raise ParameterError(
            f"{source} push",
            _shown(entries),
            "an array of tables: [[push]] with t, impulse and duration (or no push key)",
        )
    if len(entries) > MAX_PUSHES:
        raise ParameterError(f"{source} push", f"{len(entries)} pushes", f"at most {MAX_PUSHES}")
    pushes = [_push_from_toml(entry, f"{source} push[{i}]") for i, entry in enumerate(entries)]
    return Scenario(
        name=name,
        duration=duration,
        pushes=tuple(pushes),
        description=description,
        reference_mass=reference_mass,
    )


def _push_from_toml(entry: dict[str, Any], source: str) -> Push:
    unknown = sorted(set(entry) - set(PUSH_KEYS))
    if unknown:
        raise ParameterError(
            f"{source} keys", _shown(unknown), "only t [s], impulse [N s], duration [s]"
        )
    for key in ("t", "impulse"):
        if key not in entry:
            raise ParameterError(f"{source} {key}", "missing", "t [s] and impulse [IX, IY] [N s]")
    time = _number(f"{source} t", entry["t"], PUSH_TIME)
    duration = _number(f"{source} duration", entry.get("duration", 0.1), PUSH_DURATION)
    impulse = entry["impulse"]
    if not (
        isinstance(impulse, list)
        and len(impulse) == 2
        and all(isinstance(v, int | float) and not isinstance(v, bool) for v in impulse)
    ):
        raise ParameterError(f"{source} impulse", _shown(impulse), "two numbers [IX, IY] [N s]")
    return _check_push(Push(time, np.array(impulse, dtype=float), duration), source)
