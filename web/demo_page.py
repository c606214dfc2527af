"""The live demo's page: :class:`web.page.PageView` plus the controls of the simulation.

The page reads :meth:`web.live.LiveSimulation.snapshot` in its own thread and draws
it (:attr:`DemoPage.frame_rate` frames per second while the simulation runs). GUI
callbacks only send requests to the simulation thread, so nothing here waits for
the simulation. Any browser tab can push, pause or reset the run.

Push fields are text fields (:mod:`web.push_input`): a typed value is read once
the user has stopped typing for :data:`FIELD_SETTLE_TIME` (or at once when Push
is pressed); the field then shows the value that will be used (720 deg becomes 0,
an impulse above the robot's bound the bound), and an empty or non-numeric entry
is refused: the field shows the value in use again and the page says so. A push
with a zero impulse, or into a run that is paused, fallen or stopped, is refused
and not logged as a push. The aim arrow shows for :data:`AIM_TIME` after the user
changes the push; the push arrow shows while a push acts.
"""

from __future__ import annotations

import html
import time as wallclock
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
import viser
from numpy.typing import NDArray

from planner.parameters import CONTROLLERS

from .live import SLOW_MOTION_FACTORS, LiveSimulation
from .page import PageView
from .push_input import (
    FieldValue,
    PushBounds,
    PushInput,
    clamp_push,
    format_field,
    paper_presets,
    push_refusal,
    read_field,
    wrap_degrees,
)
from .scene_model import direction_towards, push_arrow, ray_ground_intersection
from .snapshot import Snapshot
from .worker import FrameLoop

Array = NDArray[np.float64]

FRAME_RATE = 40.0  # [Hz] scene updates while the simulation runs
FIELD_SETTLE_TIME = 1.5  # [s] a typed field is read once the user stopped typing this long
AIM_TIME = 4.0  # [s] the aim arrow shows this long after the push was changed
CUSTOM = "custom"
SLOW_MOTION_LABELS = {
    f"{f:g}x" + (" (real time)" if f == 1.0 else ""): f for f in SLOW_MOTION_FACTORS
}


def _set_value(handle: Any, value: object) -> None:
    """Set a GUI input's value (viser's setter, which mypy sees as read-only)."""
    handle.value = value


def _note_html(text: str, refused: bool = False) -> str:
    """The note under Push: two lines of fixed height (the panel below does not move)."""
    colour = "#c0392b" if refused else "#555555"
    return (
        f'<div style="height:2.6em;line-height:1.3em;overflow:hidden;font-size:0.8em;'
        f'color:{colour}">{html.escape(text)}</div>'
    )


@dataclass
class _Field:
    """A push field: its handle, value in use, and text typed but not read yet."""

    handle: Any
    name: str
    unit: str
    normalise: Callable[[float], float]
    value: float
    pending: str | None = None
    typed_at: float = 0.0


class DemoPage(FrameLoop):
    """The live demo's page on a viser server, driven by a live simulation.

    Args:
        server: The viser server.
        live: The simulation to show and control.
        urdf: Derived URDF of the robot (absolute mesh paths) for the full robot, or
            None to draw the point-mass LIPM (CoM ball on a stick).
        log: Called with a line for the user's actions (aim, refused pushes)
            (default: print).
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
        self.live = live
        super().__init__(frame_rate, "rsg-page")
        self._log = log or (lambda line: print(line, flush=True))
        self._last_serial = -1
        self._dirty = True
        self._frames: list[float] = []
        self._aim_until = 0.0
        self._note = ""
        self.update_rate = 0.0  # [Hz] scene updates over the last second
        first = live.snapshot()
        self._bounds = PushBounds.for_mass(first.mass)
        self._presets = paper_presets(first.mass)
        self.view = PageView(server, urdf, controls=self._build_controls)
        server.scene.on_click()(self._on_click)

    # ------------------------------------------------------------------------- GUI
    def _build_controls(self) -> None:
        gui = self.server.gui
        self.reset_button = gui.add_button("Reset", hint="the robot stands again, the run restarts")
        self.pause_button = gui.add_button("Pause")
        first = next(iter(self._presets.values()))
        bounds = self._bounds
        with gui.add_folder("Push"):
            self.preset = gui.add_dropdown("Preset", (*self._presets, CUSTOM), initial_value=CUSTOM)
            impulse_max = format_field(bounds.impulse_max)
            self.fields = {
                "direction": _Field(
                    gui.add_text(
                        "Direction [deg]",
                        format_field(first.direction),
                        hint="0 = forward (+x), 90 = left (+y); any angle, wrapped to "
                        "(-180, 180]. Or click the ground to aim.",
                    ),
                    "direction",
                    "deg",
                    wrap_degrees,
                    first.direction,
                ),
                "impulse": _Field(
                    gui.add_text(
                        "Impulse [N s]",
                        format_field(first.impulse),
                        hint=f"more than 0, at most {impulse_max} N s for this robot",
                    ),
                    "impulse",
                    "N s",
                    lambda v: float(np.clip(v, 0.0, bounds.impulse_max)),
                    first.impulse,
                ),
                "duration": _Field(
                    gui.add_text(
                        "Duration [s]",
                        format_field(first.duration),
                        hint=f"{format_field(bounds.duration_min)} to "
                        f"{format_field(bounds.duration_max)} s",
                    ),
                    "duration",
                    "s",
                    lambda v: float(np.clip(v, bounds.duration_min, bounds.duration_max)),
                    first.duration,
                ),
            }
            self.push_button = gui.add_button("Push", color="red")
            self.push_note = gui.add_html(_note_html("Click the ground to aim from the robot."))
        with gui.add_folder("Simulation", expand_by_default=False):
            self.slow_motion = gui.add_dropdown(
                "Slow motion",
                tuple(SLOW_MOTION_LABELS),
                initial_value=next(iter(SLOW_MOTION_LABELS)),
            )
            self.controller = gui.add_dropdown(
                "Controller", CONTROLLERS, initial_value=self.live.controller
            )
        self.push_button.on_click(lambda _: self._push())
        self.reset_button.on_click(lambda _: self.live.request_reset())
        self.pause_button.on_click(lambda _: self._toggle_pause())
        self.preset.on_update(lambda _: self._apply_preset())
        for field in self.fields.values():
            field.handle.on_update(lambda event, f=field: self._typed(f, event))
        self.slow_motion.on_update(
            lambda _: self.live.set_slow_motion(SLOW_MOTION_LABELS[self.slow_motion.value])
        )
        self.controller.on_update(lambda _: self.live.request_controller(self.controller.value))

    def push_input(self) -> PushInput:
        """The push the fields hold (the values in use), in the safe ranges."""
        values = {name: field.value for name, field in self.fields.items()}
        return clamp_push(values["direction"], values["impulse"], values["duration"], self._bounds)

    def _typed(self, field: _Field, event: viser.GuiEvent) -> None:
        if event.client is None:  # set by the page itself
            return
        field.pending = str(field.handle.value)
        field.typed_at = wallclock.perf_counter()
        if self.preset.value != CUSTOM:
            _set_value(self.preset, CUSTOM)
        self._aimed()

    def _settle_fields(self, now: float | None = None) -> list[str]:
        """Read the fields typed into (all of them if ``now`` is None, else those
        left alone for :data:`FIELD_SETTLE_TIME`); returns why texts were refused."""
        refused = []
        for field in self.fields.values():
            if field.pending is None:
                continue
            if now is not None and now - field.typed_at < FIELD_SETTLE_TIME:
                continue
            read: FieldValue = read_field(
                field.pending, field.value, field.name, field.unit, field.normalise
            )
            field.pending = None
            field.value = read.value
            if field.handle.value != read.text:
                _set_value(field.handle, read.text)
            if read.refused:
                refused.append(read.refused)
        if refused:
            self._say("; ".join(refused), refused=True)
        return refused

    def _say(self, text: str, refused: bool = False) -> None:
        self._note = text
        self.push_note.content = _note_html(text, refused)

    def _push(self) -> None:
        refused = self._settle_fields()
        push = self.push_input()
        why = "; ".join(refused) or push_refusal(push)
        status = self.live.snapshot().status
        if not why and not status.advancing:
            why = (
                "the run is not advancing ("
                + (
                    "paused: press Resume"
                    if status.paused
                    else "fallen: press Reset"
                    if status.fell
                    else status.busy or status.error
                )
                + ")"
            )
        if why:
            self._say(f"push refused: {why}", refused=True)
            self._log(f"push refused: {why}")
            return
        self._say("Click the ground to aim from the robot.")
        self.live.request_push(push)

    def _toggle_pause(self) -> None:
        paused = not self.live.snapshot().status.paused
        self.live.set_paused(paused)
        self.pause_button.label = "Resume" if paused else "Pause"

    def _apply_preset(self) -> None:
        preset = self._presets.get(self.preset.value)
        if preset is None:
            return
        for name, value in (
            ("direction", preset.direction),
            ("impulse", preset.impulse),
            ("duration", preset.duration),
        ):
            field = self.fields[name]
            field.value, field.pending = value, None
            _set_value(field.handle, format_field(value))
        self._aimed()

    def _aimed(self) -> None:
        self._aim_until = wallclock.perf_counter() + AIM_TIME
        self._dirty = True

    def _on_click(self, event: viser.SceneClickEvent) -> None:
        point = ray_ground_intersection(event.ray_origin, event.ray_direction)
        state = self.live.snapshot().state
        if point is None or state is None:
            return
        target = point + self.view.offset
        direction = direction_towards(state.com, target)
        if direction is not None:
            x, y = target
            self._log(f"aim direction={direction:.0f} deg towards ({x:.2f}, {y:.2f}) m")
            field = self.fields["direction"]
            field.value, field.pending = float(round(direction)), None
            _set_value(field.handle, format_field(field.value))
            _set_value(self.preset, CUSTOM)
            self._aimed()

    # ---------------------------------------------------------------- render thread
    def _frame(self, now: float, dt: float) -> bool:
        """Draw when there is something new (a snapshot, a change, the aim arrow)."""
        self._settle_fields(now)
        snap = self.live.snapshot()
        aiming = now < self._aim_until
        if snap.serial == self._last_serial and not self._dirty and not aiming:
            return False
        self._dirty = aiming  # one more frame once the aim arrow expires
        self._last_serial = snap.serial
        try:
            self.update(snap, dt)
        except Exception as exc:  # noqa: BLE001 - keep the page alive, say why
            self.view.set_status([f"page update failed: {html.escape(repr(exc))}"])
        self._frames = [t for t in self._frames if t > now - 1.0] + [now]
        self.update_rate = float(len(self._frames))
        return True

    def update(self, snap: Snapshot, dt: float) -> None:
        """Show ``snap`` (status, scene, plots)."""
        state = snap.state
        aim = None
        if state is not None and wallclock.perf_counter() < self._aim_until:
            aim = push_arrow(state.com, state.com_height, self.push_input().impulse_xy())
        self._update_status(snap)
        self.view.show(snap, dt, aim)

    def _update_status(self, snap: Snapshot) -> None:
        s = snap.status
        if s.error:
            state = f"<b>stopped</b>: {html.escape(s.error)}. Press Reset."
        elif s.busy:
            state = f"<b>{s.busy} ...</b>"
        elif s.fell:
            state = (
                f'<b style="color:#c0392b">FALLEN</b> ({html.escape(s.fall_reason)}): press Reset'
            )
        elif s.paused:
            state = "<b>paused</b>"
        else:
            state = "running"
        robot = s.robot if s.model != "lipm" else ""
        self.view.set_status(
            [
                f"<b>t = {s.time:.2f} s</b> · {state} · controller <b>{s.controller}</b> · "
                f"{s.model} {robot}",
                f"speed {s.speed:.2f}x real time (asked {s.slow_motion:g}x) · "
                f"page {self.update_rate:.0f} Hz",
                f"pushes {snap.pushes_applied} · adjusted steps {snap.adjusted_steps}",
                f"<small>last event: {html.escape(s.last_event or '-')}</small>",
            ]
        )
        self.pause_button.label = "Resume" if s.paused else "Pause"
        if self.push_button.disabled == s.advancing:
            self.push_button.disabled = not s.advancing
