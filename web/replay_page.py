"""The replay's page: :class:`web.page.PageView` driven by a recorded run.

The same drawing as the live demo (robot, footholds, ZMP window, DCM-error plot,
V_u plot, push arrows), with a time slider, Play/Pause and the playback speed.
Snapshots come from the recording (:mod:`web.replay_source`); no simulation runs.
Playback stops at the end of the run; Play there starts it again from 0.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import Any

import viser

from app.results.replay import ReplayData

from .page import PageView
from .replay_source import snapshot_at
from .worker import FrameLoop

FRAME_RATE = 20.0  # [Hz] frames while playing
SPEEDS = {"0.1x": 0.1, "0.25x": 0.25, "0.5x": 0.5, "1x (real time)": 1.0, "2x": 2.0}


def _set_value(handle: Any, value: object) -> None:
    handle.value = value


class ReplayPage(FrameLoop):
    """A recorded run on a viser server.

    Args:
        server: The viser server.
        replay: The recorded run.
        folder: Where it was read from (shown on the page).
        urdf: Derived URDF of the robot for a full-robot run, else None.
        frame_rate: Frames per second while playing [Hz].
    """

    def __init__(
        self,
        server: viser.ViserServer,
        replay: ReplayData,
        folder: Path,
        urdf: Path | None,
        frame_rate: float = FRAME_RATE,
    ) -> None:
        self.server = server
        self.replay = replay
        self.folder = folder
        super().__init__(frame_rate, "rsg-replay")
        self.time = 0.0  # [s] replay time shown
        self.playing = False
        self._speed = 1.0
        self._serial = 0
        self._dirty = True
        self.view = PageView(server, urdf, controls=self._build_controls, frame_rate=frame_rate)

    def stop(self, timeout: float = 5.0) -> None:
        """Stop publishing and every tab's drawing."""
        super().stop(timeout)
        self.view.stop()

    def _build_controls(self) -> None:
        gui = self.server.gui
        replay = self.replay
        period = float(replay.meta["record_period"])
        with gui.add_folder("Replay"):
            self.time_slider = gui.add_slider(
                "Time [s]", 0.0, round(replay.duration, 2), period, 0.0
            )
            self.play_button = gui.add_button("Play")
            self.speed = gui.add_dropdown("Speed", tuple(SPEEDS), initial_value="1x (real time)")
        self.time_slider.on_update(self._scrubbed)
        self.play_button.on_click(lambda _: self._toggle())
        self.speed.on_update(lambda _: self._set_speed())

    def _scrubbed(self, event: viser.GuiEvent) -> None:
        if event.client is None:  # moved by playback
            return
        self.time = float(self.time_slider.value)
        self._dirty = True

    def _toggle(self) -> None:
        if not self.playing and self.time >= self.replay.duration - 1e-9:
            self.time = 0.0
        self.playing = not self.playing
        self.play_button.label = "Pause" if self.playing else "Play"
        self._dirty = True

    def _set_speed(self) -> None:
        self._speed = SPEEDS[self.speed.value]
        self._dirty = True

    def _frame(self, now: float, dt: float) -> bool:
        """Move the replay time on while playing; draw when it moved or changed."""
        if self.playing:
            self.time = min(self.time + dt * self._speed, self.replay.duration)
            if self.time >= self.replay.duration:
                self.playing = False
                self.play_button.label = "Play"
                self._dirty = True  # draw the end once more, paused
            _set_value(self.time_slider, round(self.time, 2))
        if self.playing or self._dirty:
            self._dirty = False
            self.show(dt if self.playing else 0.0)
        return True

    def show(self, dt: float = 0.0) -> None:
        """Draw the replay at :attr:`time`."""
        self._serial += 1
        snap = snapshot_at(self.replay, self.time, self._serial, paused=not self.playing)
        meta = self.replay.meta
        outcome = (
            f"fell ({meta['fall_reason']}) at {meta['sim_time']:.2f} s"
            if meta["fell"]
            else f"no fall in {meta['sim_time']:.2f} s"
        )
        state = "playing" if self.playing else "paused"
        self.view.set_status(
            [
                f'<b>replay</b> of <code title="{html.escape(str(self.folder.resolve()))}">'
                f"{html.escape(self.folder.name)}</code>",
                f"<b>t = {snap.status.time:.2f} s</b> of {self.replay.duration:.2f} · {state} "
                f"({self._speed:g}x)",
                f"controller <b>{meta['controller']}</b> · {meta['model']} {meta['robot']} · "
                f"scenario {html.escape(meta['scenario'])}",
                f"pushes {snap.pushes_applied} of {len(self.replay.pushes)} · adjusted steps "
                f"{snap.adjusted_steps} · {html.escape(outcome)}",
            ]
        )
        self.view.show(snap, dt)
