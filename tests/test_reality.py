"""The reality of a full-robot run (app/reality.py): profiles, seeded draws and their
ranges, and ``--reality`` on every command that builds a robot."""

from __future__ import annotations

import argparse
import json
import math
import os
import subprocess
import sys
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from app.cli import main
from app.commands.arguments import CommandParser
from app.experiments.campaign import RESULT_FIELDS as CAMPAIGN_FIELDS
from app.experiments.campaign import CampaignSpec, push_seed
from app.experiments.jobs import load_finished
from app.experiments.sweep import (
    RESULT_FIELDS,
    PushExperiment,
    SweepSpec,
    push_reality_seed,
    result_fields,
)
from app.reality import (
    COM_OFFSET,
    DEFAULT_PROFILE,
    DELAY,
    GAIN_SCALE,
    GROUND_FRICTION,
    LINK_MASS_SCALE,
    NOISE_SCALE,
    NOMINAL_DELAY,
    NOMINAL_NOISE,
    PROFILES,
    TORSO_ADDED_MASS,
    RealityDraw,
    SensorNoise,
    draw_reality,
    robot_reality,
    trial_seed,
)
from app.setup.build import backend_reality, build_backend
from planner.exceptions import ParameterError
from robots import get_robot

ROOT = Path(__file__).resolve().parents[1]
LINKS = ("pelvis", "left_knee_link", "right_knee_link", "torso_link", "left_ankle_roll_link")
JOINTS = ("left_knee_joint", "right_knee_joint", "waist_yaw_joint")
TORSO = "torso_link"
FRICTION = 1.0
#: The commands that take --reality, and the arguments each needs to parse.
COMMANDS = {
    "run": ["--out", "x"],
    "pushes": ["--out", "x"],
    "sweep": ["--out", "x"],
    "grid": ["--out", "x"],
    "protocol": ["--out", "x"],
    "bench": ["--out", "x"],
    "demo": [],
}


def draw(profile: str, seed: int = 7) -> RealityDraw:
    return draw_reality(profile, seed, LINKS, JOINTS, TORSO, FRICTION)


def test_the_same_seed_draws_the_same_errors_bit_for_bit_and_another_seed_others() -> None:
    first, again = draw("randomized", 7), draw("randomized", 7)
    assert first == again
    # JSON writes each float's shortest round-trip repr: equal text is equal bits.
    assert json.dumps(first.as_dict()) == json.dumps(again.as_dict())
    other = draw("randomized", 8)
    assert other != first
    for name in ("delay", "torso_added_mass", "ground_friction", "noise_scale", "com_offset"):
        assert getattr(other, name) != getattr(first, name), name
    assert other.link_mass_scale != first.link_mass_scale
    assert other.stiffness_scale != first.stiffness_scale
    assert first.stiffness_scale != first.damping_scale  # kp and kd drawn apart


def test_a_draw_is_the_same_in_another_process() -> None:
    """No per-process state (Python's string hash changes per process; the draw does not)."""
    code = (
        "import json; from app.reality import draw_reality; "
        f"print(json.dumps(draw_reality('randomized', 7, {LINKS!r}, {JOINTS!r}, {TORSO!r}, "
        f"{FRICTION!r}).as_dict()))"
    )
    environment = {**os.environ, "PYTHONHASHSEED": "12345"}
    completed = subprocess.run(
        [sys.executable, "-c", code], cwd=ROOT, capture_output=True, text=True, env=environment,
        timeout=120, check=True,
    )  # fmt: skip
    assert completed.stdout.strip() == json.dumps(draw("randomized", 7).as_dict())


def test_a_factor_depends_on_its_name_only() -> None:
    """Welding a joint (a link fewer) does not reshuffle the other links' factors."""
    full = draw("randomized", 3)
    fewer = draw_reality("randomized", 3, LINKS[:2] + (TORSO,), JOINTS[:1], TORSO, FRICTION)
    for name, factor in fewer.link_mass_scale.items():
        assert full.link_mass_scale[name] == factor
    assert fewer.stiffness_scale[JOINTS[0]] == full.stiffness_scale[JOINTS[0]]
    assert fewer.delay == full.delay and fewer.com_offset == full.com_offset


def within(value: float, bounds: tuple[float, float]) -> bool:
    return bounds[0] <= value <= bounds[1]


def test_every_randomized_draw_lies_in_its_ranges() -> None:
    seen_signs = set()
    for seed in range(200):
        reality = draw("randomized", seed)
        assert reality.profile == "randomized" and reality.seed == seed
        assert set(reality.link_mass_scale) == set(LINKS)
        assert set(reality.stiffness_scale) == set(reality.damping_scale) == set(JOINTS)
        assert all(within(f, LINK_MASS_SCALE) for f in reality.link_mass_scale.values())
        assert all(within(f, GAIN_SCALE) for f in reality.stiffness_scale.values())
        assert all(within(f, GAIN_SCALE) for f in reality.damping_scale.values())
        assert within(reality.torso_added_mass, TORSO_ADDED_MASS)
        assert reality.torso_link == TORSO
        assert len(reality.com_offset) == 3
        assert all(within(c, COM_OFFSET) for c in reality.com_offset)
        assert within(reality.ground_friction, GROUND_FRICTION)
        assert within(reality.delay, DELAY)
        assert within(reality.noise_scale, NOISE_SCALE)
        for name, value in asdict(reality.noise).items():
            expected = getattr(NOMINAL_NOISE, name) * reality.noise_scale
            assert value == pytest.approx(expected, rel=1e-12), name
        assert abs(reality.gyro_yaw_bias) == pytest.approx(reality.noise.gyro_yaw_bias)
        seen_signs.add(math.copysign(1.0, reality.gyro_yaw_bias))
        assert reality.model_error
    assert seen_signs == {1.0, -1.0}


def test_the_ranges_are_the_stated_ones() -> None:
    """The ranges of the brief and their sources (holosoma, mujoco_playground)."""
    assert LINK_MASS_SCALE == (0.9, 1.1) and GAIN_SCALE == (0.9, 1.1)
    assert TORSO_ADDED_MASS == (-1.0, 3.0) and COM_OFFSET == (-0.05, 0.05)
    assert GROUND_FRICTION == (0.4, 1.0) and DELAY == (0.0, 0.020)
    assert NOISE_SCALE == (0.0, 2.0)


def test_ideal_has_no_noise_no_delay_and_unit_scales() -> None:
    reality = draw("ideal")
    assert reality.noise == SensorNoise() and all(v == 0.0 for v in asdict(reality.noise).values())
    assert reality.noise_scale == 0.0 and reality.delay == 0.0 and reality.gyro_yaw_bias == 0.0
    assert reality.link_mass_scale == dict.fromkeys(LINKS, 1.0)
    assert reality.stiffness_scale == reality.damping_scale == dict.fromkeys(JOINTS, 1.0)
    assert reality.torso_added_mass == 0.0 and reality.com_offset == (0.0, 0.0, 0.0)
    assert reality.ground_friction == FRICTION
    assert not reality.model_error
    assert "ideal" in reality.describe()


def test_nominal_has_the_nominal_figures_and_no_model_error() -> None:
    reality = draw("nominal")
    assert reality.noise == NOMINAL_NOISE and reality.noise_scale == 1.0
    assert reality.delay == NOMINAL_DELAY == 0.002
    assert reality.gyro_yaw_bias == NOMINAL_NOISE.gyro_yaw_bias > 0.0
    assert NOMINAL_NOISE.gyroscope == 0.005 and NOMINAL_NOISE.joint_position == 0.001
    assert not reality.model_error
    assert reality.link_mass_scale == dict.fromkeys(LINKS, 1.0)
    assert reality.ground_friction == FRICTION
    assert replace(draw("nominal", 1), seed=2) == draw("nominal", 2)  # only the noise's seed
    assert DEFAULT_PROFILE == "nominal" and PROFILES == ("ideal", "nominal", "randomized")


def test_as_dict_is_plain_json_and_describe_is_one_line() -> None:
    for profile in PROFILES:
        reality = draw(profile)
        document = reality.as_dict()
        assert json.loads(json.dumps(document)) == document
        assert document["profile"] == profile and document["seed"] == 7
        line = reality.describe()
        assert "\n" not in line and profile in line


@pytest.mark.parametrize("profile", ["foo", "", "Nominal", None, 3])
def test_an_unknown_profile_is_refused_naming_reality(profile: object) -> None:
    with pytest.raises(ParameterError) as error:
        draw_reality(profile, 1, LINKS, JOINTS, TORSO, FRICTION)  # type: ignore[arg-type]
    assert error.value.field == "reality" and error.value.value == profile
    assert "ideal, nominal, randomized" in error.value.allowed
    with pytest.raises(ParameterError, match="reality"):
        build_backend("lipm", None, "rsg", reality=profile)  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="reality"):
        PushExperiment(reality=profile)  # type: ignore[arg-type]


def test_bad_seeds_and_links_are_refused_naming_the_field() -> None:
    for seed in (-1, 1.5, True):
        with pytest.raises(ParameterError, match="seed"):
            draw_reality("ideal", seed, LINKS, JOINTS, TORSO, FRICTION)  # type: ignore[arg-type]
    with pytest.raises(ParameterError, match="torso_link"):
        draw_reality("nominal", 1, LINKS, JOINTS, "no_such_link", FRICTION)
    with pytest.raises(ParameterError, match="ground_friction"):
        draw_reality("nominal", 1, LINKS, JOINTS, TORSO, 0.0)


def test_trial_seeds_are_deterministic_and_distinct() -> None:
    assert trial_seed(1, 5) == trial_seed(1, 5)
    seeds = {trial_seed(1), trial_seed(1, 0), trial_seed(1, 0, 0), trial_seed(2, 0)}
    seeds |= {trial_seed(1, index) for index in range(1, 1000)}
    assert len(seeds) == 4 + 999  # numpy pads entropy with zeros; the key count keeps apart
    assert all(0 <= s < 2**63 for s in seeds)
    spec = CampaignSpec(model="lipm", robot="g1", controllers=("rsg",), pushes=3)
    assert push_seed(spec, 2) == trial_seed(spec.seed, 2) != push_seed(spec, 1)
    # A push's robot does not depend on the controller; the sweep's does not on the impulse.
    assert push_reality_seed(45.0, 0.5) != push_reality_seed(45.0, 0.5, 6.0)
    assert push_reality_seed(45.0, 0.5, 6.0) != push_reality_seed(45.0, 0.5, 8.0)


def test_g1s_reality_covers_its_physics_links_and_actuated_joints() -> None:
    description = get_robot("g1")
    reality = robot_reality(description, "randomized", 11)
    assert reality == robot_reality(description, "randomized", 11)
    assert reality.torso_link == description.trunk_link in reality.link_mass_scale
    actuated = set(description.joint_impedance) - set(description.locked_joints)
    assert set(reality.stiffness_scale) == actuated
    assert not set(reality.stiffness_scale) & set(description.locked_joints)
    assert robot_reality(description, "ideal", 11).ground_friction == description.ground_friction


def test_the_recorded_draw_is_the_backends_own_when_it_has_one() -> None:
    class WithDraw:
        reality = draw("randomized", 4)

    class Lipm:
        pass

    assert backend_reality(WithDraw(), "randomized", 4) is WithDraw.reality
    assert backend_reality(Lipm(), "randomized", 4) is None


def command_parser(verb: str) -> argparse.ArgumentParser:
    """``rsg VERB``'s parser alone, built by its module's ``add_parser`` (nothing runs)."""
    if verb == "demo":
        from web import cli_demo as module
    else:
        import importlib

        module = importlib.import_module(f"app.commands.{verb}")  # type: ignore[assignment]
    parser = CommandParser(prog="rsg")
    module.add_parser(parser.add_subparsers(dest="command", required=True))
    return parser


@pytest.mark.parametrize("verb", list(COMMANDS))
def test_every_command_takes_reality(verb: str, capsys: pytest.CaptureFixture[str]) -> None:
    parser = command_parser(verb)
    arguments = [verb, *COMMANDS[verb]]
    assert parser.parse_args(arguments).reality == DEFAULT_PROFILE
    for profile in PROFILES:
        assert parser.parse_args([*arguments, "--reality", profile]).reality == profile
    with pytest.raises(SystemExit) as stop:
        parser.parse_args([*arguments, "--reality", "foo"])
    assert stop.value.code == 2
    error = capsys.readouterr().err
    assert "--reality" in error and "'foo'" in error and "randomized" in error
    with pytest.raises(SystemExit):
        parser.parse_args([verb, "--help"])
    assert "--reality {ideal,nominal,randomized}" in capsys.readouterr().out


def test_run_takes_a_reality_seed(capsys: pytest.CaptureFixture[str]) -> None:
    parser = command_parser("run")
    assert parser.parse_args(["run", "--out", "x"]).reality_seed == 0
    assert parser.parse_args(["run", "--out", "x", "--reality-seed", "12"]).reality_seed == 12
    with pytest.raises(SystemExit):
        parser.parse_args(["run", "--out", "x", "--reality-seed", "-3"])
    assert "--reality-seed='-3': an integer >= 0" in capsys.readouterr().err


def test_a_lipm_run_writes_its_profile_into_the_summary(tmp_path: Path, capsys) -> None:
    out = tmp_path / "run"
    args = ["run", "--model", "lipm", "--reality", "randomized", "--reality-seed", "5",
            "--scenario", "walk", "--duration", "1", "--no-plots", "--quiet",
            "--out", str(out)]  # fmt: skip
    assert main(args) in (0, 1)  # recovered or not: 1 s of walking decides nothing here
    assert "ignored on --model lipm" in capsys.readouterr().out
    summary = json.loads((out / "summary.json").read_text())
    assert summary["reality"] == "randomized" and summary["reality_seed"] == 5
    assert "reality_draw" not in summary  # the LIPM twin stays ideal


def test_a_folder_of_before_the_profiles_counts_as_ideal(tmp_path: Path) -> None:
    """A specification stored before the profiles existed ran on the ideal robot: resuming
    it with another profile is refused, naming reality. On the LIPM the profile changes
    nothing and is not compared (:func:`app.experiments.sweep.result_fields`)."""
    spec = SweepSpec(controllers=("rsg",), directions=2, phases=(0.5,))
    stored = {k: v for k, v in json.loads(json.dumps(asdict(spec))).items() if k != "reality"}
    (tmp_path / "sweep_spec.json").write_text(json.dumps(stored))
    fields = ("model", "directions", "reality")  # as on the full robot

    def parse(line: bytes) -> tuple[dict | None, str]:
        return json.loads(line), ""

    with pytest.raises(ParameterError, match="reality"):
        load_finished(tmp_path, spec, "sweep_spec.json", fields, parse)
    ideal = replace(spec, reality="ideal")
    assert load_finished(tmp_path, ideal, "sweep_spec.json", fields, parse) == {}
    assert "reality" in RESULT_FIELDS and "reality" in CAMPAIGN_FIELDS
    assert "reality" not in result_fields(RESULT_FIELDS, spec)  # spec is on the LIPM
    lipm_fields = result_fields(RESULT_FIELDS, spec)
    assert load_finished(tmp_path, spec, "sweep_spec.json", lipm_fields, parse) == {}


def test_the_simulated_robot_is_the_drawn_one(tmp_path: Path, monkeypatch) -> None:
    """A randomized G1 in PyBullet weighs what its draw says (each link's mass scaled, the
    torso's mass added) and stands on ground of the drawn friction, while its controller
    keeps the nominal model; the same seed builds the same robot."""
    import pybullet

    from app.backends.pybullet import PyBulletBackend

    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path / "cache"))
    g1 = get_robot("g1")
    draw = robot_reality(g1, "randomized", 7)
    assert draw == robot_reality(g1, "randomized", 7)
    backend = PyBulletBackend(g1, reality=draw)
    nominal = PyBulletBackend(g1, reality=robot_reality(g1, "ideal", 7))
    try:
        sim, plain = backend.sim, nominal.sim
        names = [sim.link_name(link) for link in range(-1, sim.link_count)]
        expected = [
            mass * draw.link_mass_scale.get(name, 1.0)
            for name, mass in zip(names, plain.link_masses, strict=True)
        ]
        expected[names.index(draw.torso_link)] += draw.torso_added_mass
        assert sim.link_masses == pytest.approx(expected, rel=1e-6)
        assert sim.mass != pytest.approx(plain.mass, abs=0.1)
        # PyBullet's contact friction is the product of the two bodies': each sole's pair
        # with the ground has the drawn coefficient (not its square)
        ground = sim.client.getDynamicsInfo(sim.ground, -1)[1]
        for link in sim.foot_links.values():
            sole = sim.client.getDynamicsInfo(sim.body, link)[1]
            assert ground * sole == pytest.approx(draw.ground_friction)
        assert backend.controller.mass == pytest.approx(nominal.controller.mass)
        assert pybullet.isConnected(sim.client._client)
    finally:
        backend.close()
        nominal.close()
