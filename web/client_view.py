"""One browser tab's 3-D view, drawn at the pace the tab draws.

Every tab has its own scene nodes (viser's client scene) and its own drawing thread.
A frame is the robot, the footholds, the ZMP window, the points and the trails in
one ``client.atomic()`` update, followed by a frame token: a localStorage read that
the browser answers while it applies the frame, in its render loop, just before it
draws it. The next frame is sent only once the token is back, so a tab that draws
one frame a second (software WebGL) always gets the newest state and never a
backlog, and a fast tab gets up to the page's frame rate. The tokens give each
tab's drawn frame rate; their keys carry the frame's push count, so a page-side
probe can tell which frame first shows a push (``benchmarks/bench_page_latency.py``).

A push acts for a tenth of a second; a tab drawing once a second would miss its
arrow, so each tab shows a new push's arrow in at least one of its frames and for
at least :data:`PUSH_SHOW_TIME` of wall time.
"""

from __future__ import annotations

import threading
import time as wallclock
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import viser
from numpy.typing import NDArray

from .robot_view import RobotView
from .scene_model import (
    COM_COLOUR,
    DCM_COLOUR,
    PREVIEW_COLOUR,
    PUSH_COLOUR,
    WINDOW_COLOUR,
    ZMP_COLOUR,
    Colour,
    SceneDrawing,
    draw_scene,
    follow,
    on_ground,
    polyline_segments,
    push_arrow,
)
from .snapshot import Snapshot

Array = NDArray[np.float64]

GRID_SIZE = 20.0  # [m]
GRID_CELL = 0.25  # [m]
ACK_TIMEOUT = 10.0  # [s] a tab that answers no token this long gets the next frame anyway
PUSH_SHOW_TIME = 1.0  # [s] wall time a new push's arrow stays drawn, at least
RATE_WINDOW = 3.0  # [s] the drawn frame rate is counted over this much wall time
FRAME_TOKEN = "rsg-frame"  # key prefix of the frame tokens: rsg-frame:<serial>:<pushes>


@dataclass(frozen=True)
class Frame:
    """What every tab should draw now.

    Attributes:
        serial: Increases with every frame published.
        snap: The run's state.
        aim: Arrow of the push being aimed (start, end) [m], shape (2, 3), or None.
        robot_visible: Draw the robot's meshes.
    """

    serial: int
    snap: Snapshot
    aim: Array | None = None
    robot_visible: bool = True


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


class ClientView:
    """The 3-D view of one tab, drawn in its own thread at the tab's pace.

    Args:
        client: The tab.
        urdf: Derived URDF of the robot, or None to draw the LIPM (CoM ball on a stick).
        latest: Returns what to draw now.
        frame_rate: Frames per second at most [Hz].
    """

    def __init__(
        self,
        client: viser.ClientHandle,
        urdf: Path | None,
        latest: Callable[[], Frame | None],
        frame_rate: float,
    ) -> None:
        self.client = client
        self._latest = latest
        self._period = 1.0 / frame_rate
        self.offset = np.zeros(2)  # [m] world point shown at the view's origin
        self.stance = np.zeros(2)  # [m] stance ankle drawn last, in the world
        self._drawn: int | None = None
        self._snap_serial = -1  # the snapshot drawn last
        self._pushes_drawn = 0
        self._push_shown: tuple[Array, float] | None = None  # (impulse, wall time until)
        self._acks: deque[float] = deque()
        self._last_frame = 0.0
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._build(urdf)
        self._thread = threading.Thread(
            target=self._run, name=f"rsg-tab-{client.client_id}", daemon=True
        )

    # ----------------------------------------------------------------------- scene
    def _build(self, urdf: Path | None) -> None:
        scene = self.client.scene
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
            self.robot = RobotView(scene, urdf, "/world/robot")
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

    # ---------------------------------------------------------------------- thread
    def start(self) -> None:
        """Start drawing."""
        self._thread.start()

    def stop(self) -> None:
        """Stop drawing (the tab left or the page stops)."""
        self._stop.set()
        self._wake.set()

    def changed(self) -> None:
        """There is something new to draw."""
        self._wake.set()

    @property
    def frame_rate(self) -> float:
        """Frames the tab drew per second over the last :data:`RATE_WINDOW` [Hz]."""
        acks = list(self._acks)
        if len(acks) < 2:
            return 0.0
        return (len(acks) - 1) / max(acks[-1] - acks[0], 1e-9)

    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait(self._period)
            self._wake.clear()
            if self._stop.is_set():
                return
            wait = self._last_frame + self._period - wallclock.perf_counter()
            if wait > 0.0:
                self._stop.wait(wait)
            frame = self._latest()
            if frame is None:
                continue
            key = frame.serial
            if key == self._drawn and not self._push_pending():
                continue
            now = wallclock.perf_counter()
            dt = now - self._last_frame if self._drawn is not None else 0.0
            self._last_frame = now
            try:
                token = self._draw(frame, dt)
                self.client.flush()
                self.client.local_storage.get_item(token, timeout=ACK_TIMEOUT)
            except TimeoutError:
                continue  # a stalled tab: send it the newest frame next time
            except RuntimeError:
                return  # the tab disconnected
            self._drawn = key
            done = wallclock.perf_counter()
            self._acks.append(done)
            while self._acks and self._acks[0] < done - RATE_WINDOW:
                self._acks.popleft()

    def _push_pending(self) -> bool:
        shown = self._push_shown
        return shown is not None and wallclock.perf_counter() < shown[1] + self._period

    # ---------------------------------------------------------------------- frames
    def _draw(self, frame: Frame, dt: float) -> str:
        """One frame of ``frame`` in one atomic update; returns its token's key."""
        snap, aim = frame.snap, frame.aim
        state = snap.state
        with self.client.atomic():
            if self.robot is not None:
                self.robot.visible = frame.robot_visible
            if state is not None:
                self.stance = np.asarray(state.stance, float)
                if snap.serial != self._snap_serial:  # the same state redrawn stays put
                    self._snap_serial = snap.serial
                    target = np.asarray(state.com, float)
                    jump = float(np.linalg.norm(target - self.offset)) > 2.0
                    self.offset = target if jump or dt <= 0.0 else follow(self.offset, target, dt)
                self.world.position = (-self.offset[0], -self.offset[1], 0.0)
                cell = np.round(self.offset / 1.0) * 1.0
                self.grid.position = (cell[0], cell[1], 0.0)
                drawing = draw_scene(state, snap.foot_lower, snap.foot_upper)
                self._draw_drawing(drawing, state.stance)
                arrow = self._push_arrow(snap, drawing)
                if arrow is not None:
                    self.push_node.points = arrow[None].astype(np.float32)
                self.push_node.visible = arrow is not None
                visible = aim is not None and arrow is None and not state.fell
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
        return f"{FRAME_TOKEN}:{snap.serial}:{self._pushes_drawn}"

    def _push_arrow(self, snap: Snapshot, drawing: SceneDrawing) -> Array | None:
        """The push arrow of this frame: the acting push's, or a push this tab has not
        shown yet (it acted between two of the tab's frames) for :data:`PUSH_SHOW_TIME`."""
        now = wallclock.perf_counter()
        state = snap.state
        if snap.pushes_applied < self._pushes_drawn:  # a reset
            self._pushes_drawn, self._push_shown = snap.pushes_applied, None
        if snap.pushes_applied > self._pushes_drawn and snap.last_push is not None:
            self._pushes_drawn = snap.pushes_applied
            self._push_shown = (np.asarray(snap.last_push, float), now + PUSH_SHOW_TIME)
        if drawing.push_arrow is not None:
            return drawing.push_arrow
        if self._push_shown is not None and state is not None and now < self._push_shown[1]:
            return push_arrow(state.com, state.com_height, self._push_shown[0])
        return None

    def _draw_drawing(self, drawing: SceneDrawing, stance: Array) -> None:
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

    @staticmethod
    def _set_polyline(node: viser.LineSegmentsHandle, points: Array) -> None:
        segments = polyline_segments(points)
        if len(segments) == 0:
            node.visible = False
            return
        node.points = segments.astype(np.float32)
        node.visible = True
