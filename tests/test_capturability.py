"""The capture bound: Koolen's closed forms, exactness where the relaxations are exact, and
an upper limit for a strong stepping policy simulated on the LIPM with the same limits."""

from __future__ import annotations

import math
from dataclasses import replace
from functools import cache

import numpy as np
import pytest

from app.backends.lipm import LEG_REACH
from app.experiments.capturability import CaptureModel, capture_distance, capture_edges
from app.experiments.capture_bound import impulse_bound, nominal_state
from app.experiments.capture_lp import PushCase, largest_impulse
from planner.exceptions import ParameterError
from planner.hybrid_lipm import dcm, integrate_lipm
from planner.parameters import PlannerConfig
from planner.reference_model import NominalOrbit

CONFIG = PlannerConfig()
MODEL = CaptureModel.from_config(CONFIG)
PERIOD = CONFIG.gait.step_duration  # T^*
DURATION = 0.1  # [s] the sweep's push
SIGMA = -1  # the sweep's cycle 3 is on the right foot


def kappa(omega: float, duration: float) -> float:
    """DCM jump per i / (m omega) of a push over ``duration`` (for times after it)."""
    return (1.0 - math.exp(-omega * duration)) / (omega * duration)


def test_capture_distance_closed_forms() -> None:
    omega, t, l_max, r_max = 3.5, 0.3, 0.6, 0.12
    assert capture_distance(0, l_max, r_max, omega, t) == pytest.approx(r_max)
    decay = math.exp(-omega * t)
    assert capture_distance(1, l_max, r_max, omega, t) == pytest.approx(l_max * decay + r_max)
    distances = [capture_distance(n, l_max, r_max, omega, t) for n in range(12)]
    assert np.all(np.diff(distances) > 0.0)
    limit = capture_distance(math.inf, l_max, r_max, omega, t)
    assert limit == pytest.approx(r_max + l_max * decay / (1.0 - decay))
    assert distances[-1] == pytest.approx(limit, rel=1e-4)


def test_forward_edge_is_koolens_d_inf_plus_the_step_taken_now() -> None:
    edges = capture_edges(MODEL)
    l_max, t_min = MODEL.step_max[0], MODEL.min_step_time
    d_inf = capture_distance(math.inf, l_max, MODEL.cmp_max[0], MODEL.omega, t_min)
    for sigma in (1, -1):
        assert edges.upper[0][sigma] == pytest.approx(l_max + d_inf, rel=1e-12)
        assert edges.interval(0, sigma)[1] == pytest.approx(l_max + d_inf, rel=1e-12)


def test_crossing_rule_makes_the_stance_side_narrow_and_the_feet_mirror() -> None:
    edges = capture_edges(MODEL)
    # Right stance: the left foot steps, at least 2 w_y + mu_2 to the left.
    right_side, left_side = edges.interval(1, -1)
    assert -right_side < 0.5 * left_side
    assert edges.lower[1][1] == pytest.approx(-edges.upper[1][-1])
    assert edges.upper[1][1] == pytest.approx(-edges.lower[1][-1])
    # Left stance, a DCM to the left: the right foot must step right first. In double
    # support the CMP may stay at the old foot, which makes up part of that step.
    hull = 1.0 - math.exp(-MODEL.omega * MODEL.double_support_duration)
    decay = math.exp(-MODEL.omega * MODEL.min_step_time)
    step, r_max = MODEL.min_lateral_step, MODEL.cmp_max[1]
    expected = -step + step * hull + r_max + max(0.0, edges.upper[1][-1] - r_max) * decay
    assert edges.upper[1][1] == pytest.approx(expected, rel=1e-12)


def test_bound_is_the_closed_form_where_the_relaxations_are_exact() -> None:
    """A forward push at the step (phase 0): one axis, the reach not binding, the first
    step T_min after the push start. The programme must give the 1-D optimum."""
    omega, mass, t_min = MODEL.omega, MODEL.mass, MODEL.min_step_time
    edges = capture_edges(MODEL)
    state = nominal_state(CONFIG, SIGMA, 0.0)
    x0 = state[0] + state[2] / omega
    r_max, upper = MODEL.cmp_max[0], edges.upper[0][SIGMA]
    reachable = r_max + (upper - r_max) * math.exp(-omega * t_min)
    expected = (reachable - x0) * mass * omega / kappa(omega, DURATION)
    bound = impulse_bound(CONFIG, 0.0, SIGMA, 0.0, DURATION)
    assert bound == pytest.approx(expected, rel=1e-6)


def test_leg_reach_lowers_the_bound_where_it_binds() -> None:
    """A first step during the push (phase 0.5) backwards to the left: the CoM, near the
    stance ankle at the step, limits it (the reach binds); shorter legs bind more."""
    since = 0.5 * PERIOD
    state = nominal_state(CONFIG, SIGMA, since)
    orbit = NominalOrbit(MODEL.omega, CONFIG.gait)
    case = PushCase(
        state[:2],
        state[2:],
        SIGMA,
        since,
        -2.0 * orbit.state_after_step(SIGMA)[:2],
        np.array([math.cos(math.radians(135)), math.sin(math.radians(135))]),
        DURATION,
    )
    bounds = [largest_impulse(replace(MODEL, leg_reach=r), case).impulse for r in (0.4, 0.6, 10.0)]
    assert bounds[0] < 0.9 * bounds[1] and bounds[1] < 0.99 * bounds[2], bounds


def test_push_changes_the_dcm_by_kappa_impulse_over_m_omega() -> None:
    """Same CMP: after a push over Delta the DCM is as after a jump kappa i / (m omega)."""
    model = CONFIG.model
    impulse, duration, dt = np.array([6.0, -4.0]), 0.1, 0.001
    omega, mass = model.omega, model.mass
    states = []
    for scale in (0.0, 1.0):
        com, velocity = np.array([0.02, -0.01]), np.array([0.3, 0.1])
        for tick in range(int(round(0.3 / dt))):  # push over [0, Delta], then coast
            force = scale * impulse / duration if tick * dt < duration - 1e-12 else np.zeros(2)
            com, velocity = integrate_lipm(
                model, com, velocity, np.zeros(2), np.zeros(2), force, dt
            )
        states.append(dcm(omega, np.array([*com, *velocity])))
    expected = impulse / (mass * omega) * kappa(omega, duration) * math.exp(omega * 0.3)
    np.testing.assert_allclose(states[1] - states[0], expected, rtol=1e-6)


def test_bad_input_is_a_parameter_error() -> None:
    with pytest.raises(ParameterError):
        CaptureModel(3.5, 60.0, (0.1, -0.1), (0.2, 0.1), (-0.4, -0.6), (0.6, 0.6), 0.19, 0.3, 0.1)
    with pytest.raises(ParameterError):
        replace(MODEL, double_support_duration=MODEL.min_step_time)
    with pytest.raises(ParameterError, match="push_duration"):
        impulse_bound(CONFIG, 0.0, SIGMA, 0.2, 0.0)
    with pytest.raises(ParameterError, match="sigma"):
        impulse_bound(CONFIG, 0.0, 0, 0.2, 0.1)


# -- A strong stepping policy on the LIPM, with the bound's limits ------------------------

TICK = 0.01  # [s] the policy's control period
HORIZON = 3.0  # [s] simulated after the push start


def policy_captures(angle: float, since: float, impulse: float) -> bool:
    """Whether a simple policy captures the push on the LIPM.

    The CMP sits on the DCM, clipped to the stance window (in double support to the hull
    of both feet's windows). A step comes as soon as the swing foot is ready (T_min after
    the last one): while the push acts, to the extreme of the step range along the push;
    after it, onto the DCM (capture point), clipped to the step range (27b), (27d); each
    moved towards the CoM when it would leave it beyond the leg reach. Captured: no CoM
    beyond the reach of the stance ankle, and the DCM in the window at the end.
    """
    omega = MODEL.omega
    direction = np.array([math.cos(angle), math.sin(angle)])
    state = nominal_state(CONFIG, SIGMA, since)
    com, velocity = state[:2].copy(), state[2:].copy()
    sigma, foot = SIGMA, np.zeros(2)
    previous = foot + 2.0 * NominalOrbit(omega, CONFIG.gait).state_after_step(SIGMA)[:2]
    last_step, low, high = -since, np.array(MODEL.cmp_min), np.array(MODEL.cmp_max)
    force, reach = impulse * direction / DURATION, LEG_REACH - 1e-3
    for tick in range(int(round(HORIZON / TICK))):
        t = tick * TICK
        xi = com + velocity / omega
        offset = xi - foot
        captured = bool(np.all(offset >= low) and np.all(offset <= high))
        if t - last_step >= MODEL.min_step_time - 1e-9 and not captured:
            ranges = [MODEL.step_range(axis, sigma) for axis in (0, 1)]
            step = np.array([np.clip(offset[axis], *ranges[axis]) for axis in (0, 1)])
            if t < DURATION - 1e-9:
                for axis in (0, 1):
                    if abs(direction[axis]) > 1e-6:
                        step[axis] = ranges[axis][1] if direction[axis] > 0 else ranges[axis][0]
            gap = step - (com - foot)
            if np.linalg.norm(gap) > reach:
                step = com - foot + reach * gap / np.linalg.norm(gap)
                step = np.array([np.clip(step[axis], *ranges[axis]) for axis in (0, 1)])
            previous, foot, sigma, last_step = foot, foot + step, -sigma, t
        window_low, window_high = foot + low, foot + high
        if t - last_step < MODEL.double_support_duration - 1e-9:
            window_low = np.minimum(window_low, previous + low)
            window_high = np.maximum(window_high, previous + high)
        cmp = np.clip(xi, window_low, window_high)
        push = force if t < DURATION - 1e-9 else np.zeros(2)
        com, velocity = integrate_lipm(CONFIG.model, com, velocity, cmp, np.zeros(2), push, TICK)
        if np.linalg.norm(com - foot) > LEG_REACH:
            return False
    offset = com + velocity / omega - foot
    return bool(np.all(offset >= low - 1e-6) and np.all(offset <= high + 1e-6))


@cache
def policy_largest(angle: float, since: float, upper: float) -> float:
    """Largest impulse [N s] the policy captures, up to 1.2 ``upper``: the largest of 12
    levels it captures (capture need not be monotone at small impulses, where the first
    step is too long), then bisection to 0.5 N s above it."""
    levels = [upper * k / 10.0 for k in range(1, 13)]
    captured = [level for level in levels if policy_captures(angle, since, level)]
    if not captured:
        return 0.0
    low = max(captured)
    if low == levels[-1]:
        return low
    high = low + upper / 10.0
    while high - low > 0.5:
        middle = 0.5 * (low + high)
        low, high = (middle, high) if policy_captures(angle, since, middle) else (low, middle)
    return low


ANGLES = [math.radians(a) for a in range(0, 360, 45)]
PHASES = (0.0, 0.25, 0.5, 0.75)


@cache
def bound_at(angle: float, phase: float) -> float:
    return impulse_bound(CONFIG, angle, SIGMA, phase * PERIOD, DURATION)


@pytest.mark.parametrize("phase", PHASES)
def test_bound_is_never_below_what_a_stepping_policy_captures(phase: float) -> None:
    for angle in ANGLES:
        bound = bound_at(angle, phase)
        captured = policy_largest(angle, phase * PERIOD, bound)
        assert captured <= bound, f"{phase=} deg={math.degrees(angle):.0f}: {captured=} {bound=}"


def test_bound_is_within_15_percent_of_the_policy_at_phase_0() -> None:
    """Where the first step comes after the push (phase 0), the causal policy is close to
    optimal; the bound must not be far above it."""
    for angle in ANGLES:
        bound = bound_at(angle, 0.0)
        captured = policy_largest(angle, 0.0, bound)
        assert bound <= 1.15 * captured, f"deg={math.degrees(angle):.0f}: {captured=} {bound=}"
