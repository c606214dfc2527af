"""Bad input is refused with a message naming the field; rsg run writes its files."""

import json
import pickle
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.results.folder import ResultFolderError
from app.results.replay import ReplayError
from app.scenarios import load_scenario, parse_push
from app.stabilizer.wrench_distribution import WrenchDistributionError
from kinematics.whole_body_ik import IkInfeasibleError
from planner.exceptions import ParameterError, StepQpError
from planner.parameters import Constraints, GaitParameters, LipmModel, PlannerConfig, RsgParameters

ROOT = Path(__file__).resolve().parents[1]


@pytest.mark.parametrize(
    "build,field",
    [
        (lambda: LipmModel(mass=-1.0), "mass"),
        (lambda: LipmModel(com_height=float("nan")), "com_height"),
        (lambda: GaitParameters(double_support_duration=0.0), "double_support_duration"),
        (lambda: RsgParameters(lyapunov_threshold=0.0), "lyapunov_threshold"),
        (lambda: Constraints(zmp_window_min=(-0.05, -0.02), zmp_window_max=(0.1, 0.03)), "y"),
        (lambda: PlannerConfig(controller="magic"), "controller"),
        (lambda: PlannerConfig(gait=GaitParameters(step_width=0.1)), "step_width"),
    ],
)
def test_bad_parameters_name_the_field(build, field):
    with pytest.raises(ParameterError) as info:
        build()
    assert field in str(info.value)
    assert "expected" in str(info.value)


@pytest.mark.parametrize(
    "text",
    [
        "",
        "3.8",
        "abc:1,2",
        "3.8:1",
        "3.8:1,2,3",
        "3.8:1,2:0",
        "3.8:1,2:-1",
        "-1:1,2",
        "3.8:nan,2",
        "3.8:1e9,0",
        "1:2:3:4",
    ],
)
def test_bad_push_strings_are_refused(text):
    with pytest.raises(ParameterError) as info:
        parse_push(text)
    assert "--push" in str(info.value)


def test_good_push_string():
    push = parse_push("3.8:8,-6:0.2")
    assert push.time == 3.8 and list(push.impulse) == [8.0, -6.0] and push.duration == 0.2
    assert parse_push("1:0,5").duration == 0.1


def test_cli_bad_push_exits_2_with_a_message(capsys):
    with pytest.raises(SystemExit) as info:
        main(["run", "--model", "lipm", "--push", "oops", "--out", "/nonexistent/x"])
    assert info.value.code == 2
    assert "--push" in capsys.readouterr().err


def test_cli_unknown_scenario_exits_2(capsys, tmp_path):
    code = main(["run", "--model", "lipm", "--scenario", "nope", "--out", str(tmp_path)])
    assert code == 2
    err = capsys.readouterr().err
    assert "--scenario" in err and "paper-fig6" in err and "Traceback" not in err


def test_scenario_toml(tmp_path):
    path = tmp_path / "side.toml"
    path.write_text('name = "side"\nduration = 5.0\n[[push]]\nt = 2.0\nimpulse = [0.0, 9.0]\n')
    scenario = load_scenario(str(path))
    assert scenario.name == "side" and scenario.duration == 5.0
    assert scenario.pushes[0].duration == 0.1
    path.write_text("duration = 5.0\n[[push]]\nt = 2.0\nimpulse = [0.0]\n")
    with pytest.raises(ParameterError, match="impulse"):
        load_scenario(str(path))
    path.write_text('duration = 5.0\ncolour = "red"\n')
    with pytest.raises(ParameterError, match="colour"):
        load_scenario(str(path))


def test_rsg_run_writes_summary_timeseries_and_plots(tmp_path):
    out = tmp_path / "fig6"
    completed = subprocess.run(
        [
            sys.executable,
            "-m",
            "app",
            "run",
            "--model",
            "lipm",
            "--scenario",
            "paper-fig6",
            "--push",
            "9:0,5",
            "--out",
            str(out),
        ],
        cwd=ROOT,
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert completed.returncode == 0, completed.stderr
    assert "RECOVERED" in completed.stdout and str(out) in completed.stdout
    summary = json.loads((out / "summary.json").read_text())
    for key in (
        "recovered",
        "fell",
        "model",
        "controller",
        "scenario",
        "mass",
        "com_height",
        "gamma_v",
        "final_lyapunov",
        "max_lyapunov",
        "pushes",
        "steps",
        "qp_infeasible",
        "constraint_violations",
        "sim_time",
        "wall_time",
        "real_time_factor",
    ):
        assert key in summary, key
    assert summary["recovered"] is True and summary["model"] == "lipm"
    assert [p["t"] for p in summary["pushes"]] == [3.8, 6.8, 9.0]
    assert set(summary["steps"][0]) >= {"t", "foot", "position", "adjusted"}
    header = (out / "timeseries.csv").read_text().splitlines()[0].split(",")
    for column in (
        "t",
        "com_x",
        "com_y",
        "com_vx",
        "com_vy",
        "zmp_x",
        "zmp_y",
        "hdot_x",
        "hdot_y",
        "foot_x",
        "foot_y",
        "dcm_error_x",
        "dcm_error_y",
        "lyapunov",
        "time_since_step",
        "push_fx",
        "push_fy",
    ):
        assert column in header, column
    for name in ("fig6a_top_view.png", "fig6b_time_since_step.png", "fig6c_dcm_error.png"):
        assert (out / name).stat().st_size > 10_000, name


@pytest.mark.parametrize(
    "error",
    [
        ParameterError("impulses", (-1.0,), "impulses in (0, 1000] N s"),
        StepQpError("no step meets (27b)-(27d)", {"target": [0.1, 0.2]}),
        IkInfeasibleError("left", np.array([0.1, 0.2]), "hard tasks"),
        WrenchDistributionError(2, np.array([1.0, 2.0, 330.0]), np.array([0.1, 0.0])),
        ReplayError(Path("runs/a"), "no replay.npz"),
        ResultFolderError(Path("runs/a"), "holds a sweep", "use --overwrite"),
    ],
)
def test_project_errors_keep_their_data_across_processes(error):
    """Sweep and grid workers send errors back pickled."""
    copy = pickle.loads(pickle.dumps(error))
    assert type(copy) is type(error) and str(copy) == str(error)
    assert {k: str(v) for k, v in vars(copy).items()} == {k: str(v) for k, v in vars(error).items()}


def test_the_physics_log_needs_the_full_robot(tmp_path, capsys) -> None:
    code = main(["run", "--model", "lipm", "--physics-log", "--out", str(tmp_path), "--quiet"])
    assert code == 2
    error = capsys.readouterr().err
    assert "--model" in error and "pybullet" in error and "Traceback" not in error
    assert not (tmp_path / "physics.csv").exists()


def test_a_robot_run_records_its_physics_model_and_real_time_factor(tmp_path) -> None:
    """``rsg run`` on G1 (the default model and robot) writes the summary with the
    real-time factor and the joints welded in its physics model."""
    from robots import get_robot

    code = main(["run", "--scenario", "walk", "--duration", "0.3", "--no-plots", "--quiet",
                 "--out", str(tmp_path)])  # fmt: skip
    assert code in (0, 1)  # 0.3 s: too short for two nominal steps, so maybe not "recovered"
    summary = json.loads((tmp_path / "summary.json").read_text())
    assert summary["model"] == "pybullet" and summary["robot"] == "g1"
    assert summary["fell"] is False and summary["sim_time"] == pytest.approx(0.3)
    assert summary["real_time_factor"] > 0.0
    assert summary["locked_joints"] == list(get_robot("g1").locked_joints)
    assert summary["parameters"]["dcm_inset"] == 0.02


def test_paper_rules_are_one_list_that_the_help_shows(capsys) -> None:
    """--paper-rules sets every extension of app.setup.paper_rules.PAPER_RULES to its paper value,
    and each command's help names each of them."""
    from app.setup.paper_rules import PAPER_RULES, paper_rules

    config = paper_rules(PlannerConfig())
    for extension in PAPER_RULES:
        owner = config.rsg if hasattr(config.rsg, extension.field) else config.constraints
        assert getattr(owner, extension.field) == extension.paper_value, extension
    for command in ("run", "sweep", "grid"):
        with pytest.raises(SystemExit):
            main([command, "--help"])
        text = " ".join(capsys.readouterr().out.split())
        for extension in PAPER_RULES:
            assert f"{extension.field}={extension.paper_value}" in text, (command, extension)
