"""The RSG walking the Unitree G1 in PyBullet (slow: full-robot runs).

The walk, push and paper-fig6 tests state the goals of the full-robot backend (the
torque-controlled robot of :mod:`app.backends.pybullet_robot` under the whole-body
stabilizer of :mod:`app.stabilizer`); the figures in the docstrings were measured
with the defaults of ``robots/g1.py`` and ``app/stabilizer/config.py``, where given.
See also ``rsg run --physics-log``.
"""

from __future__ import annotations

import dataclasses
from collections.abc import Callable
from typing import Any

import numpy as np
import pytest

from app.experiments.grid import GridSpec, run_grid
from app.runner import ClosedLoop, RunResult
from app.scenarios import BUILT_IN, Scenario
from app.setup.build import build_robot_backend
from app.stabilizer.centroidal import momentum_velocity
from app.stabilizer.controller import CONTACT_LOAD
from kinematics.robot_model import yaw_of
from planner.parameters import GRAVITY
from planner.types import PlannerOutput, Push
from robots import get_robot

pytestmark = pytest.mark.slow

LANDING_TOLERANCE = 0.03  # [m] measured sole vs. the planner's step position
# The stabilizer's mechanisms are checked with exact sensors; how the robot does under
# the nominal and randomized sensors and errors is measured on fresh seeds
# (docs/results.md, "An honest robot").
MECHANISM_REALITY = "ideal"


def HONEST_PLANT_GAP(measured: str):  # noqa: N802, ANN201
    """Held on the stable-PD plant (a7e2f47), not yet on the honest one (the driver's law
    on the command alone, the controller on its sensors): ``measured`` is how it fails.
    Strict: a fix makes the test pass and the mark must go."""
    return pytest.mark.xfail(strict=True, reason=f"honest plant: {measured}")


@pytest.fixture(autouse=True)
def _cache_in_tmp(tmp_path_factory, monkeypatch):
    monkeypatch.setenv("RSG_CACHE_DIR", str(tmp_path_factory.getbasetemp() / "cache"))


def run_g1(
    scenario: Scenario,
    controller: str = "rsg",
    duration: float | None = None,
    robot: str = "g1",
    overrides: tuple[tuple[str, str], ...] = (),
    observe: Callable[[PlannerOutput, Any], None] | None = None,
    reality: str = MECHANISM_REALITY,
) -> tuple[RunResult, list[float]]:
    """Run ``scenario`` on ``robot`` (G1 by default); returns the result and each
    step's landing error [m].

    The landing error is measured at the end of the step's double support, when
    the new stance foot is down: the distance between the measured sole and the
    planner's step position. ``overrides`` are ``--set`` pairs; ``observe(output,
    backend)`` is called after every tick.
    """
    backend, config, initial = build_robot_backend(robot, controller, overrides, reality=reality)
    if duration is not None:
        scenario = dataclasses.replace(scenario, duration=duration)
    scaled, _ = scenario.scaled_to(backend.mass)
    loop = ClosedLoop(backend, config, scaled, initial)
    errors: list[float] = []
    pending = None
    try:
        for _ in range(round(scaled.duration / loop.period)):
            out = loop.tick()
            if observe is not None:
                observe(out, backend)
            if out.step is not None:
                pending = out.stance
            if pending is not None and not out.double_support and out.step is None:
                sole = backend.sole_positions()[pending.foot][:2]
                errors.append(float(np.linalg.norm(sole - pending.position)))
                pending = None
            if backend.fall_status().fell:
                break
        return loop.result(), errors
    finally:
        backend.close()


def test_two_identical_runs_give_the_same_results():
    """Bit for bit: every QP answer is polished to its exact optimum (planner/qp.py)."""
    first, first_errors = run_g1(BUILT_IN["walk"], duration=1.5)
    second, second_errors = run_g1(BUILT_IN["walk"], duration=1.5)
    for name in ("com_x", "com_y", "zmp_x", "zmp_y", "lyapunov"):
        np.testing.assert_array_equal(first.column(name), second.column(name))
    np.testing.assert_array_equal(first_errors, second_errors)
    assert [s.event for s in first.steps] == [s.event for s in second.steps]


@HONEST_PLANT_GAP("a sole lands 4.2 cm from its foothold (3 cm allowed)")
def test_g1_walks_20_s_with_the_rsg_and_lands_where_planned():
    result, errors = run_g1(BUILT_IN["walk"], duration=20.0)
    assert not result.fall.fell, result.fall.reason
    assert result.sim_time == pytest.approx(20.0)
    assert len(errors) >= 20
    assert max(errors) < LANDING_TOLERANCE
    assert result.recovered


@HONEST_PLANT_GAP("at a 0.3 m stride G1 falls")
def test_g1_walks_past_x_100_m_where_pybullets_plane_ended():
    """PyBullet's plane.urdf ends at x = 100 m; at 0.3 m a step G1 is there after 264 s."""
    result, _ = run_g1(BUILT_IN["walk"], duration=290.0, overrides=(("stride_length", "0.3"),))
    assert not result.fall.fell, result.fall.reason
    assert result.sim_time == pytest.approx(290.0)
    assert result.column("com_x")[-1] > 103.0


def test_talos_walks_10_s_with_the_rsg_and_lands_where_planned():
    """The second robot: only its description (robots/talos.py), no controller change."""
    result, errors = run_g1(BUILT_IN["walk"], duration=10.0, robot="talos")
    assert not result.fall.fell, result.fall.reason
    assert result.sim_time == pytest.approx(10.0)
    assert len(errors) >= 10
    assert max(errors) < LANDING_TOLERANCE
    assert not any(s.event["adjusted"] for s in result.steps)
    assert result.recovered


def test_talos_catches_a_stance_side_push_with_a_wide_outward_step():
    """A 23 N s push toward the stance side in the single support (development push 61
    of seed 1): Talos steps out wider than 0.45 m (measured 0.50 m; its bound is its
    legs' reach, 0.83 m), lands where planned and recovers. With a 0.4 m bound it falls
    (measured: a knee touches the ground)."""
    push = Push(3.368, np.array([16.7103, 16.1369]), 0.146)
    result, errors = run_g1(Scenario("push", 7.5, (push,), reference_mass=None), robot="talos")
    assert not result.fall.fell, result.fall.reason
    assert max(errors) < LANDING_TOLERANCE
    assert max(abs(s.step[1]) for s in result.steps) > 0.45  # u_d,y [m]
    assert result.recovered


@HONEST_PLANT_GAP("Talos falls")
def test_talos_keeps_the_outward_reach_its_lean_gives_a_wide_catching_step():
    """26 N s to the left early in a right single support (development push 26 of Talos's
    seed 1): a 0.83 m outward step. The swing sole's correction for the body's tilt leaves
    alone the part that lengthens the step: Talos recovers (measured: 3 adjusted steps in
    all). Correcting the whole offset, the pelvis rolled 10-17 deg after the wide step, the
    correction chased the roll, the crossing sole landed 16.8 cm off its foothold and Talos
    fell (docs/notes/2026-12-07-swing-sole-on-a-tilted-body.md)."""
    push = Push(3.3744, np.array([5.2927, 25.5577]), 0.077)
    result, _ = run_g1(Scenario("push", 8.0, (push,), reference_mass=None), robot="talos")
    assert not result.fall.fell, result.fall.reason
    assert max(abs(s.step[1]) for s in result.steps) > 0.8  # u_d,y [m]
    assert result.recovered


@HONEST_PLANT_GAP("the widest step is 0.27 m")
def test_g1_catches_a_stance_side_push_with_an_outward_step_wider_than_0_4_m():
    """9.6 N s toward the stance side in the single support (development push 26 of
    seed 1): G1 steps out more than 0.45 m (its bound is its legs' reach, 0.55 m),
    walks back in quick adjusted steps, and within 8 s of the push walks on in nominal
    steps landing where planned. With a 0.4 m bound it falls (measured). From 2 s after
    the push its jumps are nominal, V_u at them 0.51-0.75 gamma_v (measured)."""
    push = Push(3.3744, np.array([1.9508, 9.4201]), 0.077)
    result, errors = run_g1(Scenario("push", push.time + 8.0, (push,), reference_mass=None))
    assert not result.fall.fell, result.fall.reason
    assert max(abs(s.step[1]) for s in result.steps) > 0.45  # u_d,y [m]
    assert not any(s.event["adjusted"] for s in result.steps[-2:])
    assert max(errors[-5:]) < LANDING_TOLERANCE


def test_a_fast_outward_step_does_not_turn_the_stance_foot():
    """7.5 N s to the left, early in the right foot's single support (development push 24
    of seed 1): G1 steps its left foot out 0.32 m in 0.22 s. The upper body turns against
    the swinging leg's momentum about z (kinematics/upper_body.py), so the stance sole's
    yaw changes less than 2.5 deg over each single support of the 2 s after the push
    (measured 1.8 deg on the wide step that follows, since the swing leg's accelerations
    are fed forward unfiltered; 0.5 deg before. Measured over-turning: the upper body
    taking back all of the legs' momentum about z, 3.5 deg; turning with the legs instead
    of against them, 3.1 deg; before 510e58d, taking back only the horizontal momentum,
    3.0 deg)."""
    push = Push(3.2096, np.array([-3.1806, 6.7591]), 0.107)
    turns: list[float] = []
    yaws: list[float] = []  # the stance sole's, over the current single support [deg]

    def observe(out: PlannerOutput, backend: Any) -> None:
        if out.double_support:  # a single support ended: its stance foot's turn
            if yaws and out.time > push.time:
                turns.append(yaws[-1] - yaws[0])
            yaws.clear()
            return
        _, rotation = backend.controller.model.sole_frame(out.stance.foot)
        yaws.append(float(np.degrees(yaw_of(rotation))))

    scenario = Scenario("push", push.time + 2.0, (push,), reference_mass=None)
    result, _ = run_g1(scenario, observe=observe)
    assert not result.fall.fell, result.fall.reason
    assert len(turns) >= 3
    assert max(abs(turn) for turn in turns) < 2.5, turns


def test_a_swing_sole_sent_elsewhere_by_a_push_follows_its_target():
    """25 N s forward and to the left at 2.6 s, mid-swing: the planner moves the left
    foot's step 8 cm further forward and 13 cm further out, to be taken 0.2 s after the
    push instead of at 3.1 s. The swing leg
    gets its planned accelerations as feed-forward torque, so its sole stays within 3.8
    cm of the IK's target and 1.6 cm on average until it lands (measured 3.0 and 1.3 cm;
    with its feed-forward low-passed as the stance leg's is, 4.8 and 1.9 cm, and the sole
    touched down 0.03 s later)."""
    push = Push(2.6, np.array([17.68, 17.68]), 0.1)
    errors: list[float] = []  # horizontal, sole against its target [m]
    landed: list[float] = []

    def observe(out: PlannerOutput, backend: Any) -> None:
        if out.time < push.time or landed:
            return
        if out.step is not None:
            landed.append(out.time)
        elif not out.double_support:
            swing = "left" if out.stance.foot == "right" else "right"
            sole = backend.sole_positions()[swing][:2]
            errors.append(float(np.linalg.norm(sole - backend.controller.sole_targets[swing][:2])))

    scenario = Scenario("push", push.time + 0.5, (push,), reference_mass=None)
    result, _ = run_g1(scenario, observe=observe)
    assert not result.fall.fell, result.fall.reason
    assert landed and landed[0] < 2.9, landed
    assert max(errors) < 0.038, max(errors)
    assert float(np.mean(errors)) < 0.016, np.mean(errors)


@HONEST_PLANT_GAP("a step after the push is adjusted")
def test_after_a_backward_push_at_mid_swing_the_soles_land_on_their_footholds():
    """17.5 N s backward at 3.55 s, the left foot in mid-swing: the right foot, reversed,
    catches the push (an adjusted step), and the body, leaning back on its stance ankle,
    carries the swing leg forward of the IK's. With the swing sole's measured offset fed
    back (``_swing_correction``), every later sole lands within 1.5 cm of its foothold
    and the walk is nominal again (measured 1 cm, one adjusted step; without it the
    soles landed 3-6 cm ahead and every step was adjusted to the end)."""
    push = Push(3.55, np.array([-17.5, 0.0]), 0.1)
    result, errors = run_g1(Scenario("push", 7.0, (push,), reference_mass=None))
    assert result.recovered, result.fall.reason
    steps = [s.event for s in result.steps]
    catch = next(i for i, step in enumerate(steps) if step["t"] > push.time)
    assert steps[catch]["adjusted"]
    assert not any(step["adjusted"] for step in steps[catch + 2 :]), steps[catch:]
    later = errors[catch + 1 :]  # errors[i] is steps[i]'s
    assert len(later) >= 3 and max(later) < 0.015, errors


@HONEST_PLANT_GAP("G1 falls")
def test_at_the_legs_reach_the_ik_holds_its_soles_and_moves_its_joints_smoothly():
    """27.6 N s to the left and slightly back (112.5 deg) at 2.9 s, late in the right
    foot's single support: the left foot steps out 0.55 m, the legs' reach, and the real
    stance sole slips outwards. Through the catch and the steps after it the IK moves no
    joint target more than 0.25 rad from one tick to the next and a support sole it stands
    on by no more than 1.5 cm, and G1 recovers. With the support soles as hard tasks,
    placo's step at the reach left them up to 37 cm off their targets and moved joint targets
    by up to 92 deg in a tick; G1 jumped off the ground and fell (measured)."""
    push = Push(2.9, np.array([-10.543692230395413, 25.454724780108435]), 0.1)
    previous: dict[str, Any] = {}
    worst = {"joint": 0.0, "sole": 0.0}

    def observe(out: PlannerOutput, backend: Any) -> None:
        ik = backend.controller.ik
        angles = ik.joint_angles()
        support = ("left", "right") if out.double_support else (out.stance.foot,)
        soles = {foot: ik.sole_world(foot)[:3, 3].copy() for foot in ("left", "right")}
        if out.time > push.time and "angles" in previous:
            worst["joint"] = max(worst["joint"], float(np.abs(angles - previous["angles"]).max()))
            for foot in support:
                if foot in previous["support"]:
                    moved = float(np.linalg.norm(soles[foot] - previous["soles"][foot]))
                    worst["sole"] = max(worst["sole"], moved)
        previous.update(angles=angles, support=support, soles=soles)

    result, _ = run_g1(
        Scenario("push", push.time + 4.0, (push,), reference_mass=None), observe=observe
    )
    assert result.recovered, result.fall.reason
    assert worst["joint"] <= 0.25, worst
    assert worst["sole"] <= 0.015, worst


@HONEST_PLANT_GAP("the step comes at 2.54 s, not the touchdown's 2.65 s")
def test_a_sole_landing_before_its_timing_jump_is_stepped_on_at_once():
    """20 N s forward and to the left as the double support begins (2.3 s): the
    planner brings the left foot's step forward to 2.65 s, the earliest a swing may
    land. The sole touches down sooner and the jump comes at that touchdown; waiting
    for 2.65 s, the sole bounced off the ground, the stance foot rolled 30 deg on its
    inner edge and the step came at 2.76 s, after which G1 fell (measured)."""
    push = Push(2.3, np.array([14.14, 14.14]), 0.1)
    announced: list[float] = []  # the step time announced after the decision [s]
    steps: list[tuple[float, bool]] = []  # (time [s], swing sole touching a tick before)
    touching = [False]

    def observe(out: PlannerOutput, backend: Any) -> None:
        if out.time < push.time + 0.1 or steps:
            return
        if out.step is not None:
            steps.append((out.time, touching[0]))
        elif not out.double_support:
            announced.append(out.next_step_time)
            touching[0] = out.next_step.foot in backend.feet_in_contact()

    scenario = Scenario("push", push.time + 3.0, (push,), reference_mass=None)
    result, _ = run_g1(scenario, observe=observe)
    assert not result.fall.fell, result.fall.reason
    assert result.recovered
    first, touched = steps[0]
    assert touched
    assert announced[0] == pytest.approx(2.65, abs=0.011)
    assert first < announced[0] - 0.005, (first, announced[0])


@HONEST_PLANT_GAP("the soles' yaw stays off the heading")
def test_the_feet_turn_back_to_the_heading_after_a_push_that_yaws_them():
    """IHMC's outward push at 0.76 m g (24.8 N s over 0.1 s in the double support, 3.15 s)
    spins G1's feet 10-20 deg off the planner's heading. Each swing sole leaves the
    ground at the yaw it stood at and turns to the heading over the swing, so after the
    most turned landing each sole lands nearer the heading than the one before (until
    within 1 deg), within 2 deg by the fifth (measured, with the tests' pinned kernels:
    12.7, 8.7, 7.0, 4.9, 2.5, 1.1 deg at 1cc7f20; 15.3, 9.9, 3.7, 2.1, 0.5, 0.1 at
    7b11703). With the swing target's yaw jumping to the heading at the step, the foot
    still loaded in the double support was twisted, the new stance foot spun, and the
    soles landed 9-11 deg off for the rest of the run (measured)."""
    backend, config, initial = build_robot_backend("g1", "rsg", reality=MECHANISM_REALITY)
    push = Push(3.15, np.array([0.0, -24.77]), 0.1)
    scenario = Scenario("push", 7.5, (push,), reference_mass=None)
    loop = ClosedLoop(backend, config, scenario, initial)
    yaws = []  # (time [s], |yaw| [deg] of the sole that has just landed) at each step
    try:
        for _ in range(round(scenario.duration / loop.period)):
            out = loop.tick()
            if out.step is not None:
                yaw = abs(np.degrees(backend.sim.sole_yaw(out.step.foot)))
                yaws.append((out.time, yaw))
            assert not backend.fall_status().fell, out.time
    finally:
        backend.close()
    peak = max(range(len(yaws)), key=lambda k: yaws[k][1])
    assert yaws[peak][1] > 5.0, yaws  # the push yawed them
    after = [yaw for _, yaw in yaws[peak:]]
    turning = [(a, b) for a, b in zip(after, after[1:], strict=False) if a > 1.0]
    assert len(after) >= 6 and all(b < a for a, b in turning), yaws
    assert after[5] < 2.0, yaws


@HONEST_PLANT_GAP("steps are adjusted (V_u at touchdown near gamma_v)")
def test_g1_walks_60_s_without_drifting_into_an_adjusted_step():
    """No slow drift (a lateral CoP bias, a turn) carries the DCM out of the window over
    60 s of nominal walking: no adjusted step at all, and in single support V_u well
    below gamma_v."""
    result, errors = run_g1(BUILT_IN["walk"], duration=60.0)
    assert not result.fall.fell, result.fall.reason
    assert len(errors) >= 70
    assert max(errors) < LANDING_TOLERANCE
    assert not any(s.event["adjusted"] for s in result.steps)
    # V_u crosses gamma_v only around the lift-off (s~ in 0.07-0.13 s, up to 1.7 gamma_v
    # measured, before the step can move): after it the error stays small.
    settled = result.column("time_since_step") > 0.15
    assert result.column("lyapunov")[settled].max() < 0.7 * result.lyapunov_threshold


@HONEST_PLANT_GAP("the stance CoP is 14 cm off the plan at a touchdown")
def test_the_stance_foots_measured_cop_follows_the_planned_one_on_the_walk():
    """In single support (after its first 0.15 s) the stance foot's measured CoP is where
    the stabilizer asked for it, through the feed-forward ankle torques: rms gap within 4
    mm sideways and 8 mm forward, far below the planned CoP's own excursion. The walk is
    pushed (12 N s forward at 2.9 s) so that the plan moves the CoP: unpushed, G1's planned
    CoP stays within 6 mm rms of its mean. Measured on 6 s: gaps 1.1 and 3.9 mm, the
    excursion 4.2 and 17.4 mm rms."""
    backend, config, initial = build_robot_backend("g1", "rsg", reality=MECHANISM_REALITY)
    push = Push(2.9, np.array([12.0, 0.0]), 0.1)
    scenario = dataclasses.replace(BUILT_IN["walk"], duration=6.0, pushes=(push,))
    loop = ClosedLoop(backend, config, scenario, initial)
    gaps, excursions = [], []
    try:
        for _ in range(round(scenario.duration / loop.period)):
            out = loop.tick()
            measured = backend.foot_pressure().get(out.stance.foot)
            if not out.double_support and out.time_since_step > 0.15 and measured is not None:
                gaps.append(backend.planned_cop - measured[0])
                excursions.append(backend.planned_cop - out.stance.position)
            assert not backend.fall_status().fell
    finally:
        backend.close()
    gap = np.sqrt(np.mean(np.square(gaps), axis=0))
    excursion = np.std(excursions, axis=0)
    assert gap[1] < 0.004 and gap[0] < 0.008, f"{gap=}"
    assert np.all(gap < 0.3 * excursion), f"{gap=} {excursion=}"


@HONEST_PLANT_GAP("u departs from the LIPM about the measured CoP")
@pytest.mark.parametrize("robot", ["g1", "talos"])
def test_the_momentum_velocity_moves_as_the_lipm_about_the_measured_cop(robot):
    """Over 6 s of walking, the momentum velocity u (the angular momentum about the CoP over m
    Z) changes within each 0.1 s as omega^2 (c - cop) of the measured CoP says, closer than
    the CoM velocity does: the limbs' swing moves the CoM velocity, not u
    (app/stabilizer/centroidal.py), and the planner reads u. Measured rms gaps (forward,
    sideways): G1 4 and 9 mm/s against the CoM velocity's 17 and 18; Talos 2 and 6 against
    18 and 11."""
    backend, config, initial = build_robot_backend(robot, "rsg", reality=MECHANISM_REALITY)
    scenario = dataclasses.replace(BUILT_IN["walk"], duration=6.0)
    loop = ClosedLoop(backend, config, scenario, initial)
    omega2 = config.model.omega**2
    rows = []
    try:
        for _ in range(round(scenario.duration / loop.period)):
            loop.tick()
            pressure = backend.foot_pressure().values()
            force = sum(normal for _, normal in pressure)
            cop = sum(point[:2] * normal for point, normal in pressure) / force
            controller = backend.controller
            com_velocity = controller.state.com_velocity[:2]
            u = momentum_velocity(
                com_velocity,
                controller.model.centroidal_angular_momentum()[:2],
                controller.mass,
                config.model.com_height,
                backend.description.rotational_height,
            )
            read = loop.measured.com_velocity
            np.testing.assert_array_equal(read, u)
            rows.append((*controller.state.com[:2], *u, *com_velocity, *cop))
            assert not backend.fall_status().fell
    finally:
        backend.close()
    rows = np.array(rows)
    window = round(0.1 / loop.period)
    expected = omega2 * (rows[:, 0:2] - rows[:, 6:8]) * loop.period
    change = np.vstack([np.zeros(2), np.cumsum(expected, axis=0)])  # sum of the first k
    lipm = change[window:-1] - change[: -window - 1]
    errors = {}
    for name, columns in (("u", slice(2, 4)), ("cdot", slice(4, 6))):
        # velocity at the end of each window minus at its start, against the LIPM's change
        gap = rows[window:, columns] - rows[:-window, columns] - lipm
        errors[name] = np.sqrt(np.mean(gap**2, axis=0))
    assert np.all(errors["u"] < 0.75 * errors["cdot"]), errors


def test_g1_recovers_paper_fig6_with_an_adjusted_step():
    """The paper's two pushes, scaled by the mass ratio (5.6 N s each; the first late in
    a left single support): recovered, with adjusted steps after the first push."""
    scenario = BUILT_IN["paper-fig6"]
    result, _ = run_g1(scenario)
    assert result.recovered, result.fall.reason
    first_push = scenario.pushes[0].time
    assert any(s.event["adjusted"] and s.event["t"] > first_push for s in result.steps)


def test_a_forward_push_is_recovered_with_an_adjusted_step():
    """8 N s forward over 0.1 s at mid single support (s~ = 0.45 s of the third step,
    the sweep's phase 0.5625). The RSG takes an adjusted step and is back to nominal
    steps with V_u below gamma_v within 4 s."""
    push = Push(2.75, np.array([8.0, 0.0]), 0.1)
    rsg, _ = run_g1(Scenario("push", 6.75, (push,), reference_mass=None))
    assert not rsg.fall.fell, rsg.fall.reason
    assert any(s.event["adjusted"] and s.event["t"] > push.time for s in rsg.steps)
    assert rsg.recovered


@HONEST_PLANT_GAP("G1 falls")
def test_the_net_force_holds_the_com_height_through_a_hard_forward_push():
    """34 N s forward early in single support (2.5 s): the long catching step lands ahead of
    a CoM moving at 1 m/s, and the new stance foot's moment is planned for the force it
    will carry because the net force holds the CoM height (``height_frequency``). The CoM
    rises at most 10 mm above its nominal height and sinks at most 20 mm below it, and G1
    recovers by 9 s (measured at 75eb0dd: 0.646-0.665 m, 2 adjusted steps; with the loop
    off 0.646-0.672 m). The push this test used before, 32 N s at 2.4 s, G1 no longer
    recovers with the loop since 75eb0dd (with the loop off it does, the CoM rising to
    0.679 m; docs/notes/2026-12-07-ik-at-the-legs-reach.md)."""
    push = Push(2.5, np.array([34.0, 0.0]), 0.1)
    heights: list[float] = []

    def height(out: PlannerOutput, backend: Any) -> None:
        if out.time > push.time:
            heights.append(float(backend.controller.state.com[2]))

    result, _ = run_g1(Scenario("push", 9.0, (push,), reference_mass=None), observe=height)
    assert result.recovered, result.fall.reason
    nominal = get_robot("g1").com_height
    assert max(heights) - nominal < 0.010, (min(heights), max(heights))
    assert nominal - min(heights) < 0.020, (min(heights), max(heights))


def test_a_catching_sole_that_carries_less_than_planned_stays_flat():
    """35.8 N s forward early in the right foot's single support: the left foot's catching
    step lands 0.35 m ahead of a CoM moving at 1 m/s and, over its first moments on the
    ground, carries less than the force it is planned for. Its ankle's moment is bounded
    by the force it carries (``within_sole_at_force``), so within 0.15 s of its touchdown
    the sole tilts less than 4 deg and its origin stays within 5 mm of the ground
    (measured: touchdown at 2.70 s, 1.2 deg and 1.6 mm below; with the moment of the
    planned force 6.9 deg and 12 mm: the ankle turned the foot onto its toe)."""
    push = Push(2.6, np.array([35.8, 0.0]), 0.1)
    touchdown: list[float] = []
    tilts: list[float] = []  # [deg] the left sole's, from its touchdown on
    heights: list[float] = []  # [m] its origin's

    def observe(out: PlannerOutput, backend: Any) -> None:
        if out.time < push.time + 0.1:
            return
        load = backend.foot_pressure().get("left", (None, 0.0))[1]
        if not touchdown and load > CONTACT_LOAD * backend.mass * GRAVITY:
            touchdown.append(out.time)
        if touchdown and out.time <= touchdown[0] + 0.15:
            position, rotation = backend.controller.model.sole_frame("left")
            tilts.append(float(np.degrees(np.arccos(min(rotation[2, 2], 1.0)))))
            heights.append(float(position[2]))

    run_g1(Scenario("push", push.time + 0.7, (push,), reference_mass=None), observe=observe)
    assert touchdown and 2.65 < touchdown[0] < 2.95, touchdown
    assert len(tilts) >= 14
    assert max(tilts) < 4.0, max(tilts)
    assert max(heights) < 0.005, max(heights)


@pytest.fixture(scope="module")
def issue_pushes():
    """The issue's pushes, run as ``rsg grid --impulses 10 --controllers rsg,no-step`` runs
    them: 10 N s over 0.1 s at mid single support (phase 0.5625), 8 directions, 8 s to
    settle. Returns {controller: {direction [deg]: record}}. (Single outcomes on G1 are
    sensitive to round-off: the same push built another way can end otherwise; the
    grid's own jobs are what the README reports.)"""
    spec = GridSpec(controllers=("rsg", "no-step"), impulses=(10.0,), directions=8)
    records = run_grid(spec, workers=2, progress=False)
    by_controller: dict[str, dict[float, dict]] = {"rsg": {}, "no-step": {}}
    for record in records:
        by_controller[record["controller"]][record["direction_deg"]] = record
    return by_controller


def test_10_n_s_at_mid_single_support_topples_no_step_and_the_rsg_recovers_most(issue_pushes):
    """no-step falls after at least half of the 8 pushes; the RSG recovers, with
    adjusted steps, at least 5 of them and every push no-step recovers."""
    rsg, no_step = issue_pushes["rsg"], issue_pushes["no-step"]
    assert sum(r["outcome"] == "fell" for r in no_step.values()) >= 4
    recovered = [d for d, r in rsg.items() if r["outcome"] == "recovered"]
    assert len(recovered) >= 5, {d: (r["outcome"], r["fall_reason"]) for d, r in rsg.items()}
    assert all(rsg[d]["adjusted_steps"] > 0 for d in recovered)
    assert all(d in recovered for d, r in no_step.items() if r["outcome"] == "recovered")


def test_10_n_s_at_mid_single_support_is_recovered_in_every_direction(issue_pushes):
    """The issue's requirement (the random campaign, not this fixed set, is what
    options are chosen on)."""
    rsg = issue_pushes["rsg"]
    assert all(r["outcome"] == "recovered" for r in rsg.values()), {
        d: r["outcome"] for d, r in rsg.items()
    }
