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
of the view (the ground grid scrolls under it). "Side view" puts every browser's
camera just above the ground, :data:`SIDE_VIEW_DISTANCE` to the right of the
stance ankle, looking at the robot: the ground is seen edge-on, so a sole on the
ground sits on the ground's line.
All GUI and scene nodes are server-wide: every browser tab sees the same run.
"""

from __future__ import annotations

import time as wallclock
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import viser
from numpy.typing import NDArray

from .plots import RATIO_FLOOR, DcmErrorPlot, log_axis_top, lyapunov_ratio
from .robot_view import RobotView
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
    SceneDrawing,
    draw_scene,
    follow,
    on_ground,
    polyline_segments,
)
from .snapshot import Snapshot

Array = NDArray[np.float64]

STATUS_LINES = 4  # the status block's height [lines]
PLOT_RATE = 5.0  # [Hz] uPlot updates
IMAGE_RATE = 3.0  # [Hz] DCM-error plot updates (a matplotlib image, ~20 ms each)
GRID_SIZE = 20.0  # [m]
GRID_CELL = 0.25  # [m]
SIDE_VIEW_DISTANCE = 3.5  # [m] camera to stance ankle, along -y
SIDE_VIEW_HEIGHT = 0.05  # [m] camera height above the ground: the ground is seen edge-on
SIDE_VIEW_LOOK_HEIGHT = 0.6  # [m] height of the point looked at, above the stance ankle
SIDE_VIEW_FOV = np.radians(45.0)  # [rad] vertical field of view
TIME_AXIS: Any = {"time": False}  # plain seconds on the x axis (a uPlot scale)


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


def _colours(colour: Colour, count: int) -> NDArray[np.uint8]:
    return np.tile(np.array(colour, dtype=np.uint8), (count, 2, 1))


def _hidden_arrow(
    scene: viser.SceneApi, name: str, colour: Colour, sizes: tuple[float, float, float]
) -> viser.ArrowsHandle:
    """A hidden arrow ``/world/<name>``; sizes: shaft radius, head radius, head length [m]."""
    shaft_radius, head_radius, head_length = sizes
    return scene.add_arrows(
        f"/world/{name}",
        np.zeros((1, 2, 3)),
        colour,
        shaft_radius=shaft_radius,
        head_radius=head_radius,
        head_length=head_length,
        visible=False,
    )


class PageView:
    """The drawing of a run on a viser server.

    Args:
        server: The viser server.
        urdf: Derived URDF of the robot (absolute mesh paths) for the full robot, or
            None to draw the point-mass LIPM (CoM ball on a stick).
        controls: Adds the page's own GUI (buttons, fields), placed between the
            legend and the plots.
    """

    def __init__(
        self,
        server: viser.ViserServer,
        urdf: Path | None,
        controls: Callable[[], None] | None = None,
    ) -> None:
        self.server = server
        self.offset = np.zeros(2)  # [m] world point shown at the view's origin
        self._stance = np.zeros(2)  # [m] stance ankle, in the world
        self._last_plot = 0.0
        self._last_image = 0.0
        self._dcm_error_plot = DcmErrorPlot()
        server.scene.set_up_direction("+z")
        server.initial_camera.position = (-0.7, -2.1, 1.25)
        server.initial_camera.look_at = (0.3, -0.45, 0.4)
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
                padding=(12, 24, 0, 0),
                aspect=1.6,
            )
            self._lyapunov_top = 10.0
            self.since_step_plot = gui.add_uplot(
                (zeros, zeros),
                ({"label": "t [s]"}, {"label": "s~ [s]", "stroke": "#14aa46", "width": 2}),
                title="time since the last step s~ [s]",
                scales={"x": TIME_AXIS},
                aspect=1.6,
            )
        with gui.add_folder("View"):
            self.show_robot = gui.add_checkbox("Robot", True, hint="draw the robot's meshes")
            self.side_view_button = gui.add_button(
                "Side view", hint="camera level with the ground, beside the stance sole"
            )
        self.show_robot.on_update(lambda _: self._show_robot())
        self.side_view_button.on_click(lambda _: self.side_view())
        self._build_scene(urdf)

    # ----------------------------------------------------------------------- scene
    def _build_scene(self, urdf: Path | None) -> None:
        scene = self.server.scene
        self.world = scene.add_frame("/world", show_axes=False)
        self.grid = scene.add_grid(
            "/world/grid",
            GRID_SIZE,
            GRID_SIZE,
            cell_size=GRID_CELL,
            section_size=1.0,
            shadow_opacity=0.0,
        )
        self.robot: RobotView | None = None
        if urdf is not None:
            self.robot = RobotView(self.server, urdf, "/world/robot")
        else:
            self.com_ball = scene.add_icosphere("/world/com_ball", 0.06, (60, 60, 60))
            self.stick = scene.add_line_segments(
                "/world/stick", np.zeros((1, 2, 3)), (60, 60, 60), thickness=0.02
            )
        self.footholds_node = scene.add_line_segments(
            "/world/footholds", np.zeros((1, 2, 3)), (0, 0, 0), thickness=0.012
        )
        self.window_node = scene.add_line_segments(
            "/world/window", np.zeros((1, 2, 3)), WINDOW_COLOUR, thickness=0.008
        )
        self.trail_nodes = {
            name: scene.add_line_segments(
                f"/world/{name}_trail", np.zeros((1, 2, 3)), colour, thickness=0.006
            )
            for name, colour in (("zmp", ZMP_COLOUR), ("com", COM_COLOUR), ("dcm", DCM_COLOUR))
        }
        self.point_nodes = {
            name: scene.add_icosphere(f"/world/{name}", radius, colour)
            for name, radius, colour in (
                ("zmp", 0.022, ZMP_COLOUR),
                ("com", 0.03, COM_COLOUR),
                ("com_ground", 0.015, COM_COLOUR),
                ("dcm", 0.022, DCM_COLOUR),
            )
        }
        self.push_node = _hidden_arrow(scene, "push", PUSH_COLOUR, (0.015, 0.04, 0.08))
        self.aim_node = _hidden_arrow(scene, "aim", PREVIEW_COLOUR, (0.008, 0.025, 0.05))
        self.fall_label = scene.add_label(
            "/world/fall_label", "", visible=False, font_screen_scale=1.6, anchor="bottom-center"
        )

    def set_status(self, lines: list[str]) -> None:
        """Show the status: up to :data:`STATUS_LINES` lines of HTML, each cut to one
        line, in a block of fixed height (the controls below it never move)."""
        self.status.content = _status_html(lines)

    @staticmethod
    def _lyapunov_scales(top: float) -> Any:
        return {"x": TIME_AXIS, "y": {"distr": 3, "log": 10, "range": [RATIO_FLOOR, top]}}

    def _show_robot(self) -> None:
        if self.robot is not None:
            self.robot.visible = bool(self.show_robot.value)

    def side_view(self) -> None:
        """Every browser's camera :data:`SIDE_VIEW_HEIGHT` above the ground,
        :data:`SIDE_VIEW_DISTANCE` to the right of the stance ankle, looking at the point
        :data:`SIDE_VIEW_LOOK_HEIGHT` above it (vertical field of view :data:`SIDE_VIEW_FOV`)."""
        ankle = self._stance - self.offset
        camera = np.array([ankle[0], ankle[1] - SIDE_VIEW_DISTANCE, SIDE_VIEW_HEIGHT])
        target = np.array([ankle[0], ankle[1], SIDE_VIEW_LOOK_HEIGHT])
        for client in self.server.get_clients().values():
            client.camera.fov = float(SIDE_VIEW_FOV)
            client.camera.up_direction = (0.0, 0.0, 1.0)
            client.camera.position = camera
            client.camera.look_at = target

    # ---------------------------------------------------------------------- frames
    def show(self, snap: Snapshot, dt: float, aim: Array | None = None) -> None:
        """Draw ``snap``: one atomic scene update; plots at :data:`PLOT_RATE` and
        :data:`IMAGE_RATE`.

        Args:
            snap: What to draw.
            dt: Wall time since the last frame [s] (the view follows the robot).
            aim: Arrow of the push being aimed (start, end) [m], shape (2, 3), or None.
        """
        state = snap.state
        with self.server.atomic():
            if state is not None:
                self._stance = np.asarray(state.stance, float)
                target = np.asarray(state.com, float)
                jump = float(np.linalg.norm(target - self.offset)) > 2.0
                self.offset = target if jump or dt <= 0.0 else follow(self.offset, target, dt)
                self.world.position = (-self.offset[0], -self.offset[1], 0.0)
                cell = np.round(self.offset / 1.0) * 1.0
                self.grid.position = (cell[0], cell[1], 0.0)
                drawing = draw_scene(state, snap.foot_lower, snap.foot_upper)
                self._draw(drawing, state.stance)
                visible = aim is not None and drawing.push_arrow is None and not state.fell
                if aim is not None and visible:
                    self.aim_node.points = aim[None].astype(np.float32)
                self.aim_node.visible = visible
                self.fall_label.visible = state.fell
                if state.fell:
                    self.fall_label.text = f"FALLEN ({state.fall_reason})"
                    self.fall_label.position = (state.com[0], state.com[1], 1.2)
            if snap.robot is not None and self.robot is not None:
                pose = snap.robot
                self.robot.update(pose.base_position, pose.base_wxyz, pose.joints)
        self._plot(snap)

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

    def _draw(self, drawing: SceneDrawing, stance: Array) -> None:
        segments, colours = [], []
        for foothold in drawing.footholds:
            z = 0.002 if foothold.role == "trail" else 0.004
            seg = polyline_segments(on_ground(foothold.corners, z))
            if foothold.adjusted:  # a cross marks an adjusted step
                c = foothold.corners
                seg = np.concatenate(
                    [seg, on_ground(np.array([[c[0], c[2]], [c[1], c[3]]]), z)], axis=0
                )
            segments.append(seg)
            colours.append(_colours(foothold.colour, len(seg)))
        self.footholds_node.points = np.concatenate(segments).astype(np.float32)
        self.footholds_node.colors = np.concatenate(colours)
        self.window_node.points = polyline_segments(on_ground(drawing.window, 0.006)).astype(
            np.float32
        )
        for name, trail in (
            ("zmp", drawing.zmp_trail),
            ("com", drawing.com_trail),
            ("dcm", drawing.dcm_trail),
        ):
            self._set_polyline(self.trail_nodes[name], trail)
        self.point_nodes["zmp"].position = drawing.zmp + np.array([0.0, 0.0, 0.01])
        self.point_nodes["com"].position = drawing.com
        self.point_nodes["com_ground"].position = drawing.com * np.array([1.0, 1.0, 0.0])
        self.point_nodes["dcm"].position = drawing.dcm + np.array([0.0, 0.0, 0.01])
        if self.robot is None:
            self.com_ball.position = drawing.com
            ankle = np.array([stance[0], stance[1], 0.0])
            self.stick.points = np.array([[ankle, drawing.com]], dtype=np.float32)
        if drawing.push_arrow is not None:
            self.push_node.points = drawing.push_arrow[None].astype(np.float32)
        self.push_node.visible = drawing.push_arrow is not None

    @staticmethod
    def _set_polyline(node: viser.LineSegmentsHandle, points: Array) -> None:
        segments = polyline_segments(points)
        if len(segments) == 0:
            node.visible = False
            return
        node.points = segments.astype(np.float32)
        node.visible = True
