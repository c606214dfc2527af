"""The reactive step generator in closed loop with the LIPM: the paper's claims.

Why one long module: the claims of Sections IV and V are checked on the same closed loop
and share its fixtures; :mod:`planner.step_generator` is one module too.
"""

from dataclasses import replace

import numpy as np
import pytest

from app.runner import walking_start
from app.scenarios import BUILT_IN, Scenario
from app.setup.paper_rules import paper_rules
from conftest import run_lipm, scaled
from planner.hybrid_lipm import integrate_lipm
from planner.parameters import PlannerConfig
from planner.step_generator import ReactiveStepGenerator
from planner.types import Foothold, MeasuredState, Push

FIG6 = BUILT_IN["paper-fig6"]


def adjusted_between(result, start, end):
    return [s for s in result.steps if start <= s.event["t"] < end and s.event["adjusted"]]


def test_nominal_walk_is_periodic_and_never_adjusted():
    result = run_lipm("rsg", BUILT_IN["walk"])
    assert result.recovered
    assert not any(s.event["adjusted"] for s in result.steps)
    times = np.array([s.event["t"] for s in result.steps])
    np.testing.assert_allclose(np.diff(times), 0.8, atol=0.003)
    steps = np.array([s.step for s in result.steps])
    np.testing.assert_allclose(steps[:, 0], 0.2, atol=0.003)
    np.testing.assert_allclose(np.abs(steps[:, 1]), 0.2, atol=0.003)
    assert result.max_lyapunov < result.lyapunov_threshold


def test_paper_fig6_with_rsg(fig6_runs):
    """Recovered; adjusted step(s) after push 1; none after push 2; no violation."""
    result = fig6_runs["rsg"]
    first, second = (p.time for p in FIG6.pushes)
    assert result.recovered, result.fall
    assert len(adjusted_between(result, first, second)) >= 1
    assert adjusted_between(result, second, 1e9) == []
    assert result.constraint_violations == 0, result.violations
    assert result.qp_infeasible == 0
    window = result.column("t") >= second
    assert result.column("lyapunov")[window].max() < result.lyapunov_threshold


@pytest.mark.parametrize("factor", [3.0])
def test_pushes_that_topple_no_step_are_recovered_by_rsg(factor):
    scenario = scaled(FIG6, factor)
    no_step = run_lipm("no-step", scenario)
    rsg = run_lipm("rsg", scenario)
    assert no_step.fall.fell, f"{factor=}: no-step should fall"
    assert rsg.recovered, f"{factor=}: {rsg.fall}"
    assert rsg.violations["crossing"] == 0 and rsg.violations["step_bounds"] == 0


FORWARD_PUSH = Scenario("forward", 8.0, (Push(3.0, np.array([120.0, 0.0]), 0.1),))


@pytest.mark.parametrize(
    "scenario",
    [scaled(FIG6, 1.0), scaled(FIG6, 2.0), scaled(FIG6, 3.0), FORWARD_PUSH],
    ids=lambda s: s.name,
)
def test_post_step_level_decreases_in_case_a(scenario):
    """(24): in Case (a) (previous post-step level >= gamma_v) each adjusted step lowers
    the post-step level by at least gamma_v. Pushes away from the stance side, where
    (27b) does not block the step (25) asks for; the forward push needs two adjusted
    steps, the first leaving V_u above gamma_v."""
    from app.backends.lipm import LipmBackend
    from app.runner import run_closed_loop

    config = PlannerConfig()
    # The sweep's fall rule: the DCM error rule of 0.5 m ends the forward push at once.
    backend = LipmBackend(config.model, fall_dcm_error=2.0)
    result = run_closed_loop(backend, config, scenario, qp_solver="exact")
    gamma = result.lyapunov_threshold
    previous_post = 0.0
    checked = []
    for step in result.steps:
        event = step.event
        if event["adjusted"] and previous_post >= gamma:
            post = event["lyapunov_after"]
            assert post <= previous_post - gamma + 1e-9, f"{scenario.name} {event=}"
            checked.append(post)
        previous_post = event["lyapunov_after"]
    assert result.recovered, result.fall
    if scenario is FORWARD_PUSH:
        assert len(checked) >= 2 and checked[0] >= gamma, checked


def _on_left_foot(config, time_since_step, qp_solver="proxqp"):
    """A generator standing on the left foot (the right one behind) at s~ =
    ``time_since_step`` [s]."""
    gen = ReactiveStepGenerator(config, qp_solver=qp_solver)
    gen.reset(
        Foothold("left", np.array([0.0, 0.1])),
        Foothold("right", np.array([-0.2, -0.1])),
        time_since_step=time_since_step,
    )
    return gen


def _generator_at(config, time_since_step, error, lateral=None):
    """A generator on the left foot at s~ = ``time_since_step`` and the measured state
    with DCM error ``error`` [m] (and the CoM ``lateral`` [m] left of the ankle)."""
    gen = _on_left_foot(config, time_since_step, qp_solver="exact")
    com_offset = gen.reference.xi1.copy()
    if lateral is not None:
        com_offset[1] = lateral
    velocity = (gen.reference.dcm() + error - com_offset) * gen.omega
    return gen, MeasuredState(0.0, gen.stance + com_offset, velocity)


def _level_error(gen, level):
    """A DCM error along x with V_u = ``level``."""
    unit = np.array([1.0, 0.0])
    return unit * np.sqrt(level / gen.design.level(unit))


def test_dt1_needs_the_level_to_have_risen_since_the_last_step():
    """D_T,1 = {V_u >= gamma_v and V_u - V_u^dagger >= -gamma_v + mu_1}: with the swing
    foot ready and V_u = 2 gamma_v, no timing jump while V_u^dagger = 1.5 gamma_v
    (V_u - V_u^dagger = 0.5 gamma_v < -gamma_v + mu_1 = gamma_v); one when it is
    0.5 gamma_v."""
    config = paper_rules(PlannerConfig())
    gamma = config.rsg.lyapunov_threshold
    for dagger, jumps in ((1.5 * gamma, False), (0.5 * gamma, True)):
        gen, _ = _generator_at(config, 0.35, np.zeros(2))
        gen, measured = _generator_at(config, 0.35, _level_error(gen, 2.0 * gamma))
        gen.lyapunov_at_step = dagger
        out = gen.update(measured, 0.001)
        assert (out.step is not None) == jumps, f"{dagger=}"
        if jumps:
            assert out.step.timing_adjusted and out.step.location_adjusted
            assert out.step.lyapunov_before == pytest.approx(2.0 * gamma)
        else:
            assert out.lyapunov == pytest.approx(2.0 * gamma)


def test_dt2_steps_when_the_com_passes_the_outer_edge_with_hnu_2xi1_below_gamma():
    """D_T,2: the CoM 8 cm outside the left ankle (w_y = 7 cm), V_u = 0 < gamma_v, the
    swing foot ready: a timing jump. The paper's H_nu (--paper-rules) steps 2 xi1*;
    with ``qp_at_timing_jump`` the QP (27) places the step. Not before the swing foot
    is ready (s~ < T_DSP + T_SP)."""
    paper = paper_rules(PlannerConfig())
    extended = replace(paper, rsg=replace(paper.rsg, qp_at_timing_jump=True))
    for config, from_qp in ((paper, False), (extended, True)):
        gen, measured = _generator_at(config, 0.35, np.zeros(2), lateral=0.08)
        stance, nominal = gen.stance.copy(), gen.reference.nominal_step()
        out = gen.update(measured, 0.001)
        assert out.step is not None and out.step.timing_adjusted
        assert out.step.lyapunov_before < config.rsg.lyapunov_threshold
        step = out.stance.position - stance
        assert out.step.location_adjusted == from_qp
        if from_qp:
            assert np.linalg.norm(step - nominal) > 0.01
        else:
            np.testing.assert_allclose(step, nominal, atol=1e-12)
    gen, measured = _generator_at(paper, 0.25, np.zeros(2), lateral=0.08)
    assert gen.update(measured, 0.001).step is None


def test_jump_19b_and_nominal_location():
    """At each step e_u^+ = e_u - u_d + 2 xi1*; u_d = 2 xi1* when V_u < gamma_v."""
    config = PlannerConfig()
    gen = _on_left_foot(config, 0.79)
    com, velocity = gen.initial_com_state()
    velocity = velocity + np.array([0.004, -0.002])  # a small DCM error, V_u < gamma_v
    xi = np.r_[com - gen.stance, velocity]
    error_before = gen.dcm_error(xi)
    reference_xi1 = gen.reference.xi1.copy()
    stance_before = gen.stance.copy()
    dt = 0.001
    for k in range(40):
        out = gen.update(MeasuredState(k * dt, com, velocity), dt)
        if out.step is not None:
            break
        com = com + velocity * dt
        xi = np.r_[com - gen.stance, velocity]
        error_before, reference_xi1, stance_before = (
            gen.dcm_error(xi),
            gen.reference.xi1.copy(),
            gen.stance.copy(),
        )
    assert out.step is not None and not out.step.adjusted
    u_d = out.stance.position - stance_before
    np.testing.assert_allclose(u_d, 2 * reference_xi1, atol=1e-12)
    np.testing.assert_allclose(out.dcm_error, error_before - u_d + 2 * reference_xi1, atol=1e-9)


def _nominal_jump(config: PlannerConfig, kick_at: int | None):
    """Ticks of 1 ms up to a nominal jump from 10 ms before it, the measured CoM velocity
    kicked at tick ``kick_at``; the jump's output, its tick and the next step the tick
    before announced."""
    gen = _on_left_foot(config, 0.79)
    com, velocity = gen.initial_com_state()
    dt, announced = 0.001, None
    for k in range(40):
        kick = np.array([0.2, -0.1]) if k == kick_at else np.zeros(2)  # [m/s]
        out = gen.update(MeasuredState(k * dt, com, velocity + kick), dt)
        if out.step is not None:
            return out, k, announced
        announced = out.next_step.position.copy()
        com = com + velocity * dt
    raise AssertionError("no step within 40 ms")


def test_a_nominal_step_lands_where_the_swing_foot_was_sent():
    """A DCM error above gamma_v that shows only at the tick of a nominal jump (D_S), as
    a robot's touchdown makes it: with ``announced_foothold`` the step is the foothold
    announced at the tick before (2 xi1*, not adjusted); the paper's H_nu (False) puts it
    where the QP (27) says at the jump's own state."""
    for flag in (True, False):
        config = PlannerConfig()
        config = replace(config, rsg=replace(config.rsg, announced_foothold=flag))
        _, tick, _ = _nominal_jump(config, None)
        out, kicked_tick, announced = _nominal_jump(config, tick)
        assert kicked_tick == tick
        assert out.step.lyapunov_before > config.rsg.lyapunov_threshold
        if flag:
            np.testing.assert_allclose(out.stance.position, announced, atol=1e-12)
            assert not out.step.adjusted
        else:
            assert np.linalg.norm(out.stance.position - announced) > 0.005
            assert out.step.location_adjusted


def test_same_run_twice_is_identical(fig6_runs):
    again = run_lipm("rsg", FIG6)
    np.testing.assert_array_equal(again.timeseries, fig6_runs["rsg"].timeseries)


def test_exact_qp_solver_gives_the_same_run(fig6_runs):
    exact = run_lipm("rsg", scaled(FIG6, 2.0), qp_solver="exact")
    proxqp = run_lipm("rsg", scaled(FIG6, 2.0), qp_solver="proxqp")
    a = [s.event["position"] for s in exact.steps]
    b = [s.event["position"] for s in proxqp.steps]
    np.testing.assert_allclose(a, b, atol=1e-5)


def test_comparison_controllers_respect_their_rules(fig6_runs):
    for name in ("fixed-timing", "no-step"):
        result = fig6_runs[name]
        assert not any(s.event["timing_adjusted"] for s in result.steps), name
        times = np.array([s.event["t"] for s in result.steps])
        np.testing.assert_allclose(np.diff(times), 0.8, atol=0.003, err_msg=name)
    assert not any(s.event["location_adjusted"] for s in fig6_runs["no-step"].steps)
    assert any(s.event["location_adjusted"] for s in fig6_runs["fixed-timing"].steps)


def test_zmp_stays_in_its_window_and_feet_never_cross(fig6_runs):
    for name, result in fig6_runs.items():
        assert result.violations["zmp_window"] == 0, name
        assert result.violations["crossing"] == 0, name
        sigma = result.column("stance_sigma")
        foot_y = result.column("foot_y")
        changes = np.flatnonzero(np.diff(sigma) != 0) + 1
        for k in changes:  # the new stance foot is on its own side of the old one
            assert sigma[k] * (foot_y[k] - foot_y[k - 1]) > 0, (name, k)


def test_predicted_step_time_and_location_match_the_step_taken():
    """In nominal walking the preview (next_step, next_step_time) is where and when the
    planner actually steps, from anywhere in the cycle (the swing foot relies on it)."""
    config = PlannerConfig()
    initial = walking_start(config)
    generator = ReactiveStepGenerator(config)
    generator.reset(initial.stance, initial.swing)
    com, velocity = initial.com_position, initial.com_velocity
    dt, checked, predictions = 0.001, 0, []
    for k in range(int(3.0 / dt)):
        out = generator.update(MeasuredState(k * dt, com, velocity), dt)
        if out.step is not None:
            for when, where in predictions:
                assert abs(when - out.step.time) <= 2 * dt, f"{when=} {out.step.time=}"
                np.testing.assert_allclose(where, out.step.position, atol=2e-3)
                checked += 1
            predictions = []
        elif k % 50 == 0:
            predictions.append((out.next_step_time, out.next_step.position))
        com, velocity = integrate_lipm(
            config.model, com, velocity, out.zmp, out.angular_momentum_rate, np.zeros(2), dt
        )
    assert checked > 20


def _walk_with_push(config, push_start, force, duration, until, swing_contact=None):
    """Drive the generator on the exact LIPM with a constant push; returns its outputs.
    ``swing_contact(t)``, if given, is reported in single support (None in double)."""
    initial = walking_start(config)
    generator = ReactiveStepGenerator(config)
    generator.reset(initial.stance, initial.swing)
    com, velocity = initial.com_position, initial.com_velocity
    dt, outputs, estimates = 0.001, [], []
    for k in range(int(until / dt)):
        t = k * dt
        contact = None
        if swing_contact is not None and outputs and not outputs[-1].double_support:
            contact = swing_contact(t)
        out = generator.update(MeasuredState(t, com, velocity, swing_contact=contact), dt)
        outputs.append(out)
        estimates.append(generator.push_estimate.copy())
        pushed = push_start - 1e-9 <= t < push_start + duration - 1e-9
        f = np.asarray(force) if pushed else np.zeros(2)
        com, velocity = integrate_lipm(
            config.model, com, velocity, out.zmp, out.angular_momentum_rate, f, dt
        )
    return outputs, np.array(estimates)


def test_push_estimate_is_exact_on_the_lipm():
    """f c_z / (m g) from two measured DCMs and the commanded CMP, one tick late."""
    config = PlannerConfig()
    force = np.array([900.0, 400.0])
    outputs, estimates = _walk_with_push(config, 2.7, force, 0.1, 3.2)
    times = np.array([o.time for o in outputs])
    expected = force * config.model.com_height / (config.model.mass * config.model.gravity)
    during = (times > 2.7 + 0.0015) & (times < 2.8 - 1e-6)
    np.testing.assert_allclose(estimates[during], np.tile(expected, (during.sum(), 1)), atol=1e-6)
    quiet = (times > 0.01) & ((times < 2.7) | (times > 2.8 + 0.0015))
    assert np.abs(estimates[quiet]).max() < 1e-6


@pytest.mark.parametrize("hold", [0.15, 0.0])
def test_first_step_waits_for_the_end_of_the_push(hold):
    """Phase 0.5 (s~ = 0.4 s > T_DSP + T_SP): with the push hold the adjusted step
    comes when the push ends and lands far; with hold 0 (the paper's D_T) it comes
    ~10 ms into the push with a small step from the still-small DCM error."""
    config = PlannerConfig(rsg=replace(PlannerConfig().rsg, push_hold_time=hold))
    outputs, _ = _walk_with_push(config, 2.7, np.array([1000.0, 0.0]), 0.1, 3.0)
    first = next(o.step for o in outputs if o.step is not None and o.time >= 2.7)
    assert first.timing_adjusted and first.location_adjusted
    step_x = first.position[0] - outputs[2699].stance.position[0]
    if hold > 0.0:
        assert 2.8 <= first.time <= 2.803
        assert step_x > 0.5
    else:
        assert first.time < 2.73
        assert step_x < 0.15


def test_push_hold_is_bounded_by_its_time():
    """A push that lasts longer than push_hold_time does not keep the step back."""
    config = PlannerConfig()
    outputs, _ = _walk_with_push(config, 2.7, np.array([300.0, 0.0]), 1.0, 3.2)
    first = next(o.step for o in outputs if o.step is not None and o.time >= 2.7)
    assert first.time <= 2.7 + config.rsg.push_hold_time + 0.003


def test_paper_rules_give_the_papers_jump_set_on_fig6():
    """--paper-rules: no push hold, no leg reach; paper-fig6 is recovered with the
    adjusted step while push 1 still acts (V_u reaches gamma_v), the default steps at
    its end."""
    from app.backends.lipm import LipmBackend
    from app.runner import run_closed_loop
    from app.setup.build import build_backend

    _, config, _ = build_backend("lipm", None, "rsg", paper=True)
    assert config.rsg.push_hold_time == 0.0 and config.constraints.com_reach == np.inf
    paper = run_closed_loop(LipmBackend(config.model), config, FIG6, qp_solver="exact")
    default = run_lipm("rsg", FIG6, qp_solver="exact")
    push = FIG6.pushes[0]
    for result, inside in ((paper, True), (default, False)):
        assert result.recovered, result.fall
        steps = adjusted_between(result, push.time, FIG6.pushes[1].time)
        assert len(steps) >= 1
        assert (steps[0].event["t"] < push.time + push.duration) == inside


def _reaction_config(reaction_time, **rsg):
    base = PlannerConfig()
    return replace(
        base,
        rsg=replace(base.rsg, step_reaction_time=reaction_time, push_hold_time=0.0, **rsg),
    )


def test_step_reaction_time_schedules_the_step_and_lands_where_announced():
    """With a reaction time Delta the timing jump comes Delta after D_T fires (not
    at once), keeps the time it announced, and lands on the last announced foothold;
    while it waits the foothold converges (the QP at the predicted touchdown state)."""
    reaction = 0.1
    outputs, _ = _walk_with_push(_reaction_config(reaction), 2.7, np.array([0.0, 600.0]), 0.1, 3.2)
    instant, _ = _walk_with_push(_reaction_config(0.0), 2.7, np.array([0.0, 600.0]), 0.1, 3.2)
    decided = next(o for o in instant if o.time >= 2.7 and o.step is not None).time
    index = next(k for k, o in enumerate(outputs) if o.time >= 2.7 and o.step is not None)
    step = outputs[index].step
    assert step.timing_adjusted and step.location_adjusted
    assert step.time == pytest.approx(decided + reaction, abs=2e-3)
    before = outputs[index - 1]
    assert before.next_step_time == pytest.approx(step.time, abs=2e-3)
    np.testing.assert_allclose(before.next_step.position, step.position, atol=1e-12)
    waiting = [o for o in outputs[index - 90 : index] if o.time > decided + 0.01]
    assert all(o.next_step_time == pytest.approx(step.time, abs=2e-3) for o in waiting)
    drift = [np.linalg.norm(o.next_step.position - step.position) for o in waiting]
    assert drift[-1] < 1e-3 and drift[-1] <= drift[0]


def test_a_timing_jump_never_postpones_the_nominal_step():
    """A push 0.1 s before a nominal touchdown with a 0.2 s reaction time: D_T fires,
    and the step still comes at the nominal time (not 0.2 s after the decision), with
    the QP's foothold, and that time is what was announced."""
    reaction = 0.2
    config = _reaction_config(reaction)
    quiet, _ = _walk_with_push(config, 10.0, np.zeros(2), 0.1, 3.2)
    nominal = [o.step.time for o in quiet if o.step is not None and o.time > 1.5][0]
    push = nominal - 0.1
    outputs, _ = _walk_with_push(config, push, np.array([0.0, 900.0]), 0.05, 3.2)
    index = next(k for k, o in enumerate(outputs) if o.time >= push and o.step is not None)
    step = outputs[index].step
    assert step.time == pytest.approx(nominal, abs=2e-3)
    assert step.location_adjusted
    decided = [o for o in outputs[index - 100 : index] if o.lyapunov >= 0.0015]
    assert decided and decided[0].time < nominal - 0.03  # decided with < 0.2 s to go
    assert outputs[index - 1].next_step_time == pytest.approx(step.time, abs=2e-3)


def test_step_reaction_time_recovers_what_the_instant_step_recovers():
    """On the LIPM a 0.1 s reaction time still recovers paper-fig6 scaled x2."""
    from app.backends.lipm import LipmBackend
    from app.runner import run_closed_loop

    config = _reaction_config(0.1)
    result = run_closed_loop(LipmBackend(config.model), config, scaled(FIG6, 2.0))
    assert result.recovered, result.fall
    assert any(s.event["timing_adjusted"] for s in result.steps)
    assert result.violations["crossing"] == 0 and result.violations["step_bounds"] == 0


def test_step_reaction_time_is_validated():
    from planner.exceptions import ParameterError

    with pytest.raises(ParameterError, match="step_reaction_time"):
        _reaction_config(-0.1)


def test_a_timing_jump_comes_at_a_touchdown_before_its_time():
    """A swing sole that lands 30 ms before its scheduled timing jump: the jump comes at
    that touchdown, onto the announced foothold; a contact before the landing window
    (``touchdown_window``, 0.1 s), without a lift-off seen first (a sole still on the
    ground) or for a step at the nominal time brings nothing forward."""
    config = _reaction_config(0.1, touchdown_window=0.1)
    push = (2.7, np.array([0.0, 600.0]), 0.1, 3.2)
    on_time, _ = _walk_with_push(config, *push)
    index = next(k for k, o in enumerate(on_time) if o.time >= 2.7 and o.step is not None)
    scheduled = on_time[index].step.time
    assert on_time[index].step.timing_adjusted
    landing = scheduled - 0.03
    early, _ = _walk_with_push(
        config, *push, swing_contact=lambda t: t < 2.7 or t >= landing - 1e-9
    )
    index = next(k for k, o in enumerate(early) if o.time >= 2.7 and o.step is not None)
    step = early[index].step
    assert step.time == pytest.approx(landing, abs=1.5e-3)
    assert step.timing_adjusted and step.location_adjusted
    np.testing.assert_allclose(step.position, early[index - 1].next_step.position, atol=1e-12)
    # With a 0.2 s reaction time, a brief contact 0.15 s before the step (a scrape,
    # before the landing window): the step keeps its time.
    slow = _reaction_config(0.2, touchdown_window=0.1)
    quiet, _ = _walk_with_push(slow, *push)
    due = next(o.step.time for o in quiet if o.time >= 2.7 and o.step is not None)
    scraped, _ = _walk_with_push(
        slow, *push, swing_contact=lambda t: t < 2.7 or 0.0 <= due - 0.15 - t < 0.01 or t >= due
    )
    index = next(k for k, o in enumerate(scraped) if o.time >= 2.7 and o.step is not None)
    assert scraped[index].step.time == pytest.approx(due, abs=1.5e-3)
    # Touching from the swing's start on (never lifted): the step keeps its time.
    dragged, _ = _walk_with_push(config, *push, swing_contact=lambda t: True)
    index = next(k for k, o in enumerate(dragged) if o.time >= 2.7 and o.step is not None)
    assert dragged[index].step.time == pytest.approx(scheduled, abs=1.5e-3)
    # A timing jump at the nominal step's time (decided 0.1 s before it): it waits for
    # the reference's own jump, touchdown or not.
    config = _reaction_config(0.2, touchdown_window=0.1)
    quiet, _ = _walk_with_push(config, 10.0, np.zeros(2), 0.1, 3.2)
    nominal = [o.step.time for o in quiet if o.step is not None and o.time > 1.5][0]
    push = (nominal - 0.1, np.array([0.0, 900.0]), 0.05, 3.2)
    landing = nominal - 0.03
    touching, _ = _walk_with_push(
        config, *push, swing_contact=lambda t: t < nominal - 0.1 or t >= landing - 1e-9
    )
    index = next(k for k, o in enumerate(touching) if o.time >= push[0] and o.step is not None)
    assert touching[index].step.location_adjusted
    assert touching[index].step.time == pytest.approx(nominal, abs=2e-3)


def test_a_due_jump_waits_for_the_swing_sole_to_touch_down():
    """MeasuredState.swing_contact False when the nominal jump is due: no jump, the
    foothold and the step time stay announced (now); at the touchdown the jump comes
    onto that foothold, still a nominal step; with None the planner steps on time."""
    config = PlannerConfig()

    def walk(contact):
        gen = ReactiveStepGenerator(config)
        gen.reset(Foothold("left", np.array([0.0, 0.1])), Foothold("right", np.array([-0.2, -0.1])))
        time, announced = 0.0, (np.zeros(2), 0.0)
        for _ in range(200):  # the nominal walk: the measured state is the reference's
            com, velocity = gen.initial_com_state()
            out = gen.update(MeasuredState(time, com, velocity, swing_contact=contact(time)), 0.01)
            if out.step is not None:
                return out, announced
            announced = (out.next_step.position.copy(), out.next_step_time)
            time = round(time + 0.01, 9)
        raise AssertionError("no step in 2 s")

    on_time, _ = walk(lambda time: None)
    step_time = on_time.step.time
    late, (foothold, announced_time) = walk(lambda time: time >= step_time + 0.05)
    assert late.step.time == pytest.approx(step_time + 0.05)
    assert announced_time == pytest.approx(step_time + 0.04)  # "now", while it waits
    np.testing.assert_allclose(late.stance.position, foothold)
    np.testing.assert_allclose(late.stance.position, on_time.stance.position, atol=1e-9)
    assert not late.step.timing_adjusted and not late.step.location_adjusted
    # A sole that touched before the step time and lifts again: contact is no early jump.
    in_air, _ = walk(lambda time: time >= step_time + 0.05 or time < step_time)
    assert in_air.step.time == pytest.approx(step_time + 0.05)


def test_a_measured_stance_sole_moves_the_foothold_in_single_support_only():
    """MeasuredState.stance_sole re-anchors o_H where the stance sole stands: the ZMP
    window and the DCM error then refer to it (e_u moves by the anchor's shift); in
    the double support it is ignored."""
    config = PlannerConfig()
    gen = ReactiveStepGenerator(config)
    planned = np.array([0.0, 0.1])
    gen.reset(
        Foothold("left", planned),
        Foothold("right", np.array([-0.2, -0.1])),
        time_since_step=0.05,  # double support
    )
    measured_sole = np.array([0.012, 0.093])
    com, velocity = gen.initial_com_state()
    out = gen.update(MeasuredState(0.0, com, velocity, stance_sole=measured_sole), 0.01)
    np.testing.assert_allclose(out.stance.position, planned)
    gen.time_since_step = 0.3  # single support
    com, velocity = gen.initial_com_state()
    expected = gen.dcm_error(np.r_[com - planned, velocity]) - (measured_sole - planned)
    out = gen.update(MeasuredState(0.01, com, velocity, stance_sole=measured_sole), 0.01)
    assert out.step is None
    np.testing.assert_allclose(out.stance.position, measured_sole)
    np.testing.assert_allclose(out.window_center, measured_sole)
    np.testing.assert_allclose(out.dcm_error, expected, atol=1e-9)


def test_a_measured_stance_sole_is_approached_with_the_reanchor_time_constant():
    """With ``reanchor_time`` tau, o_H moves towards the measured sole by period / tau of
    the gap per tick (the DCM error with it), reaches it, and a step before then leaves
    the sole of the old stance foot behind."""
    config = PlannerConfig()
    config = replace(config, rsg=replace(config.rsg, reanchor_time=0.1))
    gen = ReactiveStepGenerator(config)
    planned = np.array([0.0, 0.1])
    gen.reset(Foothold("left", planned), Foothold("right", np.array([-0.2, -0.1])), 0.15)
    measured_sole = np.array([0.012, 0.093])
    com, velocity = gen.initial_com_state()
    first = planned + 0.1 * (measured_sole - planned)
    expected = gen.dcm_error(np.r_[com - planned, velocity]) - (first - planned)
    out = gen.update(MeasuredState(0.0, com, velocity, stance_sole=measured_sole), 0.01)
    np.testing.assert_allclose(out.stance.position, first, atol=1e-12)
    np.testing.assert_allclose(out.window_center, first, atol=1e-12)
    np.testing.assert_allclose(out.dcm_error, expected, atol=1e-12)
    for tick in range(1, 60):
        com, velocity = gen.initial_com_state()  # on the reference: no DCM error
        out = gen.update(MeasuredState(0.01 * tick, com, velocity), 0.01)
        if np.array_equal(out.stance.position, measured_sole) or out.step is not None:
            break
    assert out.step is None
    np.testing.assert_array_equal(out.stance.position, measured_sole)
    # A pending re-anchoring ends at a step: the new stance foot is where it stepped.
    gen.reset(Foothold("left", planned), Foothold("right", np.array([-0.2, -0.1])), 0.78)
    com, velocity = gen.initial_com_state()
    gen.update(MeasuredState(0.0, com, velocity, stance_sole=measured_sole), 0.01)
    stepped = None
    for tick in range(1, 10):
        com, velocity = gen.initial_com_state()
        out = gen.update(MeasuredState(0.01 * tick, com, velocity), 0.01)
        if out.step is not None:
            stepped = out
            break
    assert stepped is not None
    next_out = gen.update(MeasuredState(0.1, com, velocity), 0.01)
    np.testing.assert_array_equal(next_out.stance.position, stepped.stance.position)


def _g1_outward_step(preview_at_touchdown: bool):
    """G1's planner on the LIPM, pushed 8.9 N s towards its stance side early in the
    single support: a step beside the stance foot (27b), then the stance foot's outward
    step. Returns the outward step and the next steps previewed from its swing's start."""
    from app.setup.robot_config import planner_config_for
    from robots.g1 import G1

    config = planner_config_for(G1, G1.total_mass)
    config = replace(config, rsg=replace(config.rsg, preview_at_touchdown=preview_at_touchdown))
    force = np.array([-1.4155, 8.8374]) / 0.057  # [N] over 57 ms
    outputs, _ = _walk_with_push(config, 3.1408, force, 0.057, 4.2)
    steps = [k for k, o in enumerate(outputs) if o.step is not None and o.time > 3.1408]
    first, second = steps[0], steps[1]
    lift_off = first + round(config.gait.double_support_duration / 0.001)
    return outputs[second].step, [o.next_step.position for o in outputs[lift_off:second]]


def test_the_swing_foot_is_sent_where_a_pushed_step_lands():
    """preview_at_touchdown: while V_u >= gamma_v the next step is the QP (27) at the
    state predicted when the step is expected, so the foot that must step outwards after
    a crossing step is sent there from its lift-off; at the current state (False) the
    foothold is 0.3 m short until the timing jump is decided."""
    step, previews = _g1_outward_step(True)
    assert step.location_adjusted and step.position[1] > 0.5  # [m] outward, to the left
    errors = np.linalg.norm(np.array(previews) - step.position, axis=1)
    assert errors.max() < 0.01, errors.max()
    step, previews = _g1_outward_step(False)
    assert np.linalg.norm(previews[0] - step.position) > 0.2
