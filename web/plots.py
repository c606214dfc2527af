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
RATIO_CEILING = 1e4  # [-] and at most this: after a fall V_u grows without bound
INSET_ZOOM = 4.0  # [-] the inset shows gamma_v's level set once the axes are this much wider
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
    """V_u / gamma_v, in [:data:`RATIO_FLOOR`, :data:`RATIO_CEILING`] (for a log axis)."""
    ratio = np.asarray(lyapunov, dtype=float) / max(threshold, 1e-300)
    return np.clip(np.nan_to_num(ratio, nan=RATIO_CEILING), RATIO_FLOOR, RATIO_CEILING)


def log_axis_top(largest: float) -> float:
    """Top of the V_u / gamma_v axis: the power of 10 above ``largest``, in [10,
    :data:`RATIO_CEILING`]."""
    if not (math.isfinite(largest) and largest > 0.0):
        return 10.0
    return min(RATIO_CEILING, max(10.0, 10.0 ** math.ceil(math.log10(largest * 1.05))))


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
        # After a large push the axes grow and the gamma_v level set shrinks to a dot:
        # an inset keeps it, and e_u near it, readable.
        self.inset = self.figure.add_axes((0.66, 0.17, 0.28, 0.28))
        self.inset.set_aspect("equal")
        self.inset.set_xticks([])
        self.inset.set_yticks([])
        self.inset.set_visible(False)
        self.inset_half_range = 0.0  # [m], 0 while the inset is hidden
        (self.inset_threshold,) = self.inset.plot([], [], color=THRESHOLD_COLOUR, lw=1.2)
        (self.inset_trail,) = self.inset.plot([], [], color=TRAIL_COLOUR, lw=0.7)
        (self.inset_point,) = self.inset.plot([], [], "o", color=TRAIL_COLOUR, markersize=4)
        self._inset_artists = (self.inset_threshold, self.inset_trail, self.inset_point)
        self._moving = (self.threshold_line, self.level_line, self.trail_line, self.point)
        for artist in (*self._moving, *self._inset_artists):
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
        self.inset_threshold.set_data(threshold_curve[:, 0], threshold_curve[:, 1])
        self.inset_trail.set_data(trail[:, 0], trail[:, 1])
        self.inset_point.set_data([dcm_error[0]], [dcm_error[1]])
        self.inset_point.set_color(self.point.get_color())
        fitted = self._fit(threshold_curve, level_curve, trail, dcm_error)
        inset_changed = self._fit_inset(threshold_curve)
        if fitted or inset_changed or self._background is None:
            self.canvas.draw()  # axes, ticks, labels, legend: only when the range changes
            self._background = self.canvas.copy_from_bbox(self.figure.bbox)
        self.canvas.restore_region(self._background)
        for artist in self._moving:
            self.axes.draw_artist(artist)
        if self.inset_half_range > 0.0:
            for artist in self._inset_artists:
                self.inset.draw_artist(artist)
        return np.asarray(self.canvas.buffer_rgba())[..., :3].copy()

    def _fit_inset(self, threshold_curve: Array) -> bool:
        """Show the inset (its half range) when the gamma_v level set is small in the
        axes; True if that changed."""
        extent = float(np.max(np.abs(threshold_curve))) if np.size(threshold_curve) else 0.0
        wanted = nice_ceiling(1.3 * extent) if extent > 0.0 else 0.0
        if not (extent > 0.0 and self.half_range > INSET_ZOOM * wanted):
            wanted = 0.0
        if wanted == self.inset_half_range:
            return False
        self.inset_half_range = wanted
        self.inset.set_visible(wanted > 0.0)
        if wanted > 0.0:
            self.inset.set_xlim(-wanted, wanted)
            self.inset.set_ylim(-wanted, wanted)
            self.inset.set_title(f"±{100 * wanted:g} cm", fontsize=7, pad=2)
        return True

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
