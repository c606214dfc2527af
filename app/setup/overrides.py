"""``--set NAME=VALUE``: change one parameter of a run, a push grid or a sweep.

Why one long module: parsing, ranges and error wording of one option language.

Every tuning choice of a robot description (T_SP, the reaction time, the landing
depth, the flywheel, ...) can be measured again from the command line,
for example ``rsg grid --set swing_preparation_time=0.3 --controllers rsg --out DIR``.
A name is looked up in this order:

1. a field of the robot description (:class:`robots.description.RobotDescription`):
   gait, planner bounds and timing (``swing_preparation_time``, ``step_reaction_time``,
   ``filter_time_constant``, ``angular_momentum_rate_max``, ``com_height``, ...);
2. an option of the PyBullet backend: the whole-body stabilizer's
   (:class:`app.stabilizer.config.StabilizerConfig`: ``landing_depth``,
   ``flywheel_momentum``, ...) and ``control_period``;
3. a parameter of the RSG (:class:`planner.parameters.RsgParameters`) that the
   description does not set (``crossing_margin``, ``step_decrease_margin``,
   ``push_hold_time``, ...).

On ``--model lipm`` (the paper's point mass) every RSG parameter may be set, and
nothing else. On ``--model lipm --robot NAME`` (the robot's planner on the point
mass) the description fields its planner reads and the RSG parameters of 3.

RSG parameters are applied after ``--paper-rules``, so ``--set`` wins over it.

Values are numbers, ``true``/``false``, two comma-separated numbers for a pair
(``step_max=0.35,0.4``), ``none`` where the option allows it, or comma-separated joint names
(``locked_joints=none`` actuates every joint). Numbers are ASCII decimals (no nan,
inf, hex or ``_``). Each parameter has a range, defined where the parameter is (the
planner's ``planner.parameters.RANGES``, the description, the backend's
``OPTION_RANGES``); :func:`check_overrides` builds what a run builds, without loading
a robot, before any work starts, and words every error as the ``--set`` the user gave,
its value and what is allowed (:func:`blame`). On ``--model lipm`` the settings only the
full robot reads are refused (:data:`PYBULLET_ONLY_FIELDS`, the backend options).
"""

from __future__ import annotations

import dataclasses
import re
from collections.abc import Mapping
from typing import Any

from planner.exceptions import ParameterError
from planner.parameters import RsgParameters
from robots.description import RobotDescription

#: (name, value text) pairs as given on the command line, in order.
Overrides = tuple[tuple[str, str], ...]

#: The models that simulate the whole robot (the same settings on each engine).
ROBOT_MODELS = ("pybullet", "mujoco")
#: Every model a command's ``--model`` may name: the point mass and the full robots.
MODELS = ("lipm", *ROBOT_MODELS)


def is_robot_model(model: str) -> bool:
    """Whether ``model`` simulates the whole robot (any engine of :data:`ROBOT_MODELS`)."""
    return model in ROBOT_MODELS


#: Description fields that may be set: the numbers of the gait, the planner's bounds
#: and timing, the fall thresholds, PyBullet's time step (the position gains follow,
#: keeping the servos' time constants) and solver iterations, and the locked joints
#: (comma-separated names, or ``none``; not the URDF, links, sole or gains).
DESCRIPTION_FIELDS = {
    "com_height": "float",
    "rotational_height": "float",
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
    "touchdown_window": "float",
    "dcm_inset": "float | None",
    "physics_time_step": "float",
    "solver_iterations": "int",
    "locked_joints": "names",
}

#: Description fields only the full robot in PyBullet reads (its physics, IK and fall
#: rule); on ``--model lipm --robot NAME`` they would change nothing, so they are refused.
PYBULLET_ONLY_FIELDS = frozenset(
    {
        "foot_spacing",
        "fall_base_height",
        "fall_tilt",
        "swing_height",
        "ground_friction",
        "sole_spinning_friction",
        "physics_time_step",
        "solver_iterations",
        "locked_joints",
        "touchdown_window",
    }
)

#: Longest value text ``--set`` takes (a list of joint names fits).
MAX_VALUE_LENGTH = 1000
_NUMBER = re.compile(r"[+-]?(\d+(\.\d*)?|\.\d+)([eE][+-]?\d+)?", re.ASCII)
_INTEGER = re.compile(r"[+-]?\d{1,9}", re.ASCII)


def backend_option_types() -> dict[str, str]:
    """PyBullet backend option -> its annotation (``"float"``, ``"str"``, ...): the
    whole-body stabilizer's options and the control period."""
    from app.stabilizer.config import StabilizerConfig

    types = {field.name: str(field.type) for field in dataclasses.fields(StabilizerConfig)}
    return {**types, "control_period": "float"}


def _paper_point_mass(model: str, robot: str | None) -> bool:
    """The paper's LIPM (no robot description involved)."""
    return model == "lipm" and robot is None


def rsg_parameter_types(model: str = "pybullet", robot: str | None = None) -> dict[str, str]:
    """RSG parameters ``--set`` may change on ``model`` -> their kind (``"float"``,
    ``"float | None"``, ``"bool"``): all of them on the paper's LIPM; with a robot those
    its description does not set."""
    paper = _paper_point_mass(model, robot)
    return {
        f.name: str(f.type)
        for f in dataclasses.fields(RsgParameters)
        if paper or (f.name not in DESCRIPTION_FIELDS and not f.name.startswith("lqr_"))
    }


def description_field_types(model: str = "pybullet") -> dict[str, str]:
    """Description fields ``--set`` may change on ``model`` (with a robot) -> their kind:
    on the LIPM only those its planner reads."""
    if model in ROBOT_MODELS:
        return dict(DESCRIPTION_FIELDS)
    return {k: v for k, v in DESCRIPTION_FIELDS.items() if k not in PYBULLET_ONLY_FIELDS}


def allowed_names(model: str = "pybullet", robot: str | None = None) -> list[str]:
    """Every name ``--set`` accepts on ``model`` (with ``robot``: ``None`` on the LIPM
    is the paper's point mass)."""
    if _paper_point_mass(model, robot):
        return sorted(rsg_parameter_types("lipm", None))
    backend = backend_option_types() if model in ROBOT_MODELS else {}
    fields = description_field_types(model)
    return sorted({**fields, **backend, **rsg_parameter_types(model, robot)})


def parse_decimal(text: str) -> float | None:
    """``text`` as a finite decimal number (ASCII digits, no nan, inf, hex or ``_``), or
    None."""
    if not _NUMBER.fullmatch(text):
        return None
    value = float(text)
    return value if abs(value) < float("inf") else None


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
        if not all(re.fullmatch(r"[A-Za-z_][A-Za-z0-9_.-]*", n, re.ASCII) for n in names):
            raise ParameterError(f"--set {name}", text, "comma-separated joint names, or none")
        return names
    if "str" in options:
        return text
    if "int" in options:
        if not _INTEGER.fullmatch(text):
            raise ParameterError(f"--set {name}", text, "an integer")
        return int(text)
    values = [parse_decimal(part.strip()) for part in text.split(",")]
    if values and all(v is not None for v in values):
        if len(values) == 1 and "float" in options:
            return values[0]
        if len(values) == 2 and "tuple[float, float]" in options:
            return (values[0], values[1])
    wanted = " or ".join(
        {
            "float": "a finite decimal number",
            "tuple[float, float]": "two numbers a,b",
            "None": "none",
        }.get(option, option)
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
            given twice, a setting that would do nothing on ``model``, or a value of
            the wrong kind.
    """
    description: dict[str, Any] = {}
    backend: dict[str, Any] = {}
    rsg: dict[str, Any] = {}
    paper = _paper_point_mass(model, robot)
    fields = {} if paper else description_field_types(model)
    backend_types = backend_option_types() if model in ROBOT_MODELS else {}
    rsg_types = rsg_parameter_types(model, robot)
    seen: set[str] = set()
    for name, text in overrides:
        if name in seen:
            raise ParameterError(f"--set {name}", text, "each name at most once")
        seen.add(name)
        if name in fields:
            description[name] = parse_value(name, text, fields[name])
        elif name in backend_types:
            backend[name] = parse_value(name, text, backend_types[name])
        elif name in rsg_types:
            rsg[name] = parse_value(name, text, rsg_types[name])
        elif model == "lipm" and (name in PYBULLET_ONLY_FIELDS or _is_backend_option(name)):
            raise ParameterError(
                f"--set {name}",
                text,
                f"it only with --model {' or '.join(ROBOT_MODELS)}: a setting of the full "
                "robot (its physics, IK or fall rule), which the point mass does not have",
            )
        else:
            if paper:
                where = " (--model lipm: RSG parameters only)"
            elif model in ROBOT_MODELS:
                where = ""
            else:
                where = " (--model lipm with a robot: the planner's settings only)"
            allowed = ", ".join(allowed_names(model, robot))
            raise ParameterError("--set", name[:60], f"one of{where}: {allowed}")
    return ParsedOverrides(description, backend, rsg)


def _is_backend_option(name: str) -> bool:
    return name in backend_option_types()


def apply_to_description(
    description: RobotDescription, parsed: ParsedOverrides
) -> RobotDescription:
    """``description`` with the description fields and backend options of ``parsed``."""
    if not parsed.description and not parsed.backend:
        return description
    fields = dict(parsed.description)
    options = {**description.backend_options, **parsed.backend}
    return dataclasses.replace(description, **fields, backend_options=options)


def apply_to_rsg(rsg: RsgParameters, parsed: ParsedOverrides) -> RsgParameters:
    """``rsg`` with the RSG parameters of ``parsed`` (validated by RsgParameters)."""
    return dataclasses.replace(rsg, **parsed.rsg) if parsed.rsg else rsg


@dataclasses.dataclass(frozen=True)
class RunSettings:
    """What a run's settings give before its backend is built.

    Attributes:
        control_period: The loop's tick [s].
        mass: The planner's mass [kg] (the description's on a robot; PyBullet measures
            the robot's to within a few grams).
    """

    control_period: float
    mass: float


def check_overrides(
    overrides: Overrides,
    model: str = "pybullet",
    robot: str | RobotDescription | None = None,
    controller: str = "rsg",
    paper: bool = False,
) -> RunSettings:
    """Check ``overrides`` the way a run would use them, without loading a robot: the
    description with its fields, the PyBullet backend's options
    (:func:`app.backends.pybullet.check_backend_options`), the planner's configuration
    (after ``paper``, the paper's rules) and its Lyapunov design, and the swing foot's
    timing. This is the one place that turns a range error into one that names the
    ``--set`` given, its value and what is allowed (:func:`blame`).

    Args:
        overrides: ``--set`` pairs.
        model, robot, controller: As on the command line (``robot`` None: G1 on
            ``pybullet``, the paper's point mass on ``lipm``; or a description).
        paper: ``--paper-rules``.

    Returns:
        The run's control period and mass.

    Raises:
        ParameterError: A bad override, named as the user wrote it; or a bad ``robot``.
    """
    if model in ROBOT_MODELS and robot is None:
        from robots import DEFAULT_ROBOT

        robot = DEFAULT_ROBOT
    description = None
    if robot is not None:
        from robots import get_robot

        # An unknown robot is not the overrides' fault.
        description = robot if isinstance(robot, RobotDescription) else get_robot(robot)
    parsed = parse_overrides(overrides, model, None if description is None else description.name)
    try:
        return _build_settings(parsed, model, description, controller, paper)
    except ParameterError as exc:
        if not overrides:
            raise
        raise blame(exc, overrides) from None


def _build_settings(
    parsed: ParsedOverrides,
    model: str,
    robot: RobotDescription | None,
    controller: str,
    paper: bool,
) -> RunSettings:
    """Build what a run builds from ``parsed`` (see :func:`check_overrides`)."""
    from app.backends.lipm import CONTROL_PERIOD
    from app.setup.paper_rules import paper_rules
    from planner.lyapunov import design_lyapunov
    from planner.parameters import PlannerConfig

    if robot is None:
        config = PlannerConfig(controller=controller)
        period = CONTROL_PERIOD
    else:
        from app.setup.robot_config import planner_config_for

        description = apply_to_description(robot, parsed)
        config = planner_config_for(description, description.total_mass, controller)
        period = CONTROL_PERIOD
        if model in ROBOT_MODELS:
            from app.backends.pybullet import DEFAULT_CONTROL_PERIOD, check_backend_options
            from kinematics.swing_foot import SwingTiming

            check_backend_options(description, description.backend_options)
            period = float(
                description.backend_options.get("control_period", DEFAULT_CONTROL_PERIOD)
            )
    if paper:
        config = paper_rules(config)
    config = dataclasses.replace(config, rsg=apply_to_rsg(config.rsg, parsed))
    design_lyapunov(config.model, config.constraints, config.rsg)
    if model in ROBOT_MODELS:
        SwingTiming(
            config.gait.double_support_duration,
            config.rsg.swing_preparation_time,
            config.gait.step_duration,
        )
    return RunSettings(period, config.model.mass)


def blame(exc: ParameterError, overrides: Overrides) -> ParameterError:
    """``exc``, raised while building with ``overrides``, as an error naming the
    ``--set`` that caused it: the one whose name the error names, else the only one
    given, else all of them together (a rule between two parameters)."""
    given = dict(overrides)
    if exc.field.startswith("--set"):
        return exc
    if exc.field in given:
        return ParameterError(f"--set {exc.field}", given[exc.field], exc.allowed)
    message = str(exc)
    named = [
        n for n in given if re.search(rf"(?<![A-Za-z0-9_]){re.escape(n)}(?![A-Za-z0-9_])", message)
    ]
    culprits = named or list(given)
    because = f"{exc.field}={exc.value!r} to be {exc.allowed}"
    if len(culprits) == 1:
        name = culprits[0]
        return ParameterError(f"--set {name}", given[name], f"a value that allows {because}")
    return ParameterError(
        "--set " + ", ".join(culprits),
        tuple(given[n] for n in culprits),
        f"values that together allow {because}",
    )
