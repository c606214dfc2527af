"""``--set NAME=VALUE``: change one parameter of a run, a push grid or a sweep.

Every tuning choice recorded in ``robots/g1.py`` (T_SP, the reaction time, the CoP
loops, the swing's descent slope, ...) can be measured again from the command line,
for example ``rsg grid --set swing_preparation_time=0.3 --controllers rsg --out DIR``.
A name is looked up in this order:

1. a field of the robot description (:class:`robots.description.RobotDescription`):
   gait, planner bounds and timing (``swing_preparation_time``, ``step_reaction_time``,
   ``filter_time_constant``, ``angular_momentum_rate_max``, ``com_height``, ...);
2. an option of the PyBullet backend (the keyword arguments of
   :class:`app.pybullet_backend.PyBulletBackend`: ``cop_admittance``,
   ``cop_feedback``, ``swing_descent_slope``, ``landing_clearance``, ...);
3. a parameter of the RSG (:class:`planner.parameters.RsgParameters`) that the
   description does not set (``crossing_margin``, ``step_decrease_margin``,
   ``push_hold_time``, ...).

On ``--model lipm`` (the paper's point mass) every RSG parameter may be set, and
nothing else. On ``--model lipm --robot NAME`` (the robot's planner on the point
mass) the description fields and the RSG parameters of 1. and 3. may be set.

RSG parameters are applied after ``--paper-rules``, so ``--set`` wins over it.

Values are numbers, ``true``/``false``, two comma-separated numbers for a pair
(``cop_feedback=0,2``), ``none`` where the option allows it, or a word for a
string option (``plan_angular_momentum=feedback``), or comma-separated joint names
(``locked_joints=none`` actuates every joint). Ranges are checked where the
parameter is used (the description, the backend, the planner), each with an error
that names it.
"""

from __future__ import annotations

import argparse
import dataclasses
import inspect
import math
from collections.abc import Mapping
from typing import Any

from planner.exceptions import ParameterError
from planner.parameters import RsgParameters
from robots.description import RobotDescription

#: (name, value text) pairs as given on the command line, in order.
Overrides = tuple[tuple[str, str], ...]

#: Description fields that may be set: the numbers of the gait, the planner's bounds
#: and timing, the fall thresholds, PyBullet's time step (the position gains follow,
#: keeping the servos' time constants) and solver iterations, and the locked joints
#: (comma-separated names, or ``none``; not the URDF, links, sole or gains).
DESCRIPTION_FIELDS = {
    "com_height": "float",
    "foot_spacing": "float",
    "fall_base_height": "float",
    "fall_tilt": "float",
    "swing_height": "float",
    "ground_friction": "float",
    "sole_spinning_friction": "float",
    "stride_length": "float",
    "step_width": "float",
    "double_support_duration": "float",
    "single_support_duration": "float",
    "step_min": "tuple[float, float]",
    "step_max": "tuple[float, float]",
    "angular_momentum_rate_max": "float",
    "lqr_dcm_error_scale": "float",
    "swing_preparation_time": "float",
    "filter_time_constant": "float",
    "step_reaction_time": "float",
    "reanchor_time": "float",
    "dcm_inset": "float | None",
    "physics_time_step": "float",
    "solver_iterations": "int",
    "locked_joints": "names",
}

#: Backend keyword arguments that are not options of a run.
_NOT_BACKEND_OPTIONS = {"self", "robot", "timing"}


def backend_option_types() -> dict[str, str]:
    """PyBullet backend option -> its annotation (``"float"``, ``"bool"``, ...)."""
    from .pybullet_backend import PyBulletBackend

    parameters = inspect.signature(PyBulletBackend.__init__).parameters
    return {
        name: str(parameter.annotation)
        for name, parameter in parameters.items()
        if name not in _NOT_BACKEND_OPTIONS
    }


def _paper_point_mass(model: str, robot: str | None) -> bool:
    """The paper's LIPM (no robot description involved)."""
    return model == "lipm" and robot is None


def rsg_parameter_types(model: str = "pybullet", robot: str | None = None) -> dict[str, str]:
    """RSG parameters ``--set`` may change on ``model`` -> ``"float"`` (``"bool"`` for a
    switch): all of them on the paper's LIPM; with a robot those its description does
    not set."""
    paper = _paper_point_mass(model, robot)
    return {
        f.name: "bool" if f.type in ("bool", bool) else "float"
        for f in dataclasses.fields(RsgParameters)
        if paper or (f.name not in DESCRIPTION_FIELDS and not f.name.startswith("lqr_"))
    }


def allowed_names(model: str = "pybullet", robot: str | None = None) -> list[str]:
    """Every name ``--set`` accepts on ``model`` (with ``robot``: ``None`` on the LIPM
    is the paper's point mass)."""
    if _paper_point_mass(model, robot):
        return sorted(rsg_parameter_types("lipm", None))
    backend = backend_option_types() if model == "pybullet" else {}
    return sorted({**DESCRIPTION_FIELDS, **backend, **rsg_parameter_types(model, robot)})


def add_robot_argument(parser: argparse.ArgumentParser) -> None:
    """Add ``--robot`` to a command's parser (default ``None``: G1 on ``pybullet``,
    the paper's point mass on ``lipm``)."""
    parser.add_argument(
        "--robot",
        default=None,
        help="robot (default: g1 on --model pybullet; on --model lipm the paper's point "
        "mass, or with --robot that robot's planner: its mass, sole, gait and timing on "
        "the point mass)",
    )


def add_set_argument(parser: argparse.ArgumentParser) -> None:
    """Add the repeatable ``--set NAME=VALUE`` option to a command's parser."""
    parser.add_argument(
        "--set",
        dest="overrides",
        type=parse_assignment,
        action="append",
        default=[],
        metavar="NAME=VALUE",
        help="change one parameter: a robot description field, a PyBullet backend option "
        "or an RSG parameter, e.g. --set swing_preparation_time=0.3 --set cop_admittance=0.2 "
        "(repeatable; a wrong name lists the allowed ones)",
    )


def parse_assignment(text: str) -> tuple[str, str]:
    """argparse type of ``--set``: ``NAME=VALUE`` -> (name, value text)."""
    name, sep, value = text.partition("=")
    if not sep or not name.strip() or not value.strip():
        raise argparse.ArgumentTypeError(
            f"--set {text!r}: NAME=VALUE, e.g. --set swing_preparation_time=0.3"
        )
    return name.strip(), value.strip()


def parse_value(name: str, text: str, kind: str) -> Any:
    """``text`` as a value of annotation ``kind``.

    Raises:
        ParameterError: ``text`` is not such a value.
    """
    options = [part.strip() for part in kind.split("|")]
    lowered = text.lower()
    if "None" in options and lowered == "none":
        return None
    if "bool" in options:
        if lowered in ("true", "1", "yes", "on"):
            return True
        if lowered in ("false", "0", "no", "off"):
            return False
        raise ParameterError(f"--set {name}", text, "true or false")
    if "names" in options:  # comma-separated joint names; none: an empty tuple
        if lowered == "none":
            return ()
        names = tuple(part.strip() for part in text.split(","))
        if not all(names):
            raise ParameterError(f"--set {name}", text, "comma-separated names, or none")
        return names
    if "str" in options:
        return text
    if "int" in options:
        try:
            return int(text)
        except ValueError:
            raise ParameterError(f"--set {name}", text, "an integer") from None
    numbers = text.split(",")
    try:
        values = [float(part) for part in numbers]
    except ValueError:
        values = []
    if values and all(math.isfinite(v) for v in values):
        if len(values) == 1 and "float" in options:
            return values[0]
        if len(values) == 2 and "tuple[float, float]" in options:
            return (values[0], values[1])
    wanted = " or ".join(
        {"float": "a number", "tuple[float, float]": "two numbers a,b", "None": "none"}.get(
            option, option
        )
        for option in options
    )
    raise ParameterError(f"--set {name}", text, wanted)


@dataclasses.dataclass(frozen=True)
class ParsedOverrides:
    """Overrides sorted by where they apply.

    Attributes:
        description: Description field -> value.
        backend: Backend option -> value.
        rsg: RSG parameter -> value.
    """

    description: Mapping[str, Any]
    backend: Mapping[str, Any]
    rsg: Mapping[str, Any]


def parse_overrides(
    overrides: Overrides, model: str = "pybullet", robot: str | None = None
) -> ParsedOverrides:
    """Sort and parse ``overrides`` for ``model`` with ``robot`` (``None`` on the LIPM:
    the paper's point mass).

    Raises:
        ParameterError: An unknown name (the message lists the allowed ones), a name
            given twice, or a value of the wrong kind.
    """
    description: dict[str, Any] = {}
    backend: dict[str, Any] = {}
    rsg: dict[str, Any] = {}
    paper = _paper_point_mass(model, robot)
    backend_types = backend_option_types() if model == "pybullet" else {}
    rsg_types = rsg_parameter_types(model, robot)
    seen: set[str] = set()
    for name, text in overrides:
        if name in seen:
            raise ParameterError(f"--set {name}", text, "each name at most once")
        seen.add(name)
        if not paper and name in DESCRIPTION_FIELDS:
            description[name] = parse_value(name, text, DESCRIPTION_FIELDS[name])
        elif name in backend_types:
            backend[name] = parse_value(name, text, backend_types[name])
        elif name in rsg_types:
            rsg[name] = parse_value(name, text, rsg_types[name])
        else:
            if paper:
                where = " (--model lipm: RSG parameters only)"
            elif model == "pybullet":
                where = ""
            else:
                where = " (--model lipm with a robot: no backend options)"
            allowed = ", ".join(allowed_names(model, robot))
            raise ParameterError("--set", name, f"one of{where}: {allowed}")
    return ParsedOverrides(description, backend, rsg)


def apply_to_description(
    description: RobotDescription, parsed: ParsedOverrides
) -> RobotDescription:
    """``description`` with the description fields and backend options of ``parsed``."""
    if not parsed.description and not parsed.backend:
        return description
    fields = dict(parsed.description)
    if "physics_time_step" in fields:  # with the gains that keep the servos' time constants
        description = description.with_physics_time_step(fields.pop("physics_time_step"))
    options = {**description.backend_options, **parsed.backend}
    return dataclasses.replace(description, **fields, backend_options=options)


def apply_to_rsg(rsg: RsgParameters, parsed: ParsedOverrides) -> RsgParameters:
    """``rsg`` with the RSG parameters of ``parsed`` (validated by RsgParameters)."""
    return dataclasses.replace(rsg, **parsed.rsg) if parsed.rsg else rsg
