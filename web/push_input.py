"""The push the user sets on the page: safe ranges, the paper's presets, and the fields.

Pure Python and NumPy (no viser), so it is tested without a browser.

The page's number fields are text: what the browser's number inputs do with an
empty or partial entry (keep the previous value, silently) is not what the user
sees. :func:`read_push` reads the three fields' texts when Push is pressed and gives
the push they ask for, exactly, or refuses it naming each bad field, its text and
the range allowed; nothing is clipped.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

Array = NDArray[np.float64]

REFERENCE_MASS = 60.0  # [kg] mass the paper's impulses are given for
PAPER_PUSHES = (((8.0, -6.0), 0.1), ((-6.0, 8.0), 0.2))  # ([N s], [s]) for 60 kg
MAX_IMPULSE_AT_REFERENCE = 30.0  # [N s] largest push offered, for 60 kg
MIN_PUSH_DURATION = 0.05  # [s]
MAX_PUSH_DURATION = 0.5  # [s]


@dataclass(frozen=True)
class PushInput:
    """A push as the user sets it.

    Attributes:
        direction: Direction of the impulse in the ground plane [deg], 0 = +x (forward),
            90 = +y (left); in (-180, 180].
        impulse: Magnitude of the impulse [N s], >= 0.
        duration: Duration of the push [s], > 0.
    """

    direction: float
    impulse: float
    duration: float

    def impulse_xy(self) -> Array:
        """Impulse vector i_H [N s], shape (2,)."""
        angle = math.radians(self.direction)
        return self.impulse * np.array([math.cos(angle), math.sin(angle)])


@dataclass(frozen=True)
class PushBounds:
    """Safe ranges of the push input for a robot.

    Attributes:
        impulse_max: Largest impulse [N s] (30 N s for 60 kg, scaled by mass / 60 kg).
        duration_min: Shortest push [s].
        duration_max: Longest push [s].
    """

    impulse_max: float
    duration_min: float = MIN_PUSH_DURATION
    duration_max: float = MAX_PUSH_DURATION

    @staticmethod
    def for_mass(mass: float) -> PushBounds:
        """Bounds for a robot of ``mass`` [kg].

        Raises:
            ValueError: ``mass`` is not a finite number > 0.
        """
        if not (math.isfinite(mass) and mass > 0.0):
            raise ValueError(f"robot mass {mass!r}: expected a finite number > 0 [kg]")
        return PushBounds(MAX_IMPULSE_AT_REFERENCE * mass / REFERENCE_MASS)


def wrap_degrees(angle: float) -> float:
    """``angle`` [deg] wrapped to (-180, 180] (720 is 0, -180 is 180)."""
    wrapped = math.fmod(angle, 360.0)
    if wrapped <= -180.0:
        wrapped += 360.0
    elif wrapped > 180.0:
        wrapped -= 360.0
    return wrapped + 0.0  # no -0.0


def clamp_push(direction: float, impulse: float, duration: float, bounds: PushBounds) -> PushInput:
    """The push the user asked for, brought into the safe ranges.

    The direction is wrapped to (-180, 180] deg, the impulse clipped to
    [0, ``bounds.impulse_max``] N s and the duration to
    [``bounds.duration_min``, ``bounds.duration_max``] s.

    Raises:
        ValueError: A value is not a finite number (names the field and the range).
    """
    values = {"direction [deg]": direction, "impulse [N s]": impulse, "duration [s]": duration}
    for name, value in values.items():
        if not isinstance(value, int | float) or not math.isfinite(value):
            raise ValueError(f"push {name} {value!r}: expected a finite number")
    return PushInput(
        direction=wrap_degrees(float(direction)),
        impulse=float(np.clip(impulse, 0.0, bounds.impulse_max)),
        duration=float(np.clip(duration, bounds.duration_min, bounds.duration_max)),
    )


def paper_presets(mass: float) -> dict[str, PushInput]:
    """The paper's pushes, (8,-6) N s over 0.1 s and (-6,8) N s over 0.2 s, for ``mass`` [kg].

    Impulses scale with ``mass / 60 kg`` like the scenarios, so the velocity change is
    the paper's.

    Raises:
        ValueError: ``mass`` is not a finite number > 0.
    """
    bounds = PushBounds.for_mass(mass)
    presets = {}
    for (ix, iy), duration in PAPER_PUSHES:
        scale = mass / REFERENCE_MASS
        label = f"paper ({ix:g},{iy:g}) N s, {duration:g} s"
        presets[label] = clamp_push(
            math.degrees(math.atan2(iy, ix)), math.hypot(ix, iy) * scale, duration, bounds
        )
    return presets


# ----------------------------------------------------------------------------- fields
DIRECTION_LIMIT = 360.0  # [deg] a typed direction is in [-360, 360], wrapped to (-180, 180]


@dataclass(frozen=True)
class FieldRule:
    """What a push field accepts.

    Attributes:
        name: The field's name, for messages.
        unit: Its unit.
        low, high: The range allowed [unit].
        low_open: ``low`` itself is refused (an impulse must be > 0).
    """

    name: str
    unit: str
    low: float
    high: float
    low_open: bool = False

    def allowed(self) -> str:
        """The range, as the page and its messages say it."""
        lower = "more than" if self.low_open else "from"
        return f"{lower} {format_field(self.low)} to {format_field(self.high)} {self.unit}"

    def read(self, text: str) -> float | str:
        """The number typed as ``text``, or why it is refused (the field, the text,
        the range allowed)."""
        stripped = text.strip()
        try:
            number = float(stripped)
        except ValueError:
            number = math.nan
        if not stripped:
            return f"{self.name} is empty: allowed {self.allowed()}"
        if not math.isfinite(number):
            return f"{self.name} {stripped!r} is not a number: allowed {self.allowed()}"
        below = number <= self.low if self.low_open else number < self.low
        if below or number > self.high:
            return f"{self.name} {stripped} {self.unit} is out of range: allowed {self.allowed()}"
        return number


def field_rules(bounds: PushBounds) -> dict[str, FieldRule]:
    """The rules of the direction, impulse and duration fields for ``bounds``."""
    return {
        "direction": FieldRule("direction", "deg", -DIRECTION_LIMIT, DIRECTION_LIMIT),
        "impulse": FieldRule("impulse", "N s", 0.0, bounds.impulse_max, low_open=True),
        "duration": FieldRule("duration", "s", bounds.duration_min, bounds.duration_max),
    }


def read_push(texts: dict[str, str], bounds: PushBounds) -> PushInput | list[str]:
    """The push the fields' texts ask for, exactly (the direction wrapped to (-180, 180]
    deg, as the page says), or why it is refused: one reason per bad field.

    Args:
        texts: Field name (direction, impulse, duration) -> the text it holds.
        bounds: The robot's push bounds.
    """
    values, refused = {}, []
    for name, rule in field_rules(bounds).items():
        read = rule.read(texts.get(name, ""))
        if isinstance(read, str):
            refused.append(read)
        else:
            values[name] = read
    if refused:
        return refused
    return PushInput(wrap_degrees(values["direction"]), values["impulse"], values["duration"])


def format_field(value: float) -> str:
    """A field's text for ``value``: up to 3 decimals, no trailing zeros."""
    text = f"{value:.3f}".rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def push_refusal(push: PushInput) -> str:
    """Why ``push`` is not applied ("" if it can be): a push needs an impulse > 0."""
    if push.impulse <= 0.0:
        return f"impulse {format_field(push.impulse)} N s: a push needs an impulse > 0"
    return ""
