"""The page of a run on a viser server: 3-D view, legend, status line and plots.

:class:`PageView` is what the live demo (:mod:`web.demo_page`) and the replay
(:mod:`web.replay_page`) share: given a :class:`web.snapshot.Snapshot` it updates
the scene nodes in one ``server.atomic()`` block, and the plots at a lower rate:

- the legend at the top of the panel;
- the 3-D view: robot (or the LIPM's CoM on a stick), footholds, ZMP window,
  ZMP/CoM/DCM with trails, and the push arrow while a push acts;
- the DCM error of the paper's Fig. 6(c) as a 2-D plot in metres with the level
  sets V_u = gamma_v and V_u = current (:mod:`web.plots`);
- V_u / gamma_v over the last 10 s on a log axis (1 = gamma_v, above it the RSG
  adjusts the step), and the time since the last step.

View: the scene root ``/world`` is shifted so that the robot stays near the origin
of the view (the ground grid scrolls under it). "Side view" puts the camera of the
tab that pressed it just above the ground, :data:`SIDE_VIEW_DISTANCE` to the right of
the stance ankle, looking at the robot: the ground is seen edge-on, so a sole on the
ground sits on the ground's line. "Default view" puts it back where the page opened.
The GUI is server-wide: every tab sees the same run and its controls.
"""

from __future__ import annotations

import threading
import time as wallclock
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import viser
from numpy.typing import NDArray

from .client_view import ClientView, Frame
from .plots import RATIO_FLOOR, DcmErrorPlot, log_axis_top, lyapunov_ratio
from .scene_model import (
    ADJUSTED_COLOUR,
    COM_COLOUR,
    DCM_COLOUR,
    NEXT_COLOUR,
    PREVIEW_COLOUR,
    PREVIOUS_COLOUR,
    PUSH_COLOUR,
    STANCE_COLOUR,
    TRAIL_COLOUR,
    WINDOW_COLOUR,
    ZMP_COLOUR,
    Colour,
)
from .snapshot import Snapshot

Array = NDArray[np.float64]

STATUS_LINES = 4  # the status block's height [lines]
PLOT_RATE = 5.0  # [Hz] uPlot updates
IMAGE_RATE = 3.0  # [Hz] DCM-error plot updates (a matplotlib image, ~20 ms each)
SIDE_VIEW_DISTANCE = 3.5  # [m] camera to stance ankle, along -y
SIDE_VIEW_HEIGHT = 0.05  # [m] camera height above the ground: the ground is seen edge-on
SIDE_VIEW_LOOK_HEIGHT = 0.6  # [m] height of the point looked at, above the stance ankle
SIDE_VIEW_FOV = np.radians(45.0)  # [rad] vertical field of view
DEFAULT_CAMERA_POSITION = (-0.7, -2.1, 1.25)  # [m] where the page opens, behind and left
DEFAULT_CAMERA_LOOK_AT = (0.3, -0.45, 0.4)  # [m]
TIME_AXIS: Any = {"time": False}  # plain seconds on the x axis (a uPlot scale)
# The log axis's tick labels go up to "10,000" (RATIO_CEILING): 64 px hold them.
LYAPUNOV_AXES: Any = ({"label": "t [s]"}, {"label": "V_u / γ_v", "size": 64})


def _hex(colour: Colour) -> str:
    return "#{:02x}{:02x}{:02x}".format(*colour)


def _swatch(colour: Colour, text: str, shape: str = "■") -> str:
    return f'<span style="color:{_hex(colour)}">{shape}</span>&nbsp;{text}'


LEGEND = (
    "<small>"
    + "<br>".join(
        (
            "<b>Feet</b> "
            + " ".join(
                (
                    _swatch(STANCE_COLOUR, "stance", "▭"),
                    _swatch(PREVIOUS_COLOUR, "previous", "▭"),
                    _swatch(NEXT_COLOUR, "next (planned)", "▭"),
                    _swatch(TRAIL_COLOUR, "past", "▭"),
                    _swatch(ADJUSTED_COLOUR, "adjusted by the RSG", "☒"),
                )
            ),
            "<b>Points</b> "
            + " ".join(
                (
                    _swatch(ZMP_COLOUR, "ZMP", "●"),
                    _swatch(COM_COLOUR, "CoM", "●"),
                    _swatch(DCM_COLOUR, "DCM", "●"),
                    "(2 s trails)",
                    _swatch(WINDOW_COLOUR, "ZMP window W(r_H)", "▭"),
                )
            ),
            "<b>Push</b> "
            + " ".join(
                (
                    _swatch(PUSH_COLOUR, "acting now", "➜"),
                    _swatch(PREVIEW_COLOUR, "being aimed", "➜"),
                )
            ),
        )
    )
    + "</small>"
)


def _status_html(lines: list[str]) -> str:
    rows = "".join(
        f'<div style="white-space:nowrap;overflow:hidden;text-overflow:ellipsis">{line}</div>'
        for line in lines[:STATUS_LINES]
    )
    height = 1.45 * STATUS_LINES
    return f'<div style="height:{height}em;line-height:1.45em;font-size:0.85em">{rows}</div>'


class PageView:
    """The drawing of a run on a viser server: the GUI shared by every tab, and each
    tab's own 3-D view (:class:`web.client_view.ClientView`).

    Args:
        server: The viser server.
        urdf: Derived URDF of the robot (absolute mesh paths) for the full robot, or
            None to draw the point-mass LIPM (CoM ball on a stick).
        controls: Adds the page's own GUI (buttons, fields), placed between the
            legend and the plots.
        frame_rate: Frames per second a tab gets at most [Hz].
    """

    def __init__(
        self,
        server: viser.ViserServer,
        urdf: Path | None,
        controls: Callable[[], None] | None = None,
        frame_rate: float = 40.0,
    ) -> None:
        self.server = server
        self._urdf = urdf
        self._frame_rate = frame_rate
        self._frame: Frame | None = None
        self._serial = 0
        self._views: dict[int, ClientView] = {}
        self._lock = threading.Lock()
        self._last_plot = 0.0
        self._last_image = 0.0
        self._dcm_error_plot = DcmErrorPlot()
        server.scene.set_up_direction("+z")
        server.initial_camera.position = DEFAULT_CAMERA_POSITION
        server.initial_camera.look_at = DEFAULT_CAMERA_LOOK_AT
        self._default_fov = float(server.initial_camera.fov)
        gui = server.gui
        # A wider panel: the legend and the plots fit, no share button (local pages).
        gui.configure_theme(control_width="large", show_share_button=False)
        self.status = gui.add_html(_status_html(["starting ..."]))
        gui.add_html(LEGEND)
        if controls is not None:
            controls()
        with gui.add_folder("Plots"):
            self.dcm_error_image = gui.add_image(
                self._dcm_error_plot.render(
                    np.zeros(2), np.zeros((0, 2)), np.zeros((1, 2)), np.zeros((1, 2)), False
                ),
                format="png",
            )
            zeros = np.zeros(2)
            self.lyapunov_plot = gui.add_uplot(
                (zeros, zeros + 1e-3, zeros + 1.0),
                (
                    {"label": "t [s]"},
                    {"label": "V_u/γ_v", "stroke": "#1e6ee6", "width": 2},
                    {"label": "γ_v", "stroke": "#e11e1e", "dash": (6.0, 4.0), "width": 1.5},
                ),
                title="V_u / γ_v (log; above 1 the RSG adjusts the step)",
                scales=self._lyapunov_scales(10.0),
                axes=LYAPUNOV_AXES,
                padding=(12, 24, 0, 0),
                aspect=1.6,
            )
            self._lyapunov_top = 10.0
            self.since_step_plot = gui.add_uplot(
                (zeros, zeros),
                ({"label": "t [s]"}, {"label": "s~ [s]", "stroke": "#14aa46", "width": 2}),
                title="time since the last step s~ [s]",
                scales={"x": TIME_AXIS},
                axes=({"label": "t [s]"}, {"label": "s~ [s]"}),
                aspect=1.6,
            )
        with gui.add_folder("View"):
            self.show_robot = gui.add_checkbox("Robot", True, hint="draw the robot's meshes")
            self.side_view_button = gui.add_button(
                "Side view", hint="camera level with the ground, beside the stance sole"
            )
            self.default_view_button = gui.add_button(
                "Default view", hint="camera back where the page opened"
            )
        self.show_robot.on_update(lambda _: self._changed())
        self.side_view_button.on_click(lambda event: self.side_view(event.client))
        self.default_view_button.on_click(lambda event: self.default_view(event.client))
        server.on_client_connect(self._connected)
        server.on_client_disconnect(self._disconnected)

    # ----------------------------------------------------------------------- tabs
    def _connected(self, client: viser.ClientHandle) -> None:
        view = ClientView(client, self._urdf, self.latest, self._frame_rate)
        with self._lock:
            self._views[client.client_id] = view
        view.start()

    def _disconnected(self, client: viser.ClientHandle) -> None:
        with self._lock:
            view = self._views.pop(client.client_id, None)
        if view is not None:
            view.stop()

    def views(self) -> list[ClientView]:
        """The tabs' views, one per connected tab."""
        with self._lock:
            return list(self._views.values())

    def view_of(self, client: viser.ClientHandle | None) -> ClientView | None:
        """The view of ``client``'s tab (None if it has none)."""
        if client is None:
            return None
        with self._lock:
            return self._views.get(client.client_id)

    def stop(self) -> None:
        """Stop every tab's drawing."""
        for view in self.views():
            view.stop()

    def latest(self) -> Frame | None:
        """What every tab should draw now."""
        return self._frame

    def _changed(self) -> None:
        if self._frame is not None:
            self._publish(self._frame.snap, self._frame.aim)

    def tab_rates(self) -> list[float]:
        """Frames per second each tab drew lately [Hz]."""
        return [view.frame_rate for view in self.views()]

    def set_status(self, lines: list[str]) -> None:
        """Show the status: up to :data:`STATUS_LINES` lines of HTML, each cut to one
        line, in a block of fixed height (the controls below it never move)."""
        self.status.content = _status_html(lines)

    @staticmethod
    def _lyapunov_scales(top: float) -> Any:
        return {"x": TIME_AXIS, "y": {"distr": 3, "log": 10, "range": [RATIO_FLOOR, top]}}

    def _clients(self, client: viser.ClientHandle | None) -> list[viser.ClientHandle]:
        if client is not None:
            return [client]
        return list(self.server.get_clients().values())

    def side_view(self, client: viser.ClientHandle | None = None) -> None:
        """The camera of ``client`` (every tab's if None) :data:`SIDE_VIEW_HEIGHT` above
        the ground, :data:`SIDE_VIEW_DISTANCE` to the right of the stance ankle, looking
        at the point :data:`SIDE_VIEW_LOOK_HEIGHT` above it (vertical field of view
        :data:`SIDE_VIEW_FOV`)."""
        for each in self._clients(client):
            view = self.view_of(each)
            if view is None:
                continue
            ankle = view.stance - view.offset
            each.camera.fov = float(SIDE_VIEW_FOV)
            each.camera.up_direction = (0.0, 0.0, 1.0)
            each.camera.position = np.array(
                [ankle[0], ankle[1] - SIDE_VIEW_DISTANCE, SIDE_VIEW_HEIGHT]
            )
            each.camera.look_at = np.array([ankle[0], ankle[1], SIDE_VIEW_LOOK_HEIGHT])

    def default_view(self, client: viser.ClientHandle | None = None) -> None:
        """The camera of ``client`` (every tab's if None) where the page opened."""
        for each in self._clients(client):
            each.camera.fov = self._default_fov
            each.camera.up_direction = (0.0, 0.0, 1.0)
            each.camera.position = DEFAULT_CAMERA_POSITION
            each.camera.look_at = DEFAULT_CAMERA_LOOK_AT

    # ---------------------------------------------------------------------- frames
    def show(self, snap: Snapshot, dt: float = 0.0, aim: Array | None = None) -> None:
        """Publish ``snap`` to every tab (each draws it at its own pace); plots at
        :data:`PLOT_RATE` and :data:`IMAGE_RATE`.

        Args:
            snap: What to draw.
            dt: Unused (each tab follows the robot at its own frame rate).
            aim: Arrow of the push being aimed (start, end) [m], shape (2, 3), or None.
        """
        self._publish(snap, aim)
        self._plot(snap)

    def _publish(self, snap: Snapshot, aim: Array | None) -> None:
        self._serial += 1
        self._frame = Frame(self._serial, snap, aim, bool(self.show_robot.value))
        for view in self.views():
            view.changed()

    def _plot(self, snap: Snapshot) -> None:
        now = wallclock.perf_counter()
        state = snap.state
        if state is None:
            return
        if now - self._last_plot >= 1.0 / PLOT_RATE and len(snap.plot_time) >= 2:
            self._last_plot = now
            ratio = lyapunov_ratio(snap.plot_lyapunov, state.threshold)
            top = log_axis_top(float(ratio.max()))
            if top != self._lyapunov_top:
                self._lyapunov_top = top
                self.lyapunov_plot.scales = self._lyapunov_scales(top)
            self.lyapunov_plot.data = (snap.plot_time, ratio, np.ones_like(snap.plot_time))
            self.since_step_plot.data = (snap.plot_time, snap.plot_time_since_step)
        if now - self._last_image >= 1.0 / IMAGE_RATE and snap.level_set is not None:
            self._last_image = now
            self.dcm_error_image.image = self._dcm_error_plot.render(
                state.dcm_error,
                state.dcm_error_trail,
                snap.level_set(state.threshold),
                snap.level_set(state.lyapunov),
                state.lyapunov > state.threshold,
            )
