"""``--set NAME=VALUE``: parsing, where each name applies, its effect, errors."""

from __future__ import annotations

import argparse
import dataclasses
import json
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.commands.arguments import parse_assignment
from app.experiments.grid import GridSpec, run_grid
from app.experiments.jobs import JobRun
from app.experiments.sweep import SweepSpec, run_sweep
from app.runner import run_closed_loop
from app.scenarios import Scenario
from app.setup.build import build_backend, build_robot_backend, robot_with_overrides
from app.setup.overrides import allowed_names, parse_overrides, parse_value
from app.stabilizer.config import OPTION_NAMES
from planner.exceptions import ParameterError
from planner.types import Push
from robots import get_robot


def test_values_are_parsed_by_the_kind_of_the_parameter() -> None:
    assert parse_value("x", "0.3", "float") == 0.3
    assert parse_value("x", "0,2", "float | tuple[float, float]") == (0.0, 2.0)
    assert parse_value("x", "2", "float | tuple[float, float]") == 2.0
    assert parse_value("x", "none", "float | None") is None
    assert parse_value("x", "True", "bool") is True
    assert parse_value("x", "off", "bool") is False
    assert parse_value("x", "feedback", "str") == "feedback"
    assert parse_value("x", "30", "int") == 30
    assert parse_value("x", "a_joint, b_joint", "names") == ("a_joint", "b_joint")
    assert parse_value("x", "None", "names") == ()
    for text, kind in [
        ("a_joint,,b_joint", "names"),
        ("a", "float"),
        ("1,2", "float"),
        ("nan", "float"),
        ("maybe", "bool"),
        ("2.5", "int"),
    ]:
        with pytest.raises(ParameterError) as error:
            parse_value("x", text, kind)
        assert error.value.field == "--set x"
        assert error.value.value == text


def test_assignments_need_a_name_and_a_value() -> None:
    assert parse_assignment(" landing_depth = 0.003 ") == ("landing_depth", "0.003")
    for text in ("landing_depth", "=0.003", "landing_depth="):
        with pytest.raises(argparse.ArgumentTypeError):
            parse_assignment(text)


def test_each_name_goes_where_it_applies() -> None:
    parsed = parse_overrides(
        (
            ("swing_preparation_time", "0.3"),
            ("landing_depth", "0.003"),
            ("control_period", "0.004"),
            ("crossing_margin", "0.03"),
        )
    )
    assert parsed.description == {"swing_preparation_time": 0.3}
    assert parsed.backend == {
        "landing_depth": 0.003,
        "control_period": 0.004,
    }
    assert parsed.rsg == {"crossing_margin": 0.03}
    # Every stabilizer option may be set on the full robot.
    assert set(OPTION_NAMES) <= set(allowed_names("pybullet"))
    # On the LIPM only RSG parameters exist, all of them.
    lipm = parse_overrides((("swing_preparation_time", "0.3"),), "lipm")
    assert lipm.rsg == {"swing_preparation_time": 0.3}
    assert "landing_depth" not in allowed_names("lipm")


@pytest.mark.parametrize(
    ("overrides", "model", "field"),
    [
        ((("no_such_parameter", "1"),), "pybullet", "--set"),
        ((("landing_depth", "0.004"),), "lipm", "--set landing_depth"),  # PyBullet
        ((("step_width", "0.3"),), "lipm", "--set"),  # the paper's LIPM: RSG parameters
        ((("crossing_margin", "0.03"), ("crossing_margin", "0.04")), "lipm",
         "--set crossing_margin"),
        ((("friction", "1,2,3"),), "pybullet", "--set friction"),
    ],
)  # fmt: skip
def test_bad_overrides_name_the_parameter(overrides: tuple, model: str, field: str) -> None:
    with pytest.raises(ParameterError) as error:
        parse_overrides(overrides, model)
    assert error.value.field == field
    if field == "--set":
        assert "crossing_margin" in error.value.allowed  # the allowed names are listed


def test_a_robot_description_takes_fields_and_backend_options() -> None:
    tuned = dataclasses.replace(get_robot("g1"), backend_options={"landing_depth": 0.004})
    description, _ = robot_with_overrides(
        tuned, (("swing_preparation_time", "0.3"), ("landing_depth", "0.004"))
    )
    assert description.swing_preparation_time == 0.3
    assert description.backend_options["landing_depth"] == 0.004
    # The description's own options are kept.
    assert description.backend_options["landing_depth"] == 0.004
    with pytest.raises(ParameterError) as error:
        robot_with_overrides("g1", (("com_height", "5"),))
    assert error.value.field == "com_height"  # the description's own range check


def test_the_robot_backend_and_planner_receive_the_overrides() -> None:
    backend, config, _ = build_robot_backend(
        "g1",
        "rsg",
        (
            ("swing_preparation_time", "0.3"),
            ("landing_depth", "0.004"),
            ("control_period", "0.004"),
            ("crossing_margin", "0.03"),
        ),
    )
    try:
        stabilizer = backend.controller.config
        assert stabilizer.landing_depth == 0.004
        assert backend.controller.landing.depth == 0.004
        assert backend.control_period == 0.004 == backend.controller.period
        assert config.rsg.swing_preparation_time == 0.3
        assert backend.timing.ready == 0.3  # the swing foot is timed on the same T_SP
        assert config.rsg.crossing_margin == 0.03
    finally:
        backend.close()


def test_a_later_earliest_step_keeps_steps_apart_on_the_lipm() -> None:
    """T_SP bounds how soon after a step the next may come: T_DSP + T_SP (jump set D_T)."""
    scenario = Scenario("forward", 6.0, (Push(2.4, np.array([40.0, 0.0]), 0.1),))

    def step_intervals(overrides: tuple) -> np.ndarray:
        backend, config, initial = build_backend("lipm", None, "rsg", overrides=overrides)
        result = run_closed_loop(backend, config, scenario, initial)
        assert result.recovered
        return np.diff([step.event["t"] for step in result.steps])

    default = step_intervals(())
    slow = step_intervals((("swing_preparation_time", "0.5"),))
    assert default.min() == pytest.approx(0.1 + 0.2)  # the early step: T_DSP + T_SP
    assert slow.min() == pytest.approx(0.1 + 0.5)


def test_paper_rules_then_set(tmp_path: Path) -> None:
    _, config, _ = build_backend("lipm", None, "rsg", paper=True)
    assert config.rsg.step_reaction_time == 0.0
    _, config, _ = build_backend(
        "lipm", None, "rsg", paper=True, overrides=(("step_reaction_time", "0.1"),)
    )
    assert config.rsg.step_reaction_time == 0.1  # --set wins over --paper-rules


def test_the_run_command_records_the_overrides(tmp_path: Path, capsys) -> None:
    code = main(
        ["run", "--model", "lipm", "--scenario", "walk", "--duration", "2", "--no-plots",
         "--quiet", "--set", "crossing_margin=0.03", "--out", str(tmp_path)]
    )  # fmt: skip
    assert code in (0, 1)
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["overrides"] == {"crossing_margin": "0.03"}
    assert "--set crossing_margin=0.03" in capsys.readouterr().out


def test_a_bad_override_is_a_clear_error_before_any_run(tmp_path: Path, capsys) -> None:
    code = main(["grid", "--model", "lipm", "--set", "landing_depth=0.004", "--out", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err
    assert "--set landing_depth" in err and "only with --model pybullet" in err
    assert not (tmp_path / "grid.json").exists()
    with pytest.raises(ParameterError):
        GridSpec(overrides=(("swing_preparation_time", "soon"),))


def test_a_resumed_sweep_must_have_the_same_overrides(tmp_path: Path) -> None:
    spec = SweepSpec(
        controllers=("no-step",), directions=1, phases=(0.0,), tolerance=5.0,
        overrides=(("crossing_margin", "0.05"),),
    )  # fmt: skip
    run_sweep(spec, JobRun(tmp_path, workers=1, progress=False))
    run_sweep(spec, JobRun(tmp_path, workers=1, progress=False))  # resumes: nothing left to do
    other = SweepSpec(**{**spec.__dict__, "overrides": (("crossing_margin", "0.04"),)})
    with pytest.raises(ParameterError) as error:
        run_sweep(other, JobRun(tmp_path, workers=1, progress=False))
    assert "overrides" in error.value.field
    assert error.value.value == (("crossing_margin", "0.04"),)  # what was given
    assert "0.05" in error.value.allowed  # what the folder holds


def test_a_bad_override_is_caught_before_any_worker_or_folder(tmp_path: Path, capsys):
    """An RSG parameter out of its range, or breaking a rule between parameters, is
    found before the workers start and before --out is made (exit 2, the --set named
    with its value and what is allowed: mu_2 in (0, 0.5] m; with mu_2 = 0.3 the nominal
    step width 0.2 m is below 2 w_y + mu_2 = 0.14 + 0.3 m)."""
    for value, expected in [
        ("5", "--set crossing_margin='5' is not allowed: expected a number in (0, 0.5] m"),
        ("0.3", "step_width=0.2 to be >= 2 w_y + crossing_margin = 0.440 m"),
    ]:
        out = tmp_path / value
        code = main(
            ["grid", "--model", "lipm", "--controllers", "rsg", "--impulses", "20",
             "--directions", "2", "--workers", "2", "--set", f"crossing_margin={value}",
             "--out", str(out)]
        )  # fmt: skip
        assert code == 2
        err = capsys.readouterr().err
        assert expected in err and "--set crossing_margin" in err
        assert "Traceback" not in err
        assert not out.exists()


def test_a_robot_on_the_lipm_is_its_planner_on_the_point_mass() -> None:
    """``--model lipm --robot g1``: G1's mass, pendulum, ZMP window and timing, with its
    description fields settable and its backend options not."""
    from robots import get_robot

    g1 = get_robot("g1")
    backend, config, _ = build_backend(
        "lipm", "g1", "rsg", overrides=(("swing_preparation_time", "0.3"),)
    )
    assert backend.name == "lipm"
    assert config.model.mass == pytest.approx(g1.total_mass)
    assert config.model.com_height == pytest.approx(g1.com_height + g1.rotational_height)
    assert config.rsg.swing_preparation_time == pytest.approx(0.3)
    assert config.constraints.zmp_window_max[1] < g1.sole.half_width
    _, paper, _ = build_backend("lipm", None, "rsg")
    assert paper.model.mass != pytest.approx(g1.total_mass)
    with pytest.raises(ParameterError) as error:
        build_backend("lipm", "g1", "rsg", overrides=(("landing_depth", "0.004"),))
    assert error.value.field == "--set landing_depth"
    assert "only with --model pybullet" in error.value.allowed
    with pytest.raises(ParameterError) as error:
        build_backend("lipm", "g1", "rsg", overrides=(("no_such_name", "0.2"),))
    assert "swing_preparation_time" in error.value.allowed
    assert "landing_depth" not in error.value.allowed
    assert "swing_preparation_time" in allowed_names("lipm", "g1")
    assert (
        "swing_preparation_time"
        not in parse_overrides((("swing_preparation_time", "0.3"),), "lipm").description
    )


def test_g1_steps_too_late_for_a_push_towards_its_stance_side_at_its_own_t_sp() -> None:
    """The planner alone (G1's limits, a perfect point mass): 12 N s at mid single
    support towards the stance side is lost with T_SP = 0.5 s, recovered with
    0.3 s (the next step can come 0.2 s earlier); forward it is recovered with both.
    (10 N s is recovered with both since G1's outward step may be 0.55 m.)"""
    outcomes = {}
    for t_sp in ("0.5", "0.3"):
        spec = GridSpec(
            model="lipm",
            robot="g1",
            controllers=("rsg",),
            impulses=(12.0,),
            directions=4,
            overrides=(("swing_preparation_time", t_sp),),
        )
        records = run_grid(spec, workers=1, progress=False)
        outcomes[t_sp] = {r["direction_deg"]: r["outcome"] for r in records}
        assert all(r["stance"] == "right" for r in records)
    assert outcomes["0.5"][0.0] == outcomes["0.3"][0.0] == "recovered"
    assert outcomes["0.5"][270.0] == "fell"
    assert outcomes["0.3"][270.0] == "recovered"


def test_the_reanchor_time_of_a_robot_reaches_its_planner() -> None:
    """G1's description sets the planner's reanchor_time; --set changes it on the robot's
    planner (here on the point mass), and a value out of range names the field."""
    _, config, _ = build_backend("lipm", "g1", "rsg")
    assert config.rsg.reanchor_time == get_robot("g1").reanchor_time > 0.0
    _, config, _ = build_backend("lipm", "g1", "rsg", overrides=(("reanchor_time", "0.05"),))
    assert config.rsg.reanchor_time == 0.05
    with pytest.raises(ParameterError) as error:
        build_backend("lipm", "g1", "rsg", overrides=(("reanchor_time", "2"),))
    assert error.value.field == "--set reanchor_time"
    assert error.value.allowed == "a number in [0, 1] s"


def test_the_touchdown_window_of_g1_reaches_its_planner() -> None:
    """G1's description sets the planner's touchdown_window (Talos keeps it off); on the
    point mass, which reports no swing contact, --set touchdown_window is refused."""
    _, config, _ = build_backend("lipm", "g1", "rsg")
    assert config.rsg.touchdown_window == get_robot("g1").touchdown_window == 0.1
    assert get_robot("talos").touchdown_window == 0.0
    with pytest.raises(ParameterError) as error:
        build_backend("lipm", "g1", "rsg", overrides=(("touchdown_window", "0.05"),))
    assert error.value.field == "--set touchdown_window"


def test_the_solver_iterations_reach_pybullet() -> None:
    """``--set solver_iterations=N`` sets PyBullet's contact and motor solver; a value
    out of range names the field before any run."""
    from app.backends.pybullet_robot import SimulatedRobot

    description, _ = robot_with_overrides("g1", (("solver_iterations", "30"),), "pybullet")
    robot = SimulatedRobot(description)
    try:
        parameters = robot.client.getPhysicsEngineParameters()
        assert parameters["numSolverIterations"] == 30
    finally:
        robot.close()
    assert get_robot("g1").solver_iterations == 75
    with pytest.raises(ParameterError) as error:
        robot_with_overrides("g1", (("solver_iterations", "0"),), "pybullet")
    assert error.value.field == "solver_iterations"


def test_the_physics_time_step_reaches_pybullet_and_the_backend() -> None:
    """``--set physics_time_step=0.001`` runs G1's physics at 1 kHz instead of 500 Hz:
    PyBullet's fixed step, the simulated time per step and the motors' stable PD
    step (:mod:`app.backends.joint_motors`) follow. A step that does not divide the control
    period is an error naming it before any run."""
    from app.backends.pybullet_robot import SimulatedRobot

    g1 = get_robot("g1")
    for text, step in (("0.001", 0.001), (None, g1.physics_time_step)):
        overrides = () if text is None else (("physics_time_step", text),)
        description, _ = robot_with_overrides("g1", overrides, "pybullet")
        assert description.physics_time_step == step
        robot = SimulatedRobot(description)
        try:
            assert robot.client.getPhysicsEngineParameters()["fixedTimeStep"] == step
            robot.step()
            robot.step()
            assert robot.time == pytest.approx(2 * step)
        finally:
            robot.close()
        backend, config, initial = build_robot_backend("g1", "rsg", overrides=overrides)
        try:
            assert backend.sim.time_step == step
            result = run_closed_loop(backend, config, Scenario("walk", 0.1), initial)
            assert not result.fall.fell
            assert backend.sim.time == pytest.approx(0.1)  # ticks x substeps x step
        finally:
            backend.close()
    with pytest.raises(ParameterError) as error:
        build_robot_backend("g1", "rsg", overrides=(("physics_time_step", "0.003"),))
    assert error.value.field == "--set physics_time_step"
    assert error.value.value == "0.003"
    assert "control_period/physics_time_step=(0.01, 0.003)" in error.value.allowed
    with pytest.raises(ParameterError) as error:
        robot_with_overrides("g1", (("physics_time_step", "0.01"),), "pybullet")
    assert error.value.field == "physics_time_step"


def test_the_dcm_inset_of_a_robot_reaches_its_planner() -> None:
    """G1's description sets row (27c'); --set dcm_inset=none removes it."""
    _, config, _ = build_backend("lipm", "g1", "rsg")
    assert config.rsg.dcm_inset == get_robot("g1").dcm_inset == 0.02
    _, config, _ = build_backend("lipm", "g1", "rsg", overrides=(("dcm_inset", "none"),))
    assert config.rsg.dcm_inset is None
    with pytest.raises(ParameterError) as error:
        build_backend("lipm", "g1", "rsg", overrides=(("dcm_inset", "0.5"),))
    assert error.value.field == "--set dcm_inset"


def test_locked_joints_are_welded_in_pybullet_and_set_unlocks_them() -> None:
    """G1's locked arm joints are not PyBullet joints (no motor, no degree of freedom);
    ``--set locked_joints=none`` actuates all 29, and a name that is not a joint of the
    URDF is an error naming the field."""
    from app.backends.pybullet_robot import SimulatedRobot

    g1 = get_robot("g1")
    for overrides, count in (((), 29 - len(g1.locked_joints)), ((("locked_joints", "none"),), 29)):
        description, _ = robot_with_overrides("g1", overrides, "pybullet")
        robot = SimulatedRobot(description)
        try:
            assert len(robot.joint_names) == count
            assert set(robot.joint_names).isdisjoint(description.locked_joints)
            assert robot.mass == pytest.approx(g1.total_mass, abs=0.1)
        finally:
            robot.close()
    description, _ = robot_with_overrides("g1", (("locked_joints", "no_such_joint"),))
    with pytest.raises(ParameterError) as error:
        SimulatedRobot(description)
    assert error.value.field == "locked_joints"
