"""The N-step capturability bound: Koolen's closed forms, monotonicity, the crossing constraint."""

from __future__ import annotations

import math

import numpy as np
import pytest

from app.capturability import (
    CaptureModel,
    capture_box,
    capture_distance,
    first_step_time,
    impulse_bound,
    max_dcm_shift,
    nominal_dcm,
    push_discount,
)
from app.runner import walking_start
from planner.exceptions import ParameterError
from planner.hybrid_lipm import dcm, integrate_lipm
from planner.parameters import PlannerConfig

CONFIG = PlannerConfig()
MODEL = CaptureModel.from_config(CONFIG)


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


def test_box_forward_edge_is_koolens_d_n() -> None:
    t = MODEL.min_step_time
    for n in (0, 1, 2, 5, math.inf):
        _, hi = capture_box(MODEL, 1, t, n)
        expected = capture_distance(n, MODEL.step_max[0], MODEL.cmp_max[0], MODEL.omega, t)
        assert hi[0] == pytest.approx(expected, rel=1e-9)


def test_box_grows_with_steps_and_shrinks_with_delay() -> None:
    boxes = [capture_box(MODEL, -1, 0.1, n) for n in range(6)]
    for (lo_a, hi_a), (lo_b, hi_b) in zip(boxes, boxes[1:], strict=False):
        assert np.all(lo_b <= lo_a + 1e-12) and np.all(hi_b >= hi_a - 1e-12)
    _, early = capture_box(MODEL, -1, 0.0)
    _, late = capture_box(MODEL, -1, 0.3)
    assert np.all(early >= late)


def test_zero_steps_is_the_cmp_window() -> None:
    lo, hi = capture_box(MODEL, 1, 0.3, 0)
    np.testing.assert_allclose(lo, MODEL.cmp_min)
    np.testing.assert_allclose(hi, MODEL.cmp_max)


def test_crossing_constraint_blocks_the_stance_side() -> None:
    # Right stance (sigma = -1): the next step is the left foot, which cannot go right.
    lo, hi = capture_box(MODEL, -1, 0.3)
    assert -lo[1] < hi[1]
    left = impulse_bound(CONFIG, math.pi / 2, -1, 0.2, 0.1)
    right = impulse_bound(CONFIG, -math.pi / 2, -1, 0.2, 0.1)
    assert right < 0.6 * left
    # Mirror symmetry between the feet.
    lo_l, hi_l = capture_box(MODEL, 1, 0.3)
    assert lo_l[1] == pytest.approx(-hi[1]) and hi_l[1] == pytest.approx(-lo[1])


def test_impulse_bound_monotone_in_steps() -> None:
    bounds = [impulse_bound(CONFIG, 0.3, -1, 0.2, 0.1, n_steps=n) for n in range(8)]
    assert np.all(np.diff(bounds) >= -1e-9)
    assert bounds[-1] == pytest.approx(impulse_bound(CONFIG, 0.3, -1, 0.2, 0.1), rel=1e-3)


def test_push_discount_and_ray() -> None:
    assert push_discount(3.5, 1e-12) == 1.0
    assert push_discount(3.5, 0.1) == pytest.approx((1 - math.exp(-0.35)) / 0.35)
    lo, hi = np.array([-1.0, -1.0]), np.array([2.0, 1.0])
    assert max_dcm_shift(np.zeros(2), np.array([1.0, 0.0]), lo, hi) == pytest.approx(2.0)
    assert max_dcm_shift(np.array([3.0, 0.0]), np.array([1.0, 0.0]), lo, hi) == 0.0


def test_push_changes_the_dcm_by_kappa_impulse_over_m_omega() -> None:
    """Same CMP: a push over Delta equals a DCM jump kappa i / (m omega) at its start."""
    model = CONFIG.model
    impulse, duration, dt = np.array([6.0, -4.0]), 0.1, 0.001
    omega, mass = model.omega, model.mass
    states = []
    for scale in (0.0, 1.0):
        com, velocity = np.array([0.02, -0.01]), np.array([0.3, 0.1])
        for _ in range(int(round(0.3 / dt))):  # push over [0, Delta], then coast
            force = scale * impulse / duration if _ * dt < duration - 1e-12 else np.zeros(2)
            com, velocity = integrate_lipm(
                model, com, velocity, np.zeros(2), np.zeros(2), force, dt
            )
        states.append(dcm(omega, np.array([*com, *velocity])))
    expected = impulse / (mass * omega) * push_discount(omega, duration) * math.exp(omega * 0.3)
    np.testing.assert_allclose(states[1] - states[0], expected, rtol=1e-6)


def test_nominal_dcm_is_inside_the_box() -> None:
    for sigma in (1, -1):
        for s in np.linspace(0.0, 0.79, 9):
            lo, hi = capture_box(MODEL, sigma, max(0.0, MODEL.min_step_time - s))
            x0 = nominal_dcm(CONFIG, sigma, float(s))
            assert np.all(lo <= x0) and np.all(x0 <= hi)
    start = walking_start(CONFIG)
    assert start.stance.foot == "left"


def test_bad_model_is_a_parameter_error() -> None:
    with pytest.raises(ParameterError):
        CaptureModel(3.5, 60.0, (0.1, -0.1), (0.2, 0.1), (-0.4, -0.6), (0.6, 0.6), 0.19, 0.3)
    with pytest.raises(ParameterError):
        capture_box(MODEL, 1, -0.1)


def test_first_step_not_before_the_push_ends():
    """t_1 = max(T_min - s~, Delta): the swing foot ready and the push over."""
    t_min = MODEL.min_step_time
    assert first_step_time(t_min, 0.0, 0.1) == pytest.approx(t_min)
    assert first_step_time(t_min, t_min - 0.1, 0.1) == pytest.approx(0.1)
    assert first_step_time(t_min, 0.4, 0.1) == pytest.approx(0.1)
    assert first_step_time(t_min, 0.4, 0.0) == 0.0
    # Phase 0.5 (s~ = 0.4 s > T_min): the bound is the box with the first step at the
    # push end, from the nominal DCM, not at the push start.
    since, delta, angle = 0.4, 0.1, 0.0
    lo, hi = capture_box(MODEL, -1, delta)
    shift = max_dcm_shift(nominal_dcm(CONFIG, -1, since), np.array([1.0, 0.0]), lo, hi)
    expected = shift * MODEL.mass * MODEL.omega / push_discount(MODEL.omega, delta)
    bound = impulse_bound(CONFIG, angle, -1, since, delta)
    assert bound == pytest.approx(expected, rel=1e-12)
    lo0, hi0 = capture_box(MODEL, -1, 0.0)
    clairvoyant = max_dcm_shift(nominal_dcm(CONFIG, -1, since), np.array([1.0, 0.0]), lo0, hi0)
    assert bound < 0.8 * clairvoyant * MODEL.mass * MODEL.omega / push_discount(MODEL.omega, delta)
    # Where the foot is not ready before the push ends, nothing changes.
    for since in (0.0, 0.1, 0.2):
        first = max(0.0, t_min - since)
        lo, hi = capture_box(MODEL, -1, first)
        shift = max_dcm_shift(nominal_dcm(CONFIG, -1, since), np.array([1.0, 0.0]), lo, hi)
        assert impulse_bound(CONFIG, 0.0, -1, since, 0.1) == pytest.approx(
            shift * MODEL.mass * MODEL.omega / push_discount(MODEL.omega, 0.1), rel=1e-12
        )
