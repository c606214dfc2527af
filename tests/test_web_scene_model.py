"""What the browser demo draws for a given controller state (no browser, no viser)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from planner.parameters import PlannerConfig
from web.push_input import PushBounds, clamp_push, paper_presets, wrap_degrees
from web.scene_model import (
    ADJUSTED_COLOUR,
    NEXT_COLOUR,
    PREVIOUS_COLOUR,
    STANCE_COLOUR,
    TRAIL_COLOUR,
    ControllerState,
    StepMark,
    Trail,
    direction_towards,
    draw_scene,
    polyline_segments,
    push_arrow,
    ray_ground_intersection,
    rectangle,
)

FOOT_LOWER = np.array([-0.09, -0.08])
FOOT_UPPER = np.array([0.13, 0.08])


def make_state(**changes) -> ControllerState:
    config = PlannerConfig()
    values = dict(
        time=4.0,
        com=np.array([1.0, 0.02]),
        com_velocity=np.array([0.35, -0.1]),
        com_height=config.model.com_height,
        omega=config.model.omega,
        zmp=np.array([1.02, 0.09]),
        window_center=np.array([1.0, 0.1]),
        window_min=np.array(config.constraints.zmp_window_min),
        window_max=np.array(config.constraints.zmp_window_max),
        stance_foot="left",
        stance=np.array([1.0, 0.1]),
        previous_foot="right",
        previous=np.array([0.8, -0.1]),
        next_foot="right",
        next_step=np.array([1.25, -0.12]),
        steps=(
            StepMark(3.1, "right", np.array([0.8, -0.1]), False),
            StepMark(3.9, "left", np.array([1.0, 0.1]), True),
        ),
        dcm_error=np.array([0.03, -0.02]),
        lyapunov=0.002,
        threshold=0.0015,
        time_since_step=0.1,
        push_impulse=np.array([8.0, -6.0]),
        com_trail=np.array([[0.9, 0.0], [0.95, 0.01], [1.0, 0.02]]),
        zmp_trail=np.array([[1.0, 0.1], [1.02, 0.09]]),
        dcm_trail=np.zeros((0, 2)),
        dcm_error_trail=np.array([[0.0, 0.0], [0.01, -0.01], [0.03, -0.02]]),
    )
    values.update(changes)
    return ControllerState(**values)  # type: ignore[arg-type]


# ----------------------------------------------------------------------------- drawing
def test_footholds_roles_colours_and_adjusted_steps():
    state = make_state()
    drawing = draw_scene(state, FOOT_LOWER, FOOT_UPPER)
    roles = [(f.role, f.colour) for f in drawing.footholds]
    assert roles == [
        ("trail", TRAIL_COLOUR),
        ("trail", ADJUSTED_COLOUR),
        ("previous", PREVIOUS_COLOUR),
        ("next", NEXT_COLOUR),
        ("stance", STANCE_COLOUR),
    ]
    stance = drawing.footholds[-1]
    assert stance.adjusted  # the current stance foot was placed by an adjusted step
    np.testing.assert_allclose(stance.corners[0], state.stance + FOOT_LOWER)
    np.testing.assert_allclose(stance.corners[2], state.stance + FOOT_UPPER)
    next_step = drawing.footholds[3]
    np.testing.assert_allclose(
        next_step.corners[:4].mean(axis=0), state.next_step + 0.5 * (FOOT_LOWER + FOOT_UPPER)
    )


def test_trail_of_steps_is_bounded():
    steps = tuple(StepMark(i, "left", np.array([0.2 * i, 0.1]), i % 3 == 0) for i in range(40))
    from web.scene_model import footholds

    drawn = footholds(make_state(steps=steps), FOOT_LOWER, FOOT_UPPER, trail_length=12)
    trail = [f for f in drawn if f.role == "trail"]
    assert len(trail) == 12
    assert [f.adjusted for f in trail] == [s.adjusted for s in steps[-12:]]
    assert all((f.colour == ADJUSTED_COLOUR) == f.adjusted for f in trail)


def test_window_rectangle_moves_with_window_center():
    for center in ([0.0, 0.0], [1.3, -0.4]):
        state = make_state(window_center=np.array(center))
        window = draw_scene(state, FOOT_LOWER, FOOT_UPPER).window
        assert window.shape == (5, 2)
        np.testing.assert_allclose(window[0], window[-1])  # closed
        np.testing.assert_allclose(window.min(axis=0), np.array(center) + state.window_min)
        np.testing.assert_allclose(window.max(axis=0), np.array(center) + state.window_max)


def test_points_trails_and_push_arrow():
    state = make_state()
    drawing = draw_scene(state, FOOT_LOWER, FOOT_UPPER)
    np.testing.assert_allclose(drawing.com, [1.0, 0.02, state.com_height])
    np.testing.assert_allclose(drawing.zmp, [1.02, 0.09, 0.0])
    np.testing.assert_allclose(drawing.dcm[:2], state.com + state.com_velocity / state.omega)
    assert drawing.com_trail.shape == (3, 3) and drawing.dcm_trail.shape == (0, 3)
    start, end = drawing.push_arrow
    np.testing.assert_allclose(end, drawing.com)  # the arrow ends at the CoM
    direction = (end - start)[:2] / np.linalg.norm(end - start)
    np.testing.assert_allclose(direction, [0.8, -0.6], atol=1e-12)
    assert draw_scene(make_state(push_impulse=None), FOOT_LOWER, FOOT_UPPER).push_arrow is None


def test_push_arrow_length_is_bounded():
    com = np.zeros(2)
    short = push_arrow(com, 0.8, np.array([0.1, 0.0]))
    long = push_arrow(com, 0.8, np.array([1000.0, 0.0]))
    assert short is not None and long is not None
    assert np.linalg.norm(short[1] - short[0]) < np.linalg.norm(long[1] - long[0]) <= 0.8
    assert push_arrow(com, 0.8, np.zeros(2)) is None
    assert push_arrow(com, 0.8, np.array([np.nan, 1.0])) is None


def test_helpers_rectangle_and_segments():
    r = rectangle(np.array([1.0, 2.0]), np.array([-0.1, -0.2]), np.array([0.3, 0.4]))
    np.testing.assert_allclose(r, [[0.9, 1.8], [1.3, 1.8], [1.3, 2.4], [0.9, 2.4], [0.9, 1.8]])
    assert polyline_segments(r).shape == (4, 2, 2)
    assert polyline_segments(np.zeros((1, 3))).shape == (0, 2, 3)


def test_trail_keeps_the_last_points_in_order():
    trail = Trail(3)
    assert trail.points().shape == (0, 2)
    for i in range(5):
        trail.append((i, -i))
    np.testing.assert_allclose(trail.points(), [[2, -2], [3, -3], [4, -4]])
    trail.clear()
    assert len(trail) == 0
    with pytest.raises(ValueError, match="capacity"):
        Trail(1)


# ----------------------------------------------------------------------- click on ground
def test_ray_hits_ground():
    point = ray_ground_intersection((0.0, 0.0, 2.0), (1.0, 0.0, -1.0))
    np.testing.assert_allclose(point, [2.0, 0.0])
    point = ray_ground_intersection((1.0, -1.0, 1.0), (0.0, 0.0, -5.0))
    np.testing.assert_allclose(point, [1.0, -1.0])
    np.testing.assert_allclose(
        ray_ground_intersection((0.0, 0.0, 1.0), (0.0, 1.0, -1.0), height=0.5), [0.0, 0.5]
    )


@pytest.mark.parametrize(
    "origin, direction",
    [
        ((0.0, 0.0, 1.0), (1.0, 0.0, 0.0)),  # parallel to the ground
        ((0.0, 0.0, 1.0), (1.0, 0.0, 1e-12)),  # numerically parallel
        ((0.0, 0.0, 1.0), (0.0, 0.3, 1.0)),  # pointing away (up)
        ((0.0, 0.0, -1.0), (0.0, 0.0, -1.0)),  # below the ground, pointing down
        ((0.0, 0.0, 1.0), (0.0, 0.0, 0.0)),  # no direction
        ((0.0, 0.0, np.nan), (0.0, 0.0, -1.0)),  # not finite
        ((0.0, 0.0), (0.0, 0.0, -1.0)),  # wrong shape
    ],
)
def test_ray_missing_ground(origin, direction):
    assert ray_ground_intersection(origin, direction) is None


def test_direction_towards_clicked_point():
    assert direction_towards(np.array([1.0, 1.0]), np.array([1.0, 2.0])) == pytest.approx(90.0)
    assert direction_towards(np.array([0.0, 0.0]), np.array([-1.0, 0.0])) == pytest.approx(180.0)
    assert direction_towards(np.zeros(2), np.array([1.0, -1.0])) == pytest.approx(-45.0)
    assert direction_towards(np.zeros(2), np.zeros(2)) is None


# --------------------------------------------------------------------------- push input
def test_push_input_is_clamped_to_safe_ranges():
    bounds = PushBounds.for_mass(60.0)
    push = clamp_push(370.0, 1e6, 5.0, bounds)
    assert push.direction == pytest.approx(10.0)
    assert push.impulse == bounds.impulse_max == pytest.approx(30.0)
    assert push.duration == bounds.duration_max
    push = clamp_push(-190.0, -3.0, 0.0, bounds)
    assert push.direction == pytest.approx(170.0)
    assert push.impulse == 0.0
    assert push.duration == bounds.duration_min
    np.testing.assert_allclose(
        clamp_push(90.0, 2.0, 0.1, bounds).impulse_xy(), [0.0, 2.0], atol=1e-12
    )


@pytest.mark.parametrize("bad", [math.nan, math.inf, "3", None])
def test_push_input_rejects_non_numbers(bad):
    bounds = PushBounds.for_mass(60.0)
    with pytest.raises(ValueError, match="impulse"):
        clamp_push(0.0, bad, 0.1, bounds)  # type: ignore[arg-type]


def test_bounds_scale_with_mass_and_reject_bad_mass():
    assert PushBounds.for_mass(30.0).impulse_max == pytest.approx(15.0)
    for mass in (0.0, -1.0, math.nan):
        with pytest.raises(ValueError, match="mass"):
            PushBounds.for_mass(mass)


def test_paper_presets_scale_with_mass():
    presets = list(paper_presets(30.0).values())
    np.testing.assert_allclose(presets[0].impulse_xy(), [4.0, -3.0], atol=1e-12)
    assert presets[0].duration == pytest.approx(0.1)
    np.testing.assert_allclose(presets[1].impulse_xy(), [-3.0, 4.0], atol=1e-12)
    assert presets[1].duration == pytest.approx(0.2)


def test_wrap_degrees():
    assert wrap_degrees(180.0) == 180.0
    assert wrap_degrees(-180.0) == 180.0
    assert wrap_degrees(540.0) == 180.0
    assert wrap_degrees(-45.0) == -45.0
