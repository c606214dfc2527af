"""The page's plots: Fig. 6(c) drawn where the level sets are, readable log axis."""

from __future__ import annotations

import numpy as np
import pytest

from planner.lyapunov import design_lyapunov
from planner.parameters import PlannerConfig
from web.plots import (
    LEVEL_COLOUR,
    RATIO_FLOOR,
    THRESHOLD_COLOUR,
    DcmErrorPlot,
    log_axis_top,
    lyapunov_ratio,
    nice_ceiling,
)


def rgb(hex_colour: str) -> np.ndarray:
    return np.array([int(hex_colour[i : i + 2], 16) for i in (1, 3, 5)], float)


def pixel(plot: DcmErrorPlot, image: np.ndarray, point) -> np.ndarray:
    """Colour at a data point [m] (matplotlib's y axis points up, the image's down)."""
    x, y = plot.axes.transData.transform(point)
    return image[int(round(image.shape[0] - y)), int(round(x))].astype(float)


def near(image: np.ndarray, hex_colour: str, plot: DcmErrorPlot, point) -> bool:
    """Some pixel within 2 px of ``point`` has ``hex_colour`` (anti-aliasing)."""
    x, y = plot.axes.transData.transform(point)
    row, col = int(round(image.shape[0] - y)), int(round(x))
    patch = image[row - 2 : row + 3, col - 2 : col + 3].reshape(-1, 3).astype(float)
    return bool(np.min(np.linalg.norm(patch - rgb(hex_colour), axis=1)) < 60.0)


def test_dcm_error_plot_draws_the_level_sets_where_they_are_in_metres():
    config = PlannerConfig()
    design = design_lyapunov(config.model, config.constraints, config.rsg)
    plot = DcmErrorPlot()
    threshold = design.level_set(design.threshold)
    current = design.level_set(0.25 * design.threshold)  # half the size
    error = np.array([0.01, -0.005])
    image = plot.render(error, np.array([[0.0, 0.0], error]), threshold, current, False)
    assert image.shape == (300, 330, 3) and image.dtype == np.uint8
    assert plot.axes.get_xlabel() == "e_u,x [m]" and plot.axes.get_ylabel() == "e_u,y [m]"
    low, high = plot.axes.get_xlim()
    assert low == -high and plot.axes.get_ylim() == (low, high)  # square, symmetric
    assert np.abs(threshold).max() < high < 3.0 * np.abs(threshold).max()
    for point in threshold[::10]:
        assert near(image, THRESHOLD_COLOUR, plot, point), point
    for point in current[::10]:
        assert near(image, LEVEL_COLOUR, plot, point), point
    labels = [t.get_text() for t in plot.axes.get_yticklabels() if t.get_text()]
    assert len(labels) == len(set(labels)) >= 3, labels  # no ticks rounded into duplicates
    # A large error widens the axes; a point above gamma_v is drawn red.
    far = np.array([0.3, 0.1])
    image = plot.render(far, far[None], threshold, 30 * current, True)
    assert plot.axes.get_xlim()[1] >= 0.3
    assert np.linalg.norm(pixel(plot, image, far) - rgb(THRESHOLD_COLOUR)) < 60.0


def test_axis_steps_and_the_log_axis_of_v_u():
    assert [nice_ceiling(v) for v in (0.013, 0.02, 0.021, 0.7, 3.0)] == [0.02, 0.02, 0.05, 1, 5]
    ratio = lyapunov_ratio(np.array([0.0, 1e-9, 0.0015, 0.03]), 0.0015)
    np.testing.assert_allclose(ratio, [RATIO_FLOOR, RATIO_FLOOR, 1.0, 20.0])
    assert log_axis_top(0.5) == 10.0 and log_axis_top(20.0) == 100.0
    # uPlot labels a log axis at powers of ten with at most 3 decimals: from the floor
    # up, every label is distinct (V_u itself, ~1e-4, would be labelled "0").
    ticks = [10.0**k for k in range(-3, 3)]
    labels = [f"{v:.3f}".rstrip("0").rstrip(".") for v in ticks]
    assert len(set(labels)) == len(labels) and min(ticks) >= RATIO_FLOOR


@pytest.mark.parametrize("value", [0.0, -1.0, float("nan")])
def test_nice_ceiling_of_nothing_is_one(value):
    assert nice_ceiling(value) == 1.0


def test_the_log_axis_stays_readable_after_a_fall():
    """After a fall V_u grows without bound: the ratio and the axis stop at 10^4."""
    from web.plots import RATIO_CEILING

    ratio = lyapunov_ratio(np.array([1e-9, 3.0, 1e12, np.nan]), 1.0)
    assert ratio.max() == RATIO_CEILING == log_axis_top(1e12)
    np.testing.assert_allclose(ratio[:2], [1e-3, 3.0])


def test_the_inset_keeps_the_threshold_level_set_readable_after_a_large_push():
    from web.plots import INSET_ZOOM, DcmErrorPlot

    plot = DcmErrorPlot()
    angles = np.linspace(0.0, 2.0 * np.pi, 50)
    circle = 0.01 * np.stack([np.cos(angles), np.sin(angles)], axis=1)
    plot.render(np.zeros(2), np.zeros((0, 2)), circle, circle, False)
    assert plot.inset_half_range == 0.0 and not plot.inset.get_visible()  # small axes
    trail = np.array([[0.0, 0.0], [0.3, -0.2]])
    plot.render(trail[-1], trail, circle, 30.0 * circle, True)
    assert plot.half_range > INSET_ZOOM * plot.inset_half_range > 0.0
    assert plot.inset.get_visible()
    assert plot.inset.get_xlim()[1] >= 0.01  # the whole gamma_v level set is inside
