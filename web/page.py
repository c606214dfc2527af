"""The viser page of the browser demo: GUI, scene nodes, and the render thread.

The page reads :meth:`web.live.LiveSimulation.snapshot`, turns it into a
:class:`web.scene_model.SceneDrawing` and updates the scene nodes in one
``server.atomic()`` block per frame (:data:`FRAME_RATE` Hz). GUI callbacks only send
requests to the simulation thread, so nothing here waits for the simulation.

All GUI and scene nodes are server-wide: every browser tab sees the same
simulation, and any tab can push, pause or reset it.

View: the scene root ``/world`` is shifted so that the robot stays near the origin
of the view (the ground grid scrolls under it). The DCM-error panel (the paper's
Fig. 6(c)) is a flat inset on the ground beside the robot, fixed in the view.
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

from planner.parameters import CONTROLLERS

from .live import SLOW_MOTION_FACTORS, LiveSimulation, Snapshot
from .robot_view import RobotView
from .scene_model import (
    COM_COLOUR,
    DCM_COLOUR,
    EU_TRAIL_COLOUR,
    LEVEL_COLOUR,
    PREVIEW_COLOUR,
    PUSH_COLOUR,
    THRESHOLD_COLOUR,
    WINDOW_COLOUR,
    ZMP_COLOUR,
    Colour,
    EuPanel,
    PushBounds,
    PushInput,
    SceneDrawing,
    clamp_push,
    direction_towards,
    draw_scene,
    follow,
    on_ground,
    paper_presets,
    polyline_segments,
    push_arrow,
    ray_ground_intersection,
)
from .worker import Worker

Array = NDArray[np.float64]

FRAME_RATE = 40.0  # [Hz] scene updates while the simulation runs
PLOT_RATE = 5.0  # [Hz] plot updates
PANEL_ORIGIN = np.array([0.2, -1.0, 0.004])  # [m] e_u panel centre, in the view
PANEL_HALF_SIZE = 0.35  # [m]
GRID_SIZE = 20.0  # [m]
GRID_CELL = 0.25  # [m]
CUSTOM = "custom"
TIME_SCALES: dict = {"x": {"time": False}}  # plain seconds on the x axis
SLOW_MOTION_LABELS = {
    f"{f:g}x" + (" (real time)" if f == 1.0 else ""): f for f in SLOW_MOTION_FACTORS
}
LEGEND = """\
<small>
<b>Feet</b>: <span style="color:#1e6ee6">stance</span>, <span style="color:#787878">previous</span>,
<span style="color:#14aa46">planned next step</span>, past steps (grey; <span
style="color:#e11e1e">red: adjusted by the RSG</span>).
<b>Points</b>: <span style="color:#c800c8">ZMP</span>, <span style="color:#141414">CoM</span>,
<span style="color:#00aac8">DCM</span> with 2 s trails; <span style="color:#f59600">ZMP window
W(r_H)</span>; push arrow red while it acts, light orange = aim.
<b>e_u panel</b> (square beside the robot, Fig. 6(c)): DCM error e_u ×scale,
<span style="color:#e11e1e">V_u = γ_v</span>, <span style="color:#1e6ee6">V_u = current
level</span>, black = last 4 s of e_u. <b>Click the ground</b> to aim the push.
</small>"""


def _set_value(handle: Any, value: object) -> None:
    """Set a GUI input's value (viser's setter, which mypy sees as read-only)."""
    handle.value = value


def _colours(colour: Colour, count: int) -> NDArray[np.uint8]:
    return np.tile(np.array(colour, dtype=np.uint8), (count, 2, 1))


class DemoPage:
    """The demo's page on a viser server, driven by a live simulation.

    Args:
        server: The viser server.
        live: The simulation to show and control.
        urdf: Derived URDF of the robot (absolute mesh paths) for the full robot, or
            None to draw the point-mass LIPM (CoM ball on a stick).
        log: Called with a line when the user aims by clicking (default: print).
        frame_rate: Scene updates per second while the simulation runs [Hz].
    """

    def __init__(
        self,
        server: viser.ViserServer,
        live: LiveSimulation,
        urdf: Path | None,
        log: Callable[[str], None] | None = None,
        frame_rate: float = FRAME_RATE,
    ) -> None:
        self.server = server
        self.frame_rate = frame_rate
        self._log = log or (lambda line: print(line, flush=True))
        self.live = live
        self._worker = Worker(self._run, "rsg-page")
        self._offset = np.zeros(2)
        self._last_serial = -1
        self._last_plot = 0.0
        self._dirty = True
        self._frames: list[float] = []
        self.update_rate = 0.0  # [Hz] scene updates over the last second
        first = live.snapshot()
        self._bounds = PushBounds.for_mass(first.mass)
        self._presets = paper_presets(first.mass)
        self._panel: EuPanel | None = None
        server.scene.set_up_direction("+z")
        server.initial_camera.position = (-0.7, -2.1, 1.25)
        server.initial_camera.look_at = (0.3, -0.45, 0.4)
        self._build_gui()
        self._build_scene(urdf)
        server.scene.on_click()(self._on_click)

    # ------------------------------------------------------------------------- GUI
    def _build_gui(self) -> None:
        gui = self.server.gui
        self.fall_alert = gui.add_markdown("", visible=False)
        self.status = gui.add_markdown("starting ...")
        self.reset_button = gui.add_button("Reset", hint="the robot stands again, the run restarts")
        self.pause_button = gui.add_button("Pause")
        with gui.add_folder("Push"):
            first = next(iter(self._presets.values()))
            self.preset = gui.add_dropdown("Preset", (*self._presets, CUSTOM), initial_value=CUSTOM)
            self.direction = gui.add_slider(
                "Direction [deg]", -180.0, 180.0, 1.0, round(first.direction)
            )
            self.impulse = gui.add_slider(
                "Impulse [N s]",
                0.0,
                round(self._bounds.impulse_max, 1),
                0.1,
                round(first.impulse, 1),
            )
            self.duration = gui.add_slider(
                "Duration [s]",
                self._bounds.duration_min,
                self._bounds.duration_max,
                0.01,
                first.duration,
            )
            self.push_button = gui.add_button("Push", color="red")
            gui.add_markdown("<small>Click the ground to aim from the robot.</small>")
        with gui.add_folder("Simulation"):
            self.slow_motion = gui.add_dropdown(
                "Slow motion",
                tuple(SLOW_MOTION_LABELS),
                initial_value=next(iter(SLOW_MOTION_LABELS)),
            )
            self.controller = gui.add_dropdown(
                "Controller", CONTROLLERS, initial_value=self.live.controller
            )
        with gui.add_folder("Plots"):
            zeros = np.zeros(2)
            self.lyapunov_plot = gui.add_uplot(
                (zeros, zeros, zeros),
                (
                    {"label": "t [s]"},
                    {"label": "V_u", "stroke": "#1e6ee6", "width": 2},
                    {"label": "γ_v", "stroke": "#e11e1e", "dash": (6.0, 4.0)},
                ),
                title="V_u(t) against γ_v",
                scales=TIME_SCALES,
                aspect=1.6,
            )
            self.since_step_plot = gui.add_uplot(
                (zeros, zeros),
                ({"label": "t [s]"}, {"label": "s~ [s]", "stroke": "#14aa46", "width": 2}),
                title="time since the last step [s]",
                scales=TIME_SCALES,
                aspect=1.6,
            )
        with gui.add_folder("Legend", expand_by_default=False):
            gui.add_html(LEGEND)

        self.push_button.on_click(lambda _: self._push())
        self.reset_button.on_click(lambda _: self.live.request_reset())
        self.pause_button.on_click(lambda _: self._toggle_pause())
        self.preset.on_update(lambda _: self._apply_preset())
        for handle in (self.direction, self.impulse, self.duration):
            handle.on_update(lambda _: self._mark_dirty())
        self.slow_motion.on_update(
            lambda _: self.live.set_slow_motion(SLOW_MOTION_LABELS[self.slow_motion.value])
        )
        self.controller.on_update(lambda _: self.live.request_controller(self.controller.value))

    def push_input(self) -> PushInput:
        """The push set in the GUI, clamped to the safe ranges."""
        return clamp_push(
            float(self.direction.value),
            float(self.impulse.value),
            float(self.duration.value),
            self._bounds,
        )

    def _push(self) -> None:
        self.live.request_push(self.push_input())

    def _toggle_pause(self) -> None:
        paused = not self.live.snapshot().status.paused
        self.live.set_paused(paused)
        self.pause_button.label = "Resume" if paused else "Pause"

    def _apply_preset(self) -> None:
        preset = self._presets.get(self.preset.value)
        if preset is not None:
            _set_value(self.direction, round(preset.direction))
            _set_value(self.impulse, round(preset.impulse, 1))
            _set_value(self.duration, preset.duration)
        self._mark_dirty()

    def _mark_dirty(self) -> None:
        self._dirty = True

    def _on_click(self, event: viser.SceneClickEvent) -> None:
        point = ray_ground_intersection(event.ray_origin, event.ray_direction)
        state = self.live.snapshot().state
        if point is None or state is None:
            return
        direction = direction_towards(state.com, point + self._offset)
        if direction is not None:
            self._log(
                f"aim direction={direction:.0f} deg towards ({point[0] + self._offset[0]:.2f}, "
                f"{point[1] + self._offset[1]:.2f}) m"
            )
            _set_value(self.direction, round(direction))
            _set_value(self.preset, CUSTOM)
            self._mark_dirty()

    # ----------------------------------------------------------------------- scene
    def _build_scene(self, urdf: Path | None) -> None:
        scene = self.server.scene
        self.world = scene.add_frame("/world", show_axes=False)
        self.grid = scene.add_grid(
            "/world/grid", GRID_SIZE, GRID_SIZE, cell_size=GRID_CELL, section_size=1.0
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
        self.push_node = scene.add_arrows(
            "/world/push",
            np.zeros((1, 2, 3)),
            PUSH_COLOUR,
            shaft_radius=0.015,
            head_radius=0.04,
            head_length=0.08,
            visible=False,
        )
        self.aim_node = scene.add_arrows(
            "/world/aim",
            np.zeros((1, 2, 3)),
            PREVIEW_COLOUR,
            shaft_radius=0.008,
            head_radius=0.025,
            head_length=0.05,
        )
        self.fall_label = scene.add_label(
            "/world/fall_label", "", visible=False, font_screen_scale=1.6, anchor="bottom-center"
        )
        # The e_u panel, fixed in the view beside the robot.
        panel = scene.add_frame("/eu_panel", show_axes=False, position=PANEL_ORIGIN)
        del panel
        h = PANEL_HALF_SIZE
        border = np.array([[-h, -h], [h, -h], [h, h], [-h, h], [-h, -h]])
        axes = np.array([[[-h, 0, 0], [h, 0, 0]], [[0, -h, 0], [0, h, 0]]])
        scene.add_line_segments(
            "/eu_panel/frame",
            np.concatenate([polyline_segments(on_ground(border)), axes]),
            (150, 150, 150),
            thickness=0.004,
        )
        scene.add_label(
            "/eu_panel/title",
            "DCM error e_u (red: V_u = γ_v, blue: current V_u)",
            position=(-h, h + 0.02, 0.0),
            anchor="bottom-left",
            font_screen_scale=0.8,
        )
        self.threshold_node = scene.add_line_segments(
            "/eu_panel/threshold", np.zeros((1, 2, 3)), THRESHOLD_COLOUR, thickness=0.008
        )
        self.level_node = scene.add_line_segments(
            "/eu_panel/level", np.zeros((1, 2, 3)), LEVEL_COLOUR, thickness=0.006
        )
        self.eu_trail_node = scene.add_line_segments(
            "/eu_panel/trail", np.zeros((1, 2, 3)), EU_TRAIL_COLOUR, thickness=0.005
        )
        self.eu_point = scene.add_icosphere("/eu_panel/point", 0.02, EU_TRAIL_COLOUR)

    # ---------------------------------------------------------------- render thread
    def start(self) -> None:
        """Start updating the page (idempotent)."""
        self._worker.start()

    def stop(self, timeout: float = 5.0) -> None:
        """Stop updating the page."""
        self._worker.stop(timeout)

    def _run(self, stop: threading.Event) -> None:
        period = 1.0 / self.frame_rate
        last = wallclock.perf_counter()
        while not stop.is_set():
            start = wallclock.perf_counter()
            snap = self.live.snapshot()
            if snap.serial != self._last_serial or self._dirty:
                self._dirty = False
                self._last_serial = snap.serial
                try:
                    self.update(snap, start - last)
                except Exception as exc:  # noqa: BLE001 - keep the page alive, say why
                    self.status.content = f"page update failed: {exc!r}"
                last = start
                self._frames = [t for t in self._frames if t > start - 1.0] + [start]
                self.update_rate = float(len(self._frames))
            stop.wait(max(0.0, period - (wallclock.perf_counter() - start)))

    def update(self, snap: Snapshot, dt: float) -> None:
        """Show ``snap`` (one atomic scene update; plots at :data:`PLOT_RATE`)."""
        state = snap.state
        with self.server.atomic():
            self._update_status(snap)
            if state is not None and snap.level_set is not None:
                if self._panel is None:
                    self._panel = EuPanel.fitting(snap.level_set, state.threshold, PANEL_HALF_SIZE)
                target = np.asarray(state.com, float)
                jump = float(np.linalg.norm(target - self._offset)) > 2.0
                self._offset = target if jump else follow(self._offset, target, dt)
                self.world.position = (-self._offset[0], -self._offset[1], 0.0)
                cell = np.round(self._offset / 1.0) * 1.0
                self.grid.position = (cell[0], cell[1], 0.0)
                drawing = draw_scene(
                    state, snap.level_set, self._panel, snap.foot_lower, snap.foot_upper
                )
                self._update_drawing(drawing, state.stance)
                self._update_aim(state.com, state.com_height, state.fell, drawing)
                self.fall_label.visible = state.fell
                if state.fell:
                    self.fall_label.text = f"FALLEN ({state.fall_reason}): press Reset"
                    self.fall_label.position = (state.com[0], state.com[1], 1.2)
            if snap.robot is not None and self.robot is not None:
                pose = snap.robot
                self.robot.update(pose.base_position, pose.base_wxyz, pose.joints)
        now = wallclock.perf_counter()
        if now - self._last_plot >= 1.0 / PLOT_RATE and len(snap.plot_time) >= 2:
            self._last_plot = now
            threshold = state.threshold if state is not None else 0.0
            self.lyapunov_plot.data = (
                snap.plot_time,
                snap.plot_lyapunov,
                np.full_like(snap.plot_time, threshold),
            )
            self.since_step_plot.data = (snap.plot_time, snap.plot_time_since_step)

    def _update_status(self, snap: Snapshot) -> None:
        s = snap.status
        if s.error:
            state = f"**stopped**: {s.error}. Press Reset."
        elif s.busy:
            state = f"**{s.busy} ...**"
        elif s.fell:
            state = "**FALLEN**"
        elif s.ended:
            state = "**run ended** (time limit): press Reset"
        elif s.paused:
            state = "**paused**"
        else:
            state = "running"
        self.status.content = (
            f"**t = {s.time:.2f} s** · {state} · controller **{s.controller}** · "
            f"{s.model} {s.robot if s.model != 'lipm' else ''}  \n"
            f"speed {s.speed:.2f}x real time (asked {s.slow_motion:g}x) · "
            f"page {self.update_rate:.0f} Hz · pushes {snap.pushes_applied} · "
            f"adjusted steps {snap.adjusted_steps}  \n"
            f"<small>last event: {s.last_event or '-'}</small>"
        )
        self.fall_alert.visible = s.fell
        if s.fell:
            self.fall_alert.content = (
                f"### The robot has fallen\n{s.fall_reason} at t = {s.time:.2f} s. "
                "Press **Reset** to stand it up and restart."
            )
        self.pause_button.label = "Resume" if s.paused else "Pause"

    def _update_drawing(self, drawing: SceneDrawing, stance: Array) -> None:
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
        self._set_polyline(self.threshold_node, on_ground(drawing.threshold_curve))
        self._set_polyline(self.level_node, on_ground(drawing.level_curve))
        self._set_polyline(self.eu_trail_node, on_ground(drawing.dcm_error_trail))
        self.eu_point.position = (*drawing.dcm_error_point, 0.01)
        self.eu_point.color = THRESHOLD_COLOUR if drawing.above_threshold else EU_TRAIL_COLOUR

    def _update_aim(self, com: Array, height: float, fell: bool, drawing: SceneDrawing) -> None:
        aim = push_arrow(com, height, self.push_input().impulse_xy())
        visible = aim is not None and drawing.push_arrow is None and not fell
        if aim is not None and visible:
            self.aim_node.points = aim[None].astype(np.float32)
        self.aim_node.visible = visible

    @staticmethod
    def _set_polyline(node: viser.LineSegmentsHandle, points: Array) -> None:
        segments = polyline_segments(points)
        if len(segments) == 0:
            node.visible = False
            return
        node.points = segments.astype(np.float32)
        node.visible = True
