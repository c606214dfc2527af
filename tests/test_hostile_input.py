"""Hostile input: a corpus of malformed and extreme inputs to every command and file.

Each case is one command line (``rsg run``, ``sweep``, ``grid``, ``bench``), often with a
scenario or resume file written first. A refusal must be clean: exit code 2, one or
two lines on stderr that name the field and the value (the expected fragments), no
traceback, no RuntimeWarning, and no result written. An acceptance is documented
(docs/input-validation.md) and checked for what it promises. The cases run in this
process (``app.cli.main``) on the LIPM with short durations; a few run as subprocesses
(real exit codes, signals) at the end of the file.

Why one long module: it is one corpus, a table of cases with one runner, so that a
new field's hostile values go where all the others are.
"""

from __future__ import annotations

import json
import math
import os
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from app.cli import main
from app.experiments.sweep import SPEC_FILE, Job, SweepSpec
from app.results.folder import RESULT_FILES
from app.setup.overrides import backend_option_types, rsg_parameter_types

pytestmark = pytest.mark.filterwarnings("error::RuntimeWarning")

LIPM = ["--model", "lipm", "--no-plots", "--quiet"]


@dataclass(frozen=True)
class Case:
    """One hostile input.

    Attributes:
        name: Case id.
        argv: Command line; ``{out}`` is a fresh folder, ``{tmp}`` the case's folder,
            ``{file}`` the file written from ``content`` (named ``file_name``).
        expect: Fragments stderr must contain (field, value, what is allowed); None:
            a documented acceptance, checked by ``check``.
        content: Bytes of ``{file}``.
        file_name: Its name.
        setup: Prepares ``{tmp}`` before the command (resume files, folders).
        check: For an acceptance: called with (exit code, stdout, stderr, tmp).
    """

    name: str
    argv: list[str]
    expect: tuple[str, ...] | None = ()
    content: bytes | None = None
    file_name: str = "scenario.toml"
    setup: Callable[[Path], None] | None = None
    check: Callable[[int, str, str, Path], None] | None = field(default=None, repr=False)


def toml_case(name: str, text: str | bytes, *expect: str, extra: tuple[str, ...] = ()) -> Case:
    """``rsg run`` on a scenario file with ``text``."""
    content = text.encode() if isinstance(text, str) else text
    argv = ["run", *LIPM, "--scenario", "{file}", *extra, "--out", "{out}"]
    return Case(f"toml-{name}", argv, tuple(expect), content)


PUSH = "[[push]]\nt = 1.0\nimpulse = [5.0, 0.0]\nduration = 0.1\n"


def push_case(name: str, entry: str, *expect: str) -> Case:
    """A scenario file whose only push is ``entry`` (TOML key = value lines)."""
    return toml_case(name, f"duration = 2.0\n[[push]]\n{entry}\n", *expect)


# ---------------------------------------------------------------- scenario files
SCENARIO_FILES = [
    toml_case("latin1", 'name = "pouss\xe9e"\n'.encode("latin-1"), "UTF-8", "byte 13"),
    toml_case("utf16-le", "duration = 2.0\n".encode("utf-16"), "UTF-8", "byte 0"),
    toml_case("utf16-be", "duration = 2.0\n".encode("utf-16-be"), "valid TOML"),
    toml_case("random-bytes", bytes(range(256)) * 4, "UTF-8"),
    toml_case("nul-bytes", b"duration = 2.0\x00\n", "valid TOML"),
    toml_case("not-toml", "this is not toml\n", "valid TOML"),
    toml_case("unclosed-array", "duration = [1.0\n", "valid TOML"),
    toml_case("duplicate-key", "duration = 1.0\nduration = 2.0\n", "valid TOML"),
    toml_case("nested-arrays", "x = " + "[" * 5000 + "]" * 5000 + "\n", "nested"),
    toml_case("nested-tables", "x = " + "{a = " * 3000 + "1" + "}" * 3000 + "\n", "nested"),
    toml_case("too-big", "# padding\n" * 150_000, "at most 1000000 bytes"),
    toml_case("100000-pushes", "duration = 2.0\n" + PUSH * 100_000, "at most 1000000 bytes"),
    toml_case("1001-pushes", "duration = 3600.0\n" + PUSH * 1001, "push", "at most 1000"),
    toml_case("push-number", "push = 5\n", "push=5", "array of tables"),
    toml_case("push-true", "push = true\n", "push=True", "array of tables"),
    toml_case("push-float", "push = 1.5\n", "push=1.5", "array of tables"),
    toml_case("push-date", "push = 1979-05-27\n", "push=", "1979", "array of tables"),
    toml_case("push-datetime", "push = 1979-05-27T07:32:00Z\n", "push=", "array of tables"),
    toml_case("push-empty-string", 'push = ""\n', "push=''", "array of tables"),
    toml_case("push-inline-table", "push = {}\n", "push={}", "array of tables"),
    toml_case("push-table", "[push]\nt = 1.0\nimpulse = [1, 1]\n", "push=", "array of tables"),
    toml_case("push-list-of-numbers", "push = [1, 2]\n", "push=[1, 2]", "array of tables"),
    toml_case("push-list-of-lists", "push = [[1.0, 2.0]]\n", "array of tables"),
    toml_case("push-list-of-strings", 'push = ["t=1"]\n', "array of tables"),
    push_case(
        "push-unknown-key", "t = 1.0\nimpulse = [1, 1]\ndurration = 0.1", "durration", "only t"
    ),
    push_case("push-no-impulse", "t = 1.0", "push[0] impulse='missing'"),
    push_case("push-no-t", "impulse = [1, 1]", "push[0] t='missing'"),
    push_case("t-true", "t = true\nimpulse = [1, 1]", "push[0] t=True"),
    push_case("t-false", "t = false\nimpulse = [1, 1]", "push[0] t=False"),
    push_case("t-string", 't = "1.0"\nimpulse = [1, 1]', "push[0] t='1.0'"),
    push_case("t-list", "t = [1.0]\nimpulse = [1, 1]", "push[0] t=[1.0]"),
    push_case("t-date", "t = 2020-01-01\nimpulse = [1, 1]", "push[0] t="),
    push_case("t-negative", "t = -1.0\nimpulse = [1, 1]", "push[0] t=-1.0", "[0, 3600] s"),
    push_case("t-nan", "t = nan\nimpulse = [1, 1]", "push[0] t=nan"),
    push_case("t-inf", "t = inf\nimpulse = [1, 1]", "push[0] t=inf"),
    push_case("t-1e308", "t = 1e308\nimpulse = [1, 1]", "push[0] t=1e+308", "[0, 3600] s"),
    push_case("t-after-end", "t = 2.5\nimpulse = [1, 1]", "push at t=2.5 s", "t <= 2 s"),
    push_case("t-at-end", "t = 2.0\nimpulse = [1, 1]", "push at t=2 s", "the end of the run"),
    push_case("ends-after-end", "t = 1.95\nimpulse = [1, 1]", "ending at t=2.05", "t <= 2 s"),
    push_case("impulse-bools", "t = 1.0\nimpulse = [true, false]", "impulse=[True, False]"),
    push_case("impulse-one", "t = 1.0\nimpulse = [1.0]", "impulse=[1.0]", "two numbers"),
    push_case("impulse-three", "t = 1.0\nimpulse = [1, 2, 3]", "impulse=[1, 2, 3]"),
    push_case("impulse-string", 't = 1.0\nimpulse = "1,2"', "impulse='1,2'"),
    push_case("impulse-number", "t = 1.0\nimpulse = 5", "impulse=5", "two numbers"),
    push_case("impulse-table", "t = 1.0\nimpulse = {x = 1, y = 2}", "impulse=", "two numbers"),
    push_case("impulse-mixed", 't = 1.0\nimpulse = [1, "a"]', "impulse=[1, 'a']"),
    push_case("impulse-nan", "t = 1.0\nimpulse = [nan, 0.0]", "impulse=", "two finite numbers"),
    push_case("impulse-inf", "t = 1.0\nimpulse = [inf, 0.0]", "impulse=", "two finite numbers"),
    push_case(
        "impulse-1e308",
        "t = 1.0\nimpulse = [1e308, 1e308]",
        "impulse=[1e+308, 1e+308]",
        "norm <= 500 N s",
    ),
    push_case(
        "impulse-huge-int",
        "t = 1.0\nimpulse = [9223372036854775807, 0]",
        "impulse=[9.223372036854776e+18, 0.0]",
        "norm <= 500",
    ),
    push_case("impulse-600", "t = 1.0\nimpulse = [600.0, 0.0]", "impulse=[600.0, 0.0]"),
    push_case("impulse-nested", "t = 1.0\nimpulse = [[1], [2]]", "impulse=[[1], [2]]"),
    push_case(
        "duration-true", "t = 1.0\nimpulse = [1, 1]\nduration = true", "duration=True", "(0, 2] s"
    ),
    push_case("duration-zero", "t = 1.0\nimpulse = [1, 1]\nduration = 0.0", "duration=0.0"),
    push_case("duration-negative", "t = 1.0\nimpulse = [1, 1]\nduration = -0.1", "duration=-0.1"),
    push_case("duration-nan", "t = 1.0\nimpulse = [1, 1]\nduration = nan", "duration=nan"),
    push_case("duration-inf", "t = 1.0\nimpulse = [1, 1]\nduration = inf", "duration=inf"),
    push_case("duration-3", "t = 1.0\nimpulse = [1, 1]\nduration = 3.0", "duration=3.0"),
    push_case("duration-string", 't = 1.0\nimpulse = [1, 1]\nduration = "0.1"', "duration='0.1'"),
    toml_case("run-duration-zero", "duration = 0.0\n", "duration=0.0", "(0, 3600] s"),
    toml_case("run-duration-negative", "duration = -5\n", "duration=-5"),
    toml_case("run-duration-nan", "duration = nan\n", "duration=nan"),
    toml_case("run-duration-inf", "duration = inf\n", "duration=inf"),
    toml_case("run-duration-1e300", "duration = 1e300\n", "duration=1e+300"),
    toml_case("run-duration-true", "duration = true\n", "duration=True"),
    toml_case("run-duration-string", 'duration = "12"\n', "duration='12'"),
    toml_case("run-duration-list", "duration = [12]\n", "duration=[12]"),
    toml_case("run-duration-3601", "duration = 3601\n", "duration=3601"),
    toml_case(
        "run-duration-below-tick",
        "duration = 0.0004\n",
        "duration=0.0004",
        "one control tick (0.001 s",
    ),
    toml_case("run-duration-1e-9", "duration = 1e-9\n", "duration=1e-09", "control tick"),
    toml_case(
        "reference-mass-zero", "reference_mass = 0.0\n", "reference_mass=0.0", "[0.1, 1000] kg"
    ),
    toml_case("reference-mass-negative", "reference_mass = -60\n", "reference_mass=-60"),
    toml_case("reference-mass-inf", "reference_mass = inf\n", "reference_mass=inf"),
    toml_case("reference-mass-nan", "reference_mass = nan\n", "reference_mass=nan"),
    toml_case("reference-mass-tiny", "reference_mass = 1e-300\n", "reference_mass=1e-300"),
    toml_case("reference-mass-true", "reference_mass = true\n", "reference_mass=True"),
    toml_case("reference-mass-string", 'reference_mass = "60"\n', "reference_mass='60'"),
    toml_case("reference-mass-1e9", "reference_mass = 1e9\n", "reference_mass=1000000000.0"),
    toml_case(
        "reference-mass-scales-too-far",
        "duration = 2.0\nreference_mass = 0.1\n" + PUSH.replace("5.0", "10.0"),
        "reference_mass",
        "500 N s",
    ),
    toml_case("name-number", "name = 5\n", "name=5", "a string"),
    toml_case("name-empty", 'name = ""\n', "name=''", "1 to 100 printable characters"),
    toml_case("name-true", "name = true\n", "name=True", "a string"),
    toml_case("name-newline", 'name = "a\\nb"\n', "name='a\\nb'", "printable"),
    toml_case("name-long", f'name = "{"x" * 500}"\n', "name=", "1 to 100"),
    toml_case("name-table", "[name]\nx = 1\n", "name={'x': 1}", "a string"),
    toml_case("description-number", "description = 5\n", "description=5", "a string"),
    toml_case("unknown-key", "durration = 2.0\n", "keys=['durration']", "only name"),
    toml_case("unknown-key-pushes", "[[pushes]]\nt = 1\n", "keys=['pushes']"),
    toml_case("unknown-table", "[robot]\nmass = 60\n", "keys=['robot']"),
    Case(
        "scenario-missing",
        ["run", *LIPM, "--scenario", "{tmp}/nope.toml", "--out", "{out}"],
        ("--scenario=", "nope.toml", "existing .toml file"),
    ),
    Case(
        "scenario-directory",
        ["run", *LIPM, "--scenario", "{tmp}/dir.toml", "--out", "{out}"],
        ("--scenario=", "dir.toml", "existing .toml file"),
        setup=lambda tmp: (tmp / "dir.toml").mkdir(),
    ),
    Case(
        "scenario-fifo",
        ["run", *LIPM, "--scenario", "{tmp}/fifo.toml", "--out", "{out}"],
        ("--scenario=", "fifo.toml"),
        setup=lambda tmp: os.mkfifo(tmp / "fifo.toml"),
    ),
    Case(
        "scenario-dev-zero",
        ["run", *LIPM, "--scenario", "{tmp}/zero.toml", "--out", "{out}"],
        ("--scenario=", "zero.toml"),
        setup=lambda tmp: (tmp / "zero.toml").symlink_to("/dev/zero"),
    ),
    Case(
        "scenario-dev-null",
        ["run", *LIPM, "--scenario", "/dev/null", "--out", "{out}"],
        ("--scenario='/dev/null'",),
    ),
    Case(
        "scenario-wrong-suffix",
        ["run", *LIPM, "--scenario", "{file}", "--out", "{out}"],
        ("--scenario=", "scenario.txt"),
        b"duration = 2.0\n",
        "scenario.txt",
    ),
    Case(
        "scenario-empty-name",
        ["run", *LIPM, "--scenario", "", "--out", "{out}"],
        ("--scenario=''", "paper-fig6"),
    ),
    Case(
        "scenario-unknown",
        ["run", *LIPM, "--scenario", "paper-fig7", "--out", "{out}"],
        ("--scenario='paper-fig7'", "walk, paper-fig6"),
    ),
    Case(
        "scenario-nul",
        ["run", *LIPM, "--scenario", "a\x00b.toml", "--out", "{out}"],
        ("--scenario=", "existing .toml file"),
    ),
    Case(
        "scenario-path-too-long",
        ["run", *LIPM, "--scenario", "x" * 5000 + ".toml", "--out", "{out}"],
        ("--scenario=", "xxx..."),
    ),
    Case(
        "scenario-unreadable-dir",
        ["run", *LIPM, "--scenario", "/proc/self/fdinfo/no.toml", "--out", "{out}"],
        ("--scenario=", "no.toml"),
    ),
]


# ------------------------------------------------------------------------ --push
def push_arg_case(name: str, text: str, *expect: str) -> Case:
    argv = ["run", *LIPM, "--scenario", "walk", "--duration", "2", f"--push={text}",
            "--out", "{out}"]  # fmt: skip
    return Case(f"push-{name}", argv, tuple(expect))


PUSH_ARGUMENTS = [
    push_arg_case("empty", "", "--push=''", "T:IX,IY"),
    push_arg_case("one-number", "1", "--push='1'", "T:IX,IY"),
    push_arg_case("no-impulse-y", "1:2", "--push impulse='2'", "two numbers"),
    push_arg_case("three-components", "1:2,3,4", "--push impulse='2,3,4'"),
    push_arg_case("four-fields", "1:1,1:0.1:5", "--push='1:1,1:0.1:5'"),
    push_arg_case("letters", "a:1,1", "--push='a:1,1'", "finite decimal numbers"),
    push_arg_case("letter-impulse", "1:a,1", "--push='1:a,1'"),
    push_arg_case("letter-duration", "1:1,1:x", "--push='1:1,1:x'"),
    push_arg_case("nan-time", "nan:1,1", "--push='nan:1,1'"),
    push_arg_case("inf-time", "inf:1,1", "--push='inf:1,1'"),
    push_arg_case("nan-impulse", "1:nan,1", "--push='1:nan,1'"),
    push_arg_case("inf-impulse", "1:inf,0", "--push='1:inf,0'"),
    push_arg_case("overflowing-impulse", "1:1e400,0", "--push='1:1e400,0'"),
    push_arg_case(
        "impulse-1e308", "1:1e308,1e308", "--push impulse=[1e+308, 1e+308]", "norm <= 500 N s"
    ),
    push_arg_case("impulse-600", "1:600,0", "--push impulse=[600.0, 0.0]", "norm <= 500"),
    push_arg_case("negative-time", "-1:1,1", "--push time=-1.0", "[0, 3600] s"),
    push_arg_case("time-1e308", "1e308:1,1", "--push time=1e+308", "[0, 3600] s"),
    push_arg_case("time-after-end", "13:1,1", "push at t=13 s", "t <= 2 s"),
    push_arg_case("time-at-end", "2:1,1", "push at t=2 s", "the end of the run"),
    push_arg_case("ends-after-end", "1.95:1,1", "ending at t=2.05", "t <= 2 s"),
    push_arg_case("zero-duration", "1:1,1:0", "--push duration=0.0", "(0, 2] s"),
    push_arg_case("negative-duration", "1:1,1:-0.1", "--push duration=-0.1"),
    push_arg_case("long-duration", "1:1,1:3", "--push duration=3.0"),
    push_arg_case("nan-duration", "1:1,1:nan", "--push='1:1,1:nan'"),
    push_arg_case("arabic-digits", "\u0661:1,1", "--push=", "finite decimal numbers"),
    push_arg_case("fullwidth-digits", "\uff11:1,1", "--push=", "finite decimal numbers"),
    push_arg_case("underscore", "1_0:1,1", "--push='1_0:1,1'"),
    push_arg_case("hex", "0x1:1,1", "--push='0x1:1,1'"),
    push_arg_case("comma-decimal", "1,5:1,1", "--push='1,5:1,1'"),
    push_arg_case("semicolons", "1;1;1", "--push='1;1;1'"),
    push_arg_case("long-text", "1:" + "1," * 5000 + "1", "--push impulse='1,1,"),
]


# --------------------------------------------------------------------- --duration
def duration_case(name: str, text: str, *expect: str, model: str = "lipm") -> Case:
    argv = ["run", "--model", model, "--no-plots", "--quiet", "--scenario", "walk",
            f"--duration={text}", "--out", "{out}"]  # fmt: skip
    return Case(f"duration-{name}", argv, tuple(expect))


DURATIONS = [
    duration_case("zero", "0", "--duration='0'", "(0, 3600]"),
    duration_case("negative", "-1", "--duration='-1'"),
    duration_case("nan", "nan", "--duration='nan'"),
    duration_case("inf", "inf", "--duration='inf'"),
    duration_case("1e308", "1e308", "--duration='1e308'"),
    duration_case("3601", "3601", "--duration='3601'"),
    duration_case("letters", "abc", "--duration='abc'"),
    duration_case("empty", "", "--duration=''"),
    duration_case("underscore", "1_0", "--duration='1_0'"),
    duration_case("arabic", "\u0663", "--duration="),
    duration_case("below-a-tick", "0.0004", "duration=0.0004", "one control tick (0.001 s"),
    duration_case("1e-9", "1e-9", "duration=1e-09", "one control tick"),
    duration_case("5e-324", "5e-324", "duration=5e-324", "one control tick"),
    duration_case("below-a-g1-tick", "0.004", "duration=0.004", "(0.01 s", model="pybullet"),
]


# --------------------------------------------------------------------------- --set
def set_case(name: str, assignment: str, *expect: str, model: str = "lipm",
             robot: str | None = None, command: str = "run") -> Case:  # fmt: skip
    robot_args = [] if robot is None else ["--robot", robot]
    if command == "run":
        head = ["run", "--model", model, *robot_args, "--no-plots", "--quiet",
                "--scenario", "walk", "--duration", "0.2"]  # fmt: skip
    elif command == "grid":
        head = ["grid", "--model", model, *robot_args, "--controllers", "rsg", "--impulses",
                "5", "--directions", "1", "--quiet"]  # fmt: skip
    else:
        head = ["sweep", "--model", model, *robot_args, "--controllers", "rsg",
                "--directions", "1", "--phases", "0", "--quiet"]  # fmt: skip
    argv = [*head, "--set", assignment, "--out", "{out}"]
    return Case(f"{command}-{model}{'-' + robot if robot else ''}-{name}", argv, tuple(expect))


def refused_value(name: str, value: str, *expect: str, **where: str) -> Case:
    """``--set name=value`` refused with a message naming both (``where``: see set_case)."""
    return set_case(f"{name}={value}", f"{name}={value}", f"--set {name}", f"'{value}'", *expect,
                    **where)  # fmt: skip


def _just_below(name: str) -> str:
    """A value just below the range of RSG parameter ``name``."""
    from planner.parameters import RANGES

    valid = RANGES[name]
    if valid.low_open:
        return repr(valid.low)
    if valid.low == 0.0:
        return "-1e-300"
    return repr(valid.low / 10.0 if valid.low > 0.0 else valid.low * 5.0)


def rsg_parameter_cases() -> list[Case]:
    """Every RSG parameter on the paper's LIPM: far out of range both ways, just below its
    range, not a number."""
    cases = []
    for name, kind in rsg_parameter_types("lipm").items():
        if kind == "bool":
            cases += [refused_value(name, v, "true or false") for v in ("maybe", "2", "nan")]
            continue
        for value in ("1e300", "-1e300", _just_below(name)):
            cases.append(refused_value(name, value, "a number in"))
        for value in ("nan", "inf", "abc", "true", "1,2", "0x10"):
            cases.append(refused_value(name, value, "finite decimal number"))
    return cases


def description_field_cases() -> list[Case]:
    """G1's planner fields on the point mass, out of range; its PyBullet-only fields."""
    cases = []
    for name in ("stride_length", "step_width", "double_support_duration",
                 "single_support_duration", "angular_momentum_rate_max",
                 "lqr_dcm_error_scale", "swing_preparation_time", "filter_time_constant",
                 "step_reaction_time", "reanchor_time", "com_height",
                 "rotational_height"):  # fmt: skip
        cases += [refused_value(name, value, robot="g1") for value in ("1e300", "-1e300")]
    for name in ("physics_time_step=0.001", "solver_iterations=10", "locked_joints=none",
                 "fall_tilt=0.5", "ground_friction=0.8", "swing_height=0.05",
                 "foot_spacing=0.2", "fall_base_height=0.3", "sole_spinning_friction=0",
                 "landing_depth=0.004", "control_period=0.005"):  # fmt: skip
        cases.append(set_case(f"pybullet-only-{name}", name, f"--set {name.split('=')[0]}",
                              "only with --model pybullet", robot="g1"))  # fmt: skip
    for pair in ("step_min", "step_max"):
        for value in ("1", "a,b", "1e300,1e300", "nan,0"):
            cases.append(refused_value(pair, value, robot="g1"))
    return cases


def backend_option_cases() -> list[Case]:
    """PyBullet backend options far out of range: refused before the robot is loaded."""
    cases = []
    for name, kind in backend_option_types().items():
        if kind == "bool":
            values = ("maybe", "2")
        elif kind == "str":
            values = ("sideways",)
        else:
            values = ("1e300", "-1e300")
        cases += [refused_value(name, value, model="pybullet") for value in values]
    return cases


OVERRIDES = [
    *rsg_parameter_cases(),
    *description_field_cases(),
    *backend_option_cases(),
    set_case(
        "crossing-margin-vs-step-width",
        "crossing_margin=0.3",
        "--set crossing_margin",
        "'0.3'",
        "step_width=0.2",
        "crossing_margin = 0.440 m",
    ),
    set_case("com-margin-vs-window", "com_margin=0.1", "--set com_margin", "< w_y = 0.07 m"),
    set_case(
        "t-sp-vs-single-support",
        "swing_preparation_time=0.75",
        "--set swing_preparation_time",
        "single_support_duration = 0.7 s",
    ),
    set_case("unknown-name", "no_such=1", "--set='no_such'", "crossing_margin"),
    set_case("unknown-name-long", "x" * 500 + "=1", "--set=", "one of"),
    set_case("empty-name", "=1", "--set '=1'", "NAME=VALUE"),
    set_case("empty-value", "crossing_margin=", "--set 'crossing_margin='", "NAME=VALUE"),
    set_case("no-equals", "crossing_margin", "--set 'crossing_margin'", "NAME=VALUE"),
    set_case(
        "value-too-long",
        "locked_joints=" + "a," * 800 + "a",
        "--set locked_joints",
        "at most 1000",
        model="pybullet",
    ),
    set_case(
        "description-field-on-paper-lipm",
        "step_width=0.3",
        "--set='step_width'",
        "RSG parameters only",
    ),
    set_case(
        "backend-option-on-paper-lipm",
        "landing_depth=0.004",
        "--set landing_depth",
        "only with --model pybullet",
    ),
    set_case(
        "control-period-on-lipm",
        "control_period=0.5",
        "--set control_period",
        "only with --model pybullet",
    ),
    set_case(
        "control-period-0.5",
        "control_period=0.5",
        "--set control_period",
        "'0.5'",
        "[0.002, 0.012] s",
        model="pybullet",
    ),
    set_case(
        "control-period-not-multiple",
        "control_period=0.0035",
        "--set control_period",
        "'0.0035'",
        "whole multiple of the physics step",
        model="pybullet",
    ),
    set_case(
        "physics-step-not-dividing",
        "physics_time_step=0.003",
        "--set physics_time_step",
        "whole multiple",
        model="pybullet",
    ),
    set_case(
        "solver-iterations-arabic",
        "solver_iterations=\u0661\u0662",
        "--set solver_iterations",
        "an integer",
        model="pybullet",
    ),
    set_case(
        "solver-iterations-huge",
        "solver_iterations=99999999999999999999",
        "--set solver_iterations",
        "an integer",
        model="pybullet",
    ),
    set_case(
        "solver-iterations-zero",
        "solver_iterations=0",
        "--set solver_iterations",
        "1 to 200",
        model="pybullet",
    ),
    set_case(
        "locked-joints-bad-name",
        "locked_joints=a b",
        "--set locked_joints",
        "joint names",
        model="pybullet",
    ),
    set_case(
        "friction-three",
        "friction=1,2,3",
        "--set friction",
        "'1,2,3'",
        model="pybullet",
    ),
    set_case("friction-100", "friction=100", "--set friction", "[0.1, 2]", model="pybullet"),
    set_case(
        "estimator-unknown",
        "estimator=kalman",
        "--set",
        "'estimator'",
        "landing_depth",
        model="pybullet",
    ),
    set_case(
        "grid-range", "lqr_zmp_scale=1e-300", "--set lqr_zmp_scale", "'1e-300'", command="grid"
    ),
    set_case(
        "grid-rule",
        "crossing_margin=0.3",
        "--set crossing_margin",
        "step_width=0.2",
        command="grid",
    ),
    set_case(
        "grid-backend-option",
        "landing_depth=1e300",
        "--set landing_depth",
        "[0, 0.02]",
        model="pybullet",
        command="grid",
    ),
    set_case(
        "grid-pybullet-only",
        "solver_iterations=10",
        "--set solver_iterations",
        "only with --model pybullet",
        robot="g1",
        command="grid",
    ),
    set_case(
        "sweep-range",
        "swing_preparation_time=1e300",
        "--set swing_preparation_time",
        "(0, 2] s",
        command="sweep",
    ),
    set_case("sweep-rule", "com_margin=0.1", "--set com_margin", "< w_y", command="sweep"),
    set_case("sweep-unknown", "bogus=1", "--set='bogus'", command="sweep"),
    set_case(
        "sweep-backend-option",
        "control_period=0.5",
        "--set control_period",
        "[0.002, 0.012] s",
        model="pybullet",
        command="sweep",
    ),
]


# ------------------------------------------------------------------------- --out
def _results_of_another_run(tmp: Path) -> None:
    (tmp / "out").mkdir()
    (tmp / "out" / "summary.json").write_text("{}\n")


def _folder_named(name: str) -> Callable[[Path], None]:
    def setup(tmp: Path) -> None:
        (tmp / "out" / name).mkdir(parents=True)

    return setup


def _file_at_out(tmp: Path) -> None:
    (tmp / "out").write_text("a file\n")


def _symlinked_result(tmp: Path) -> None:
    (tmp / "out").mkdir()
    (tmp / "elsewhere.json").write_text("{}\n")
    (tmp / "out" / "summary.json").symlink_to(tmp / "elsewhere.json")


RUN = ["run", *LIPM, "--scenario", "walk", "--duration", "0.2"]
RUN_WITH_PLOTS = ["run", "--model", "lipm", "--quiet", "--scenario", "walk", "--duration", "0.2"]
GRID = ["grid", "--model", "lipm", "--impulses", "5", "--directions", "1", "--quiet"]
SWEEP = ["sweep", "--model", "lipm", "--directions", "1", "--phases", "0", "--quiet"]
OUT_FOLDERS = [
    Case("out-empty", [*RUN, "--out", ""], ("--out ''", "folder path")),
    Case("out-blank", [*RUN, "--out", "   "], ("--out '   '", "folder path")),
    Case("out-missing", RUN, ("--out",)),
    Case(
        "out-is-a-file",
        [*RUN, "--out", "{tmp}/out"],
        ("out: exists and is not a folder",),
        setup=_file_at_out,
    ),
    Case(
        "out-under-a-file",
        [*RUN, "--out", "{tmp}/out/sub"],
        ("out/sub: is not a folder that can be written",),
        setup=_file_at_out,
    ),
    Case(
        "out-in-proc",
        [*RUN, "--out", "/proc/rsg-results"],
        ("--out /proc/rsg-results: is not a folder that can be written",),
    ),
    Case("out-dev-null", [*RUN, "--out", "/dev/null"], ("--out /dev/null: exists and is not",)),
    Case("out-nul-byte", [*RUN, "--out", "a\x00b"], ("--out 'a\\x00b'", "NUL")),
    Case("out-too-long", [*RUN, "--out", "x" * 5000], ("--out 'xxxx", "4096")),
    Case(
        "out-name-too-long",
        [*RUN, "--out", "{tmp}/" + "x" * 300],
        ("is not a folder that can be written", "File name too long"),
    ),
    Case(
        "out-earlier-results",
        [*RUN, "--out", "{tmp}/out"],
        ("holds the results of an earlier run (summary.json)", "--overwrite"),
        setup=_results_of_another_run,
    ),
    Case(
        "out-grid-results",
        [*RUN, "--out", "{tmp}/out"],
        ("grid.json", "--overwrite"),
        setup=lambda tmp: (tmp / "out").mkdir() or (tmp / "out" / "grid.json").touch(),
    ),
    Case(
        "out-summary-is-a-folder",
        [*RUN, "--out", "{tmp}/out"],
        ("summary.json: exists and is not a file",),
        setup=_folder_named("summary.json"),
    ),
    Case(
        "out-plot-is-a-folder",
        [*RUN_WITH_PLOTS, "--out", "{tmp}/out"],
        ("fig6a_top_view.png: exists and is not a file",),
        setup=_folder_named("fig6a_top_view.png"),
    ),  # fmt: skip
    Case(
        "out-csv-is-a-folder",
        [*RUN, "--out", "{tmp}/out", "--overwrite"],
        ("timeseries.csv: exists and is not a file",),
        setup=_folder_named("timeseries.csv"),
    ),
    Case(
        "out-symlinked-result",
        [*RUN, "--out", "{tmp}/out", "--overwrite"],
        ("summary.json: exists and is not a file",),
        setup=_symlinked_result,
    ),
    Case(
        "grid-png-is-a-folder",
        [*GRID, "--out", "{tmp}/out"],
        ("grid.png: exists and is not a file",),
        setup=_folder_named("grid.png"),
    ),  # fmt: skip
    Case(
        "grid-earlier-results",
        [*GRID, "--out", "{tmp}/out"],
        ("holds the results of an earlier run (summary.json)",),
        setup=_results_of_another_run,
    ),  # fmt: skip
    Case(
        "sweep-envelope-is-a-folder",
        [*SWEEP, "--out", "{tmp}/out"],
        ("envelope.png: exists and is not a file",),
        setup=_folder_named("envelope.png"),
    ),
    Case(
        "sweep-earlier-results",
        [*SWEEP, "--out", "{tmp}/out"],
        ("holds the results of an earlier run (summary.json)",),
        setup=_results_of_another_run,
    ),  # fmt: skip
    Case(
        "bench-json-is-a-folder",
        ["bench", "--no-robot", "--samples", "10", "--out", "{tmp}/out"],
        ("bench.json: exists and is not a file",),
        setup=_folder_named("bench.json"),
    ),
    Case(
        "bench-earlier-results",
        ["bench", "--no-robot", "--samples", "10", "--out", "{tmp}/out"],
        ("holds the results of an earlier run",),
        setup=_results_of_another_run,
    ),
    Case("bench-empty-out", ["bench", "--no-robot", "--out", ""], ("--out ''",)),
    Case("grid-empty-out", ["grid", "--model", "lipm", "--out", ""], ("--out ''",)),
    Case("sweep-empty-out", ["sweep", "--out", ""], ("--out ''",)),
]


# ------------------------------------------------------------------ rsg run, misc
RUN_MISC = [
    Case(
        "model-unknown",
        ["run", "--model", "gazebo", "--out", "{out}"],
        ("--model", "'gazebo'", "lipm"),
    ),
    Case(
        "controller-unknown",
        ["run", *LIPM, "--controller", "mpc", "--out", "{out}"],
        ("--controller", "'mpc'"),
    ),
    Case(
        "placo-wpg-on-lipm",
        ["run", *LIPM, "--controller", "placo-wpg", "--out", "{out}"],
        ("--controller='placo-wpg'", "--model pybullet"),
    ),
    Case(
        "placo-wpg-paper-rules",
        ["run", "--controller", "placo-wpg", "--paper-rules", "--out", "{out}"],
        ("--paper-rules=True", "placo-wpg"),
    ),
    Case(
        "physics-log-on-lipm",
        ["run", *LIPM, "--physics-log", "--out", "{out}"],
        ("--model='lipm'", "--physics-log"),
    ),
    Case(
        "robot-unknown",
        ["run", *LIPM, "--robot", "atlas", "--out", "{out}"],
        ("robot='atlas'", "g1"),
    ),
    Case(
        "robot-unknown-pybullet", ["run", "--robot", "atlas", "--out", "{out}"], ("robot='atlas'",)
    ),
    Case("robot-empty", ["run", *LIPM, "--robot", "", "--out", "{out}"], ("robot=''",)),
    Case(
        "option-unknown",
        ["run", *LIPM, "--speed", "2", "--out", "{out}"],
        ("unrecognized arguments: --speed 2",),
    ),
    Case("no-command", [], ("COMMAND",)),
    Case("command-unknown", ["fly"], ("'fly'",)),
]


# ---------------------------------------------------------------- sweep and grid
def sweep_case(name: str, args: list[str], *expect: str) -> Case:
    argv = ["sweep", "--model", "lipm", "--quiet", *args, "--out", "{out}"]
    return Case(f"sweep-{name}", argv, tuple(expect))


def grid_case(name: str, args: list[str], *expect: str) -> Case:
    argv = ["grid", "--model", "lipm", "--quiet", *args, "--out", "{out}"]
    return Case(f"grid-{name}", argv, tuple(expect))


SWEEP_AND_GRID = [
    sweep_case("directions-0", ["--directions", "0"], "directions=0", "[1, 360]"),
    sweep_case("directions-negative", ["--directions", "-3"], "directions=-3"),
    sweep_case("directions-361", ["--directions", "361"], "directions=361"),
    sweep_case("directions-float", ["--directions", "1.5"], "--directions", "'1.5'"),
    sweep_case("directions-1e3", ["--directions", "1e3"], "--directions", "'1e3'"),
    sweep_case("phases-empty", ["--phases", ""], "--phases=''"),
    sweep_case("phases-one", ["--phases", "1"], "phases=(1.0,)", "[0, 1)"),
    sweep_case("phases-negative", ["--phases", "-0.1"], "phases=(-0.1,)"),
    sweep_case("phases-nan", ["--phases", "nan"], "--phases='nan'"),
    sweep_case("phases-twice", ["--phases", "0,0"], "phases=(0.0, 0.0)", "distinct"),
    sweep_case("phases-letters", ["--phases", "a,b"], "--phases='a,b'"),
    sweep_case("duration-zero", ["--duration", "0"], "duration=0.0", "[0.001, 1.0]"),
    sweep_case("duration-nan", ["--duration", "nan"], "--duration='nan'"),
    sweep_case("duration-2", ["--duration", "2"], "duration=2.0"),
    sweep_case("settle-short", ["--settle", "0.5"], "settle=0.5", "[1.0, 60.0]"),
    sweep_case("settle-long", ["--settle", "1e9"], "settle=1000000000.0"),
    sweep_case("tolerance-zero", ["--tolerance", "0"], "tolerance=0.0"),
    sweep_case("tolerance-inf", ["--tolerance", "inf"], "--tolerance='inf'"),
    sweep_case("cycle-zero", ["--cycle", "0"], "cycle=0", "[1, 20]"),
    sweep_case("cycle-21", ["--cycle", "21"], "cycle=21"),
    sweep_case("cycle-float", ["--cycle", "2.5"], "--cycle", "'2.5'"),
    sweep_case("controllers-empty", ["--controllers", ""], "controllers=''"),
    sweep_case("controllers-unknown", ["--controllers", "mpc"], "controllers='mpc'"),
    sweep_case("controllers-twice", ["--controllers", "rsg,rsg"], "controllers='rsg,rsg'"),
    sweep_case(
        "placo-wpg-on-lipm",
        ["--controllers", "placo-wpg"],
        "controllers='placo-wpg'",
        "--model pybullet",
    ),
    sweep_case(
        "workers-zero",
        ["--directions", "1", "--phases", "0", "--workers", "0"],
        "--workers=0",
        "an integer in [1,",
    ),
    sweep_case("workers-negative", ["--workers", "-2"], "--workers=-2"),
    sweep_case("workers-100000", ["--workers", "100000"], "--workers=100000"),
    sweep_case("workers-letters", ["--workers", "many"], "--workers", "'many'"),
    sweep_case("backend-unknown", ["--backend", "dask"], "--backend", "'dask'"),
    sweep_case("criterion-unknown", ["--criterion", "alive"], "--criterion", "'alive'"),
    sweep_case("robot-unknown", ["--robot", "atlas"], "robot='atlas'"),
    sweep_case("model-unknown", ["--model", "gazebo"], "--model", "'gazebo'"),
    grid_case("impulses-empty", ["--impulses", ""], "--impulses=''"),
    grid_case("impulses-zero", ["--impulses", "0"], "impulses=(0.0,)", "(0, 1000] N s"),
    grid_case("impulses-negative", ["--impulses", "-5"], "impulses=(-5.0,)"),
    grid_case("impulses-nan", ["--impulses", "nan"], "--impulses='nan'"),
    grid_case("impulses-1e308", ["--impulses", "1e308"], "impulses=(1e+308,)"),
    grid_case("impulses-twice", ["--impulses", "4,4"], "impulses=(4.0, 4.0)", "distinct"),
    grid_case(
        "impulses-101",
        ["--impulses", ",".join(str(i + 1) for i in range(101))],
        "impulses=",
        "1 to 100",
    ),
    grid_case("impulses-letters", ["--impulses", "4,x"], "--impulses='4,x'"),
    grid_case("directions-0", ["--directions", "0"], "directions=0"),
    grid_case("directions-1000", ["--directions", "1000"], "directions=1000"),
    grid_case("phases-1", ["--phases", "1"], "phases=(1.0,)"),
    grid_case("phases-negative", ["--phases", "-0.5"], "phases=(-0.5,)"),
    grid_case("duration-zero", ["--duration", "0"], "duration=0.0", "[0.001, 1] s"),
    grid_case("duration-5", ["--duration", "5"], "duration=5.0"),
    grid_case("settle-0.5", ["--settle", "0.5"], "settle=0.5", "[1, 60] s"),
    grid_case("settle-inf", ["--settle", "inf"], "--settle='inf'"),
    grid_case("controllers-unknown", ["--controllers", "mpc"], "controllers='mpc'"),
    grid_case("controllers-empty", ["--controllers", ","], "controllers=''"),
    grid_case(
        "workers-zero", ["--impulses", "5", "--directions", "1", "--workers", "0"], "--workers=0"
    ),
    grid_case("workers-100000", ["--workers", "100000"], "--workers=100000"),
    grid_case("robot-unknown", ["--robot", "atlas"], "robot='atlas'"),
]


# ------------------------------------------------------------------------- bench
def bench_case(name: str, args: list[str], *expect: str) -> Case:
    return Case(f"bench-{name}", ["bench", *args, "--out", "{out}"], tuple(expect))


BENCH = [
    bench_case("duration-zero", ["--duration", "0"], "--duration=0.0", "[0.05, 600]"),
    bench_case("duration-nan", ["--duration", "nan"], "--duration='nan'"),
    bench_case("duration-601", ["--duration", "601"], "--duration=601.0"),
    bench_case("duration-letters", ["--duration", "long"], "--duration='long'"),
    bench_case("samples-zero", ["--samples", "0"], "--samples=0", "[10, 1000000]"),
    bench_case("samples-9", ["--samples", "9"], "--samples=9"),
    bench_case("samples-huge", ["--samples", "10000000"], "--samples=10000000"),
    bench_case("samples-float", ["--samples", "1e3"], "--samples", "'1e3'"),
    bench_case("robot-unknown", ["--robot", "atlas"], "robot='atlas'"),
    bench_case("model-unknown", ["--model", "pybullet,gazebo"], "--model='pybullet,gazebo'"),
    bench_case("model-lipm", ["--model", "lipm"], "--model='lipm'", "pybullet, mujoco"),
    bench_case("model-twice", ["--model", "mujoco,mujoco"], "--model='mujoco,mujoco'"),
    bench_case(
        "set-with-no-robot",
        ["--no-robot", "--set", "landing_depth=0.004"],
        "--set='landing_depth=0.004'",
        "--no-robot",
    ),
    bench_case(
        "set-out-of-range",
        ["--set", "landing_depth=5"],
        "--set landing_depth",
        "[0, 0.02]",
    ),
    bench_case("set-unknown", ["--set", "bogus=1"], "--set='bogus'"),
]


# ------------------------------------------------------------ sweep resume files
def _resume(spec: str | bytes | None, jobs: str | bytes | None) -> Callable[[Path], None]:
    """A sweep folder with these ``sweep_spec.json`` and ``jobs.jsonl`` contents (a
    folder of that name for ``b"<dir>"``)."""

    def setup(tmp: Path) -> None:
        out = tmp / "out"
        out.mkdir()
        for name, content in ((SPEC_FILE, spec), ("jobs.jsonl", jobs)):
            if content == b"<dir>":
                (out / name).mkdir()
            elif content is not None:
                data = content.encode() if isinstance(content, str) else content
                (out / name).write_bytes(data)

    return setup


TINY_ARGS = ["--controllers", "no-step", "--directions", "1", "--phases", "0"]
TINY_SPEC = SweepSpec(controllers=("no-step",), directions=1, phases=(0.0,))


def _spec_json(**change: object) -> str:
    from dataclasses import asdict

    return json.dumps({**asdict(TINY_SPEC), **change})


def _record(angle: float = 0.0, phase: float = 0.0, controller: str = "no-step") -> dict:
    """A well-formed job record (the fields a resumed sweep reads)."""
    return {
        "key": Job(controller, angle, phase).key, "controller": controller,
        "direction_deg": math.degrees(angle), "phase": phase, "push_time": 2.3,
        "stance": "right", "impulse": 10.0, "failed_at": 10.5, "capped": False,
        "bound": 20.0, "ratio": 0.5, "runs": 6, "evaluations": [], "wall_time": 1.0,
    }  # fmt: skip


GOOD_LINE = json.dumps(_record()) + "\n"


def resume_case(name: str, spec: str | bytes | None, jobs: str | bytes | None,
                *expect: str) -> Case:  # fmt: skip
    argv = ["sweep", "--model", "lipm", "--quiet", *TINY_ARGS, "--out", "{tmp}/out"]
    return Case(f"resume-{name}", argv, tuple(expect), setup=_resume(spec, jobs))


RESUME_FILES = [
    resume_case(
        "spec-not-json",
        "not json",
        None,
        "sweep_spec.json: is not a sweep spec",
        "JSONDecodeError",
        "--overwrite",
    ),
    resume_case("spec-list", "[1, 2]", None, "sweep_spec.json: is not a sweep specification"),
    resume_case("spec-number", "5", None, "sweep_spec.json: is not a sweep specification"),
    resume_case("spec-empty-object", "{}", None, "sweep_spec.json: is not a sweep spec"),
    resume_case(
        "spec-foreign",
        '{"name": "my experiment", "model": "lipm"}',
        None,
        "other fields",
        "--overwrite",
    ),
    resume_case(
        "spec-latin1", '{"model": "l\xefpm"}'.encode("latin-1"), None, "UnicodeDecodeError"
    ),
    resume_case("spec-utf16", _spec_json().encode("utf-16"), None, "UnicodeDecodeError"),
    resume_case("spec-empty-file", "", None, "JSONDecodeError"),
    resume_case("spec-nested", "[" * 100_000 + "]" * 100_000, None, "RecursionError"),
    resume_case(
        "spec-directory", b"<dir>", None, "sweep_spec.json: exists and is not a file", "remove it"
    ),
    resume_case(
        "spec-other-tolerance",
        _spec_json(tolerance=1.0),
        None,
        "(tolerance)=0.25",
        "(1.0)",
        "--overwrite",
    ),
    resume_case("spec-other-model", _spec_json(model="pybullet"), None, "(model)='lipm'"),
    resume_case("jobs-without-spec", None, GOOD_LINE, "jobs.jsonl: has no sweep_spec.json"),
    resume_case(
        "jobs-number", _spec_json(), "5\n", "line 1 is not a job record", "JSON int", "--overwrite"
    ),
    resume_case("jobs-empty-object", _spec_json(), "{}\n", "line 1", "field key missing"),
    resume_case("jobs-list", _spec_json(), "[]\n", "line 1", "JSON list"),
    resume_case("jobs-string", _spec_json(), '"done"\n', "line 1", "JSON str"),
    resume_case(
        "jobs-missing-field",
        _spec_json(),
        json.dumps({k: v for k, v in _record().items() if k != "impulse"}) + "\n",
        "line 1",
        "field impulse missing",
    ),
    resume_case(
        "jobs-wrong-type",
        _spec_json(),
        json.dumps({**_record(), "impulse": "10"}) + "\n",
        "line 1",
        "field impulse",
    ),
    resume_case(
        "jobs-bool-as-number",
        _spec_json(),
        json.dumps({**_record(), "runs": True}) + "\n",
        "line 1",
        "field runs",
    ),
    resume_case(
        "jobs-key-mismatch",
        _spec_json(),
        json.dumps({**_record(), "phase": 0.5}) + "\n",
        "line 1",
        "does not match its fields",
    ),
    resume_case(
        "jobs-corrupt-middle",
        _spec_json(),
        GOOD_LINE + "{half\n" + GOOD_LINE,
        "line 2 is not a job record",
    ),
    resume_case(
        "jobs-latin1-line", _spec_json(), b'{"key": "\xe9"}\n', "line 1", "UnicodeDecodeError"
    ),
    resume_case(
        "jobs-directory",
        _spec_json(),
        b"<dir>",
        "jobs.jsonl: exists and is not a file",
        "remove it",
    ),
    resume_case(
        "jobs-nested",
        _spec_json(),
        "[" * 100_000 + "]" * 100_000 + "\n",
        "line 1",
        "RecursionError",
    ),
]


def _check_half_line_dropped(code: int, out: str, err: str, tmp: Path) -> None:
    """A half-written last line is dropped (noted on stderr), the finished job kept, and
    the file repaired: one record, ending with a newline."""
    assert code == 0, err
    assert "dropped its unfinished last line" in err
    lines = (tmp / "out" / "jobs.jsonl").read_text().splitlines()
    assert [json.loads(line)["impulse"] for line in lines] == [10.0]
    envelope = json.loads((tmp / "out" / "envelope.json").read_text())
    assert envelope["controllers"]["no-step"]["mean_impulse"] == 10.0


def _check_overwrite(code: int, out: str, err: str, tmp: Path) -> None:
    """--overwrite deletes the earlier results first; the new ones stand alone."""
    assert code in (0, 1), err
    assert "deleted" in out and "summary.json" in out
    summary = json.loads((tmp / "out" / "summary.json").read_text())
    assert summary["sim_time"] == pytest.approx(0.2)
    assert not (tmp / "out" / "grid.json").exists()


def _check_summary(**expected: object) -> Callable[[int, str, str, Path], None]:
    def check(code: int, out: str, err: str, tmp: Path) -> None:
        assert code in (0, 1), err
        summary = json.loads((tmp / "out" / "summary.json").read_text())
        for key, value in expected.items():
            assert summary[key] == value, (key, summary[key])

    return check


def _check_parameter(name: str, value: object) -> Callable[[int, str, str, Path], None]:
    def check(code: int, out: str, err: str, tmp: Path) -> None:
        assert code in (0, 1), err
        summary = json.loads((tmp / "out" / "summary.json").read_text())
        assert summary["parameters"][name] == value

    return check


def _check_pushes_applied(count: int) -> Callable[[int, str, str, Path], None]:
    def check(code: int, out: str, err: str, tmp: Path) -> None:
        assert code in (0, 1), err
        summary = json.loads((tmp / "out" / "summary.json").read_text())
        assert len(summary["pushes"]) == count and summary["pushes_not_applied"] == []

    return check


def _grid_and_summary(tmp: Path) -> None:
    _results_of_another_run(tmp)
    (tmp / "out" / "grid.json").write_text("{}\n")


GRID_MORE_WORKERS_THAN_JOBS = [
    "grid", "--model", "lipm", "--quiet", "--no-plots", "--controllers", "no-step", "--impulses",
    "5", "--directions", "1", "--settle", "1", "--workers", "8", "--out", "{tmp}/out",
]  # fmt: skip


def _accept_push(name: str, push: str) -> Case:
    """``--push`` accepted: the run applies it."""
    argv = [*RUN, "--push", push, "--out", "{tmp}/out"]
    return Case(name, argv, None, check=_check_pushes_applied(1))


ACCEPTED = [
    Case(
        "accept-resume-half-written-last-line",
        ["sweep", "--model", "lipm", "--quiet", *TINY_ARGS, "--out", "{tmp}/out"],
        None,
        setup=_resume(_spec_json(), GOOD_LINE + '{"key": "no-step|0.0000|0.0'),
        check=_check_half_line_dropped,
    ),  # fmt: skip
    Case(
        "accept-overwrite",
        [*RUN, "--out", "{tmp}/out", "--overwrite"],
        None,
        setup=_grid_and_summary,
        check=_check_overwrite,
    ),
    Case(
        "accept-dcm-inset-none-on-paper-lipm",
        [*RUN, "--set", "dcm_inset=none", "--out", "{tmp}/out"],
        None,
        check=_check_parameter("dcm_inset", None),
    ),
    Case(
        "accept-utf8-bom",
        ["run", *LIPM, "--scenario", "{file}", "--out", "{tmp}/out"],
        None,
        "\ufeffduration = 0.2\n".encode(),
        check=_check_summary(sim_time=0.2),
    ),
    Case(
        "accept-empty-push-array",
        ["run", *LIPM, "--scenario", "{file}", "--out", "{tmp}/out"],
        None,
        b"duration = 0.2\npush = []\n",
        check=_check_pushes_applied(0),
    ),  # fmt: skip
    _accept_push("accept-push-shorter-than-a-tick", "0.1:5,0:5e-324"),
    _accept_push("accept-push-ending-with-the-run", "0.1:5,0:0.1"),
    _accept_push("accept-spaces-in-push", " 0.1 : 5 , 0 "),
    Case(
        "accept-workers-above-the-job-count",
        GRID_MORE_WORKERS_THAN_JOBS,
        None,
        check=lambda code, out, err, tmp: None if code == 0 else pytest.fail(err),
    ),
]

CASES = [
    *SCENARIO_FILES, *PUSH_ARGUMENTS, *DURATIONS, *OVERRIDES, *OUT_FOLDERS, *RUN_MISC,
    *SWEEP_AND_GRID, *BENCH, *RESUME_FILES, *ACCEPTED,
]  # fmt: skip


def test_the_corpus_is_large_and_its_names_unique() -> None:
    names = [case.name for case in CASES]
    assert len(names) == len(set(names)), [n for n in names if names.count(n) > 1]
    refusals = [case for case in CASES if case.expect is not None]
    assert len(refusals) >= 300, len(refusals)


def _fill(text: str, tmp: Path, file: Path) -> str:
    return (
        text.replace("{out}", str(tmp / "out"))
        .replace("{tmp}", str(tmp))
        .replace("{file}", str(file))
    )


@pytest.mark.parametrize("case", CASES, ids=[case.name for case in CASES])
def test_hostile_input(case: Case, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    file = tmp_path / case.file_name
    if case.content is not None:
        file.write_bytes(case.content)
    if case.setup is not None:
        case.setup(tmp_path)
    before = sorted(p.name for p in tmp_path.rglob("*"))
    argv = [_fill(arg, tmp_path, file) for arg in case.argv]
    try:
        code = main(argv)
    except SystemExit as exit_:  # argparse
        code = exit_.code  # type: ignore[assignment]
    out, err = capsys.readouterr()
    assert "Traceback" not in err + out
    if case.expect is None:
        assert case.check is not None
        case.check(code, out, err, tmp_path)
        return
    lines = [line for line in err.splitlines() if line.strip()]
    assert code == 2, f"{case.name}: exit {code}\n{out}\n{err}"
    assert 1 <= len(lines) <= 2, err
    for fragment in case.expect:
        assert fragment in err, f"{case.name}: {fragment!r} not in {err!r}"
    # Nothing written: no new file, and no result in the out folder.
    after = sorted(p.name for p in tmp_path.rglob("*"))
    written = set(after) - set(before)
    results = {name for names in RESULT_FILES.values() for name in names}
    assert not (written & results), written


# ---------------------------------------------------------- ranges of parameters
@pytest.mark.parametrize(
    "name", sorted(n for n, k in rsg_parameter_types("lipm").items() if k != "bool")
)
def test_every_rsg_parameter_runs_at_both_ends_of_its_range(name: str, tmp_path: Path) -> None:
    """At each end of its range (just inside an open end) a parameter builds a planner
    that runs 0.3 s on the LIPM without an exception or a RuntimeWarning, or is refused
    by a rule between parameters that names it."""
    from planner.parameters import RANGES

    valid = RANGES[name]
    low = valid.low if not valid.low_open else valid.low + 1e-6 * (valid.high - valid.low)
    for value in (low, valid.high):
        out = tmp_path / f"{value:g}"
        argv = [*RUN, "--set", f"{name}={value!r}", "--out", str(out)]
        try:
            code = main(argv)
        except SystemExit as exit_:
            code = exit_.code  # type: ignore[assignment]
        if code == 2:
            assert not out.exists()
        else:
            assert code in (0, 1)
            summary = json.loads((out / "summary.json").read_text())
            assert summary["sim_time"] == pytest.approx(0.2)
