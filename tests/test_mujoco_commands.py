"""Every command that takes ``--model`` runs the full robot on MuJoCo as on PyBullet
(:class:`app.backends.mujoco.MujocoBackend`), and its result files name the engine."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from app.cli import main
from app.setup.build import build_backend
from conftest import assert_stands_one_second
from planner.types import Foothold

GRAVITY = 9.81  # [m/s^2]
QUIET = ["--quiet", "--workers", "1"]


@pytest.fixture
def engines_built(monkeypatch: pytest.MonkeyPatch) -> list[str]:
    """The name of every full-robot backend built in this process (``--workers 1`` runs
    the jobs here), from the shared ``__init__`` of both engines' backends."""
    from app.backends.pybullet import PyBulletBackend

    built: list[str] = []
    original = PyBulletBackend.__init__

    def counting(self, *args, **kwargs) -> None:  # noqa: ANN001, ANN002, ANN003
        built.append(self.name)
        original(self, *args, **kwargs)

    monkeypatch.setattr(PyBulletBackend, "__init__", counting)
    return built


@pytest.mark.usefixtures("cache_in_tmp")
def test_run_walks_on_mujoco_without_falling_and_its_replay_says_mujoco(tmp_path: Path):
    """``rsg run --model mujoco``: G1 walks 2.5 s (three steps) without falling; the summary
    and the replay name the engine, and the replay page draws the robot's pose."""
    from app.results.replay import load_replay
    from web.replay_source import snapshot_at

    out = tmp_path / "run"
    args = ["run", "--model", "mujoco", "--scenario", "walk", "--duration", "2.5"]
    assert main([*args, "--no-plots", "--quiet", "--out", str(out)]) in (0, 1)
    summary = json.loads((out / "summary.json").read_text())
    assert summary["model"] == "mujoco" and summary["robot"] == "g1"
    assert not summary["fell"], summary["fall_reason"]
    assert len(summary["steps"]) >= 3, summary["steps"]
    replay = load_replay(out)
    assert replay.meta["model"] == "mujoco" and replay.robot is not None
    snapshot = snapshot_at(replay, 2.0)
    assert snapshot.status.model == "mujoco" and snapshot.robot is not None
    assert snapshot.robot.base_position[2] > 0.5  # the pelvis drawn upright


@pytest.mark.usefixtures("cache_in_tmp")
@pytest.mark.parametrize(
    ("name", "args", "spec_file"),
    [
        ("pushes", ["--pushes", "1", "--settle", "1", "--controllers", "rsg", "--no-plots"],
         "campaign_spec.json"),
        ("sweep", ["--controllers", "rsg", "--directions", "1", "--phases", "0", "--cycle", "1",
                   "--settle", "1", "--tolerance", "10", "--replays", "0"], "sweep_spec.json"),
        ("grid", ["--controllers", "rsg", "--impulses", "5", "--directions", "1", "--settle",
                  "1", "--replays", "0", "--no-plots"], "grid.json"),
    ],
)  # fmt: skip
def test_push_commands_run_on_mujoco_and_record_it(
    name, args, spec_file, tmp_path: Path, engines_built: list[str]
):
    """``rsg pushes|sweep|grid --model mujoco`` on a single push: every robot the jobs
    build is on MuJoCo, and the folder's specification says ``mujoco``."""
    out = tmp_path / name
    assert main([name, "--model", "mujoco", *args, *QUIET, "--out", str(out)]) == 0
    assert engines_built and set(engines_built) == {"mujoco"}, engines_built
    written = json.loads((out / spec_file).read_text())
    assert written.get("model", written.get("spec", {}).get("model")) == "mujoco", written
    if name != "grid":
        records = [json.loads(line) for line in (out / "jobs.jsonl").read_text().splitlines()]
        assert records and all(r["wall_time"] > 0.0 for r in records)


def test_protocol_and_demo_accept_mujoco():
    """``rsg protocol --model mujoco`` times its pushes on the MuJoCo robot (its sweep's
    model), and ``rsg demo --model mujoco`` draws the robot from the URDF's meshes."""
    from app.experiments.protocol import ProtocolSpec
    from web.demo import _robot_urdf

    assert ProtocolSpec(model="mujoco").sweep_spec().model == "mujoco"
    urdf = _robot_urdf("mujoco", None)
    assert urdf is not None and urdf.exists()


@pytest.mark.usefixtures("cache_in_tmp")
def test_placo_wpg_runs_on_either_engine_and_not_on_the_lipm():
    """The placo-wpg baseline drives the full robot's IK through the same backend
    interface, so it is built on MuJoCo too; on the LIPM it is refused, naming both
    engines."""
    from app.experiments.sweep import SweepSpec, build_controller
    from planner.exceptions import ParameterError

    spec = SweepSpec(model="mujoco", controllers=("placo-wpg",), reality="ideal")
    backend, _, _, planner = build_controller(spec, "placo-wpg")
    try:
        assert backend.name == "mujoco" and planner is not None
    finally:
        backend.close()
    with pytest.raises(ParameterError, match="pybullet or mujoco"):
        SweepSpec(model="lipm", controllers=("placo-wpg",))


@pytest.mark.usefixtures("cache_in_tmp")
def test_bench_times_both_engines_side_by_side(tmp_path: Path, capsys: pytest.CaptureFixture):
    """``rsg bench --model pybullet,mujoco``: each engine's walk timed in one process; the
    first's figures at the top level, both under ``by_model``, a side-by-side table."""
    out = tmp_path / "bench"
    args = ["bench", "--model", "pybullet,mujoco", "--duration", "0.1", "--samples", "10"]
    assert main([*args, "--out", str(out)]) == 0
    report = json.loads((out / "bench.json").read_text())
    assert report["model"] == "pybullet" and list(report["by_model"]) == ["pybullet", "mujoco"]
    for model, figures in report["by_model"].items():
        assert figures["model"] == model and figures["placo_wpg"]["model"] == model
        assert figures["simulated"] == pytest.approx(0.1) and not figures["fell"]
        assert figures["physics"]["count"] >= 100  # one per 1 ms physics step
    assert "| real-time factor (rsg) |" in capsys.readouterr().out


@pytest.mark.usefixtures("cache_in_tmp")
def test_talos_on_mujoco_has_pybullets_mass_and_stands():
    """Talos on MuJoCo: the mass PyBullet measures within 0.1 %, and 1 s standing under
    the whole-body controller (the ideal sensors, the test's DCM feedback) without a
    fall, on both feet, which carry m g within 2 % at the end."""

    masses = {}
    for engine in ("pybullet", "mujoco"):
        backend, config, _ = build_backend(engine, "talos", "rsg", reality="ideal")
        masses[engine] = backend.mass
        if engine == "pybullet":
            backend.close()
    assert masses["mujoco"] == pytest.approx(masses["pybullet"], rel=1e-3), masses
    half_width = config.gait.step_width / 2
    left = Foothold("left", np.array([0.0, half_width]))
    right = Foothold("right", np.array([0.0, -half_width]))
    try:
        assert_stands_one_second(backend, left, right)
    finally:
        backend.close()


@pytest.mark.slow
@pytest.mark.usefixtures("cache_in_tmp")
def test_a_mujoco_campaign_runs_every_push_beside_its_twin(tmp_path: Path):
    """``rsg pushes --model mujoco --pushes 3``: each push on the MuJoCo robot with rsg and
    no-step, and on the LIPM twin; every run has an outcome; the summary names the
    engine."""
    out = tmp_path / "pushes"
    args = ["pushes", "--model", "mujoco", "--pushes", "3", "--settle", "3", "--no-plots"]
    assert main([*args, "--quiet", "--workers", "2", "--out", str(out)]) == 0
    document = json.loads((out / "campaign.json").read_text())
    assert document["spec"]["model"] == "mujoco"
    records = [json.loads(line) for line in (out / "jobs.jsonl").read_text().splitlines()]
    assert len(records) == 3 * 2 * 2  # pushes x controllers x (robot, twin)
    outcomes = {r["outcome"] for r in records}
    assert outcomes <= {"recovered", "survived", "fell"} and outcomes, records
    assert sum(not r["twin"] for r in records) == 6


@pytest.mark.slow
@pytest.mark.usefixtures("cache_in_tmp")
def test_the_protocol_runs_on_mujoco(tmp_path: Path):
    """``rsg protocol --model mujoco``: the four pushes bisected on the MuJoCo robot (a
    coarse tolerance, 1 s after each push); protocol.json names the engine and has a
    largest fraction of m g per direction."""
    out = tmp_path / "protocol"
    args = ["protocol", "--model", "mujoco", "--tolerance", "0.5", "--settle", "1"]
    assert main([*args, "--criterion", "no-fall", *QUIET, "--out", str(out)]) == 0
    document = json.loads((out / "protocol.json").read_text())
    assert document["spec"]["model"] == "mujoco"
    directions = document["controllers"]["rsg"]
    assert set(directions) == {"forward", "backward", "inward", "outward"}, directions
