"""The page's plots that are not a uPlot time series: the DCM error of Fig. 6(c).

:class:`DcmErrorPlot` draws e_u in the plane, with axes in metres, the level sets
{V_u = gamma_v} (red) and {V_u = current level} (blue), the recent e_u (black) and
the current e_u (a dot, red while V_u > gamma_v), into an RGB image that the page
shows with ``gui.add_image`` a few times a second. The axes are square and
symmetric; their half range follows the data in steps (x1, x2, x5 per decade), so
the axes stay still between large changes. Also here: V_u / gamma_v for the
log-scale V_u plot (uPlot's tick labels keep 3 decimals, so V_u itself, ~1e-4,
would be labelled 0).

Matplotlib's object API with its Agg canvas (no pyplot state), so it runs in the
page's thread. Axes, ticks and legend are drawn once per range and cached; an update
draws the four curves over them (text layout is what costs: a full draw takes
0.5 s next to the simulation thread, measured with the LIPM demo).
"""

from __future__ import annotations

import math

import numpy as np
from matplotlib.backends.backend_agg import FigureCanvasAgg
from matplotlib.figure import Figure
from numpy.typing import NDArray

Array = NDArray[np.float64]

THRESHOLD_COLOUR = "#e11e1e"
LEVEL_COLOUR = "#1e6ee6"
TRAIL_COLOUR = "#141414"
RATIO_FLOOR = 1e-3  # [-] V_u / gamma_v shown at least this (log axis; 0 would be -inf)
NICE_STEPS = (1.0, 2.0, 5.0)


def nice_ceiling(value: float) -> float:
    """The smallest of 1, 2, 5 x 10^k that is >= ``value`` (> 0)."""
    if not (math.isfinite(value) and value > 0.0):
        return 1.0
    decade = 10.0 ** math.floor(math.log10(value))
    for step in (*NICE_STEPS, 10.0):
        if step * decade >= value * (1.0 - 1e-12):
            return step * decade
    return 10.0 * decade


def lyapunov_ratio(lyapunov: Array, threshold: float) -> Array:
    """V_u / gamma_v, at least :data:`RATIO_FLOOR` (for a log axis)."""
    ratio = np.asarray(lyapunov, dtype=float) / max(threshold, 1e-300)
    return np.maximum(ratio, RATIO_FLOOR)


def log_axis_top(largest: float) -> float:
    """Top of the V_u / gamma_v axis: the power of 10 above ``largest``, at least 10."""
    if not (math.isfinite(largest) and largest > 0.0):
        return 10.0
    return max(10.0, 10.0 ** math.ceil(math.log10(largest * 1.05)))


class DcmErrorPlot:
    """Fig. 6(c) as an image: e_u [m] against the level sets of V_u.

    Args:
        width, height: Image size [px].
    """

    def __init__(self, width: int = 330, height: int = 300) -> None:
        dpi = 100.0
        self.figure = Figure(figsize=(width / dpi, height / dpi), dpi=dpi)
        self.canvas = FigureCanvasAgg(self.figure)
        self.axes = self.figure.add_subplot()
        axes = self.axes
        axes.set_aspect("equal")
        axes.set_xlabel("e_u,x [m]")
        axes.set_ylabel("e_u,y [m]")
        axes.set_title("DCM error e_u (Fig. 6c)", fontsize=10)
        axes.tick_params(labelsize=8)
        axes.grid(True, linewidth=0.4, alpha=0.5)
        axes.axhline(0.0, color="0.6", linewidth=0.6)
        axes.axvline(0.0, color="0.6", linewidth=0.6)
        plot = axes.plot
        (self.threshold_line,) = plot([], [], color=THRESHOLD_COLOUR, lw=1.6, label="V_u = γ_v")
        (self.level_line,) = plot([], [], color=LEVEL_COLOUR, lw=1.2, label="V_u = now")
        (self.trail_line,) = plot([], [], color=TRAIL_COLOUR, lw=0.9, label="e_u, last 4 s")
        (self.point,) = axes.plot([], [], "o", color=TRAIL_COLOUR, markersize=5)
        axes.legend(loc="upper right", fontsize=7, framealpha=0.8)
        self.figure.subplots_adjust(left=0.2, right=0.96, bottom=0.15, top=0.91)
        self.half_range = 0.0  # [m]
        self._moving = (self.threshold_line, self.level_line, self.trail_line, self.point)
        for artist in self._moving:
            artist.set_animated(True)  # drawn over the cached background only
        self._background: object | None = None

    def render(
        self,
        dcm_error: Array,
        dcm_error_trail: Array,
        threshold_curve: Array,
        level_curve: Array,
        above_threshold: bool,
    ) -> NDArray[np.uint8]:
        """The plot for this state, RGB, shape (height, width, 3).

        Args:
            dcm_error: e_u now [m], shape (2,).
            dcm_error_trail: Recent e_u [m], shape (n, 2), oldest first.
            threshold_curve: {V_u = gamma_v} [m], shape (m, 2).
            level_curve: {V_u = current level} [m], shape (m, 2).
            above_threshold: V_u > gamma_v (the RSG adjusts the next step).
        """
        trail = np.asarray(dcm_error_trail, dtype=float).reshape(-1, 2)
        self.threshold_line.set_data(threshold_curve[:, 0], threshold_curve[:, 1])
        self.level_line.set_data(level_curve[:, 0], level_curve[:, 1])
        self.trail_line.set_data(trail[:, 0], trail[:, 1])
        self.point.set_data([dcm_error[0]], [dcm_error[1]])
        self.point.set_color(THRESHOLD_COLOUR if above_threshold else TRAIL_COLOUR)
        if self._fit(threshold_curve, level_curve, trail, dcm_error) or self._background is None:
            self.canvas.draw()  # axes, ticks, labels, legend: only when the range changes
            self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        self.canvas.restore_region(self._background)
        for artist in self._moving:
            self.axes.draw_artist(artist)
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()

    def _fit(self, *point_sets: Array) -> bool:
        """Set the axes' half range for the data; True if it changed."""
        extent = max(float(np.max(np.abs(p))) if np.size(p) else 0.0 for p in point_sets)
        wanted = nice_ceiling(1.15 * max(extent, 1e-4))
        # Grow at once, shrink only when the data fill less than a fifth.
        if wanted > self.half_range or extent < 0.2 * self.half_range:
            self.half_range = wanted
            self.axes.set_xlim(-wanted, wanted)
            self.axes.set_ylim(-wanted, wanted)
            return True
        return False
