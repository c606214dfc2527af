"""The live demo's page: :class:`web.page.PageView` plus the controls of the simulation.

The page reads :meth:`web.live.LiveSimulation.snapshot` in its own thread and draws
it (:attr:`DemoPage.frame_rate` frames per second while the simulation runs). GUI
callbacks only send requests to the simulation thread, so nothing here waits for
the simulation. Any browser tab can push, pause or reset the run.

Push fields are text fields (:mod:`web.push_input`) that the page never rewrites
while the user types: they are read when Push is pressed, from what they hold at
that moment. A field that is empty, not a number or out of its range refuses the
push, on the page (the field, its text, the range allowed) and in the log; nothing
is clipped. The direction is wrapped to (-180, 180] deg, as its hint says. viser's
page sends a field's last key and a click at most every 50 ms, keeping only the
latest, so a Push pressed within :data:`TYPING_GUARD` of the last key received is
refused too ("press Push again") rather than applied with a text the user did not
see. A push into a run that is paused, fallen or stopped is refused the same way.
The aim arrow shows for :data:`AIM_TIME` after the user changes the push; the push
arrow shows while a push acts (each tab draws it at least once).
"""

from __future__ import annotations

import html
import time as wallclock
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import viser
from numpy.typing import NDArray

from planner.parameters import CONTROLLERS

from .live import SLOW_MOTION_FACTORS, LiveSimulation
from .page import PageView
from .push_input import (
    PushBounds,
    PushInput,
    field_rules,
    format_field,
    paper_presets,
    read_push,
)
from .scene_model import direction_towards, push_arrow, ray_ground_intersection
from .snapshot import Snapshot
from .worker import FrameLoop

Array = NDArray[np.float64]

FRAME_RATE = 40.0  # [Hz] scene updates while the simulation runs
TYPING_GUARD = 0.12  # [s] a Push this soon after a field's last key is refused (see above)
AIM_TIME = 4.0  # [s] the aim arrow shows this long after the push was changed
CUSTOM = "custom"
DEFAULT_NOTE = "Click the ground to aim from the robot."
SLOW_MOTION_LABELS = {
    f"{f:g}x" + (" (real time)" if f == 1.0 else ""): f for f in SLOW_MOTION_FACTORS
}


def _set_value(handle: Any, value: object) -> None:
    """Set a GUI input's value (viser's setter, which mypy sees as read-only)."""
    handle.value = value


def _rates(rates: list[float]) -> str:
    """Each tab's drawn frame rate, e.g. "1.0, 24"."""
    return ", ".join(f"{r:.1f}" if r < 10.0 else f"{r:.0f}" for r in rates) or "-"


def _note_html(text: str, refused: bool = False) -> str:
    """The note under Push: two lines of fixed height (the panel below does not move)."""
    colour = "#c0392b" if refused else "#555555"
    return (
        f'<div style="height:2.6em;line-height:1.3em;overflow:hidden;font-size:0.8em;'
        f'color:{colour}">{html.escape(text)}</div>'
    )


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
        self._note = ("", False)
        self.update_rate = 0.0  # [Hz] scene updates over the last second
        first = live.snapshot()
        self._bounds = PushBounds.for_mass(first.mass)
        self._presets = paper_presets(first.mass)
        self.view = PageView(server, urdf, controls=self._build_controls, frame_rate=frame_rate)
        server.scene.on_click()(self._on_click)

    def stop(self, timeout: float = 5.0) -> None:
        """Stop publishing and every tab's drawing."""
        super().stop(timeout)
        self.view.stop()

    # ------------------------------------------------------------------------- GUI
    def _build_controls(self) -> None:
        gui = self.server.gui
        self.reset_button = gui.add_button("Reset", hint="the robot stands again, the run restarts")
        self.pause_button = gui.add_button("Pause")
        first = next(iter(self._presets.values()))
        rules = field_rules(self._bounds)
        self._push = first  # the last push the fields held (drawn as the aim arrow)
        with gui.add_folder("Push"):
            self.preset = gui.add_dropdown("Preset", (*self._presets, CUSTOM), initial_value=CUSTOM)
            self.fields = {
                "direction": gui.add_text(
                    "Direction [deg]",
                    format_field(first.direction),
                    hint="0 = forward (+x), 90 = left (+y); "
                    f"{rules['direction'].allowed()}, wrapped to (-180, 180]. "
                    "Or click the ground to aim.",
                ),
                "impulse": gui.add_text(
                    "Impulse [N s]",
                    format_field(first.impulse),
                    hint=f"{rules['impulse'].allowed()} for this robot",
                ),
                "duration": gui.add_text(
                    "Duration [s]", format_field(first.duration), hint=rules["duration"].allowed()
                ),
            }
            self.push_button = gui.add_button("Push", color="red")
            self.push_note = gui.add_html(_note_html(DEFAULT_NOTE))
        with gui.add_folder("Simulation", expand_by_default=False):
            asked = self.live.snapshot().status.slow_motion
            self.slow_motion = gui.add_dropdown(
                "Speed",
                tuple(SLOW_MOTION_LABELS),
                initial_value=next(k for k, v in SLOW_MOTION_LABELS.items() if v == asked),
            )
            self.controller = gui.add_dropdown(
                "Controller", CONTROLLERS, initial_value=self.live.controller
            )
        self.push_button.on_click(lambda event: self._pressed(event.client))
        self.reset_button.on_click(lambda _: self._reset())
        self.pause_button.on_click(lambda _: self._toggle_pause())
        self.preset.on_update(lambda _: self._apply_preset())
        for handle in self.fields.values():
            handle.on_update(self._typed)
        self.slow_motion.on_update(
            lambda _: self.live.set_slow_motion(SLOW_MOTION_LABELS[self.slow_motion.value])
        )
        self.controller.on_update(lambda _: self.live.request_controller(self.controller.value))

    def texts(self) -> dict[str, str]:
        """What the push fields hold now, as the server last received it."""
        return {name: str(handle.value) for name, handle in self.fields.items()}

    def push_input(self) -> PushInput:
        """The last push the fields held that could be applied (the aim arrow's)."""
        read = read_push(self.texts(), self._bounds)
        if isinstance(read, PushInput):
            self._push = read
        return self._push

    def _typed(self, event: viser.GuiEvent) -> None:
        if event.client is None:  # set by the page itself
            return
        if self.preset.value != CUSTOM:
            _set_value(self.preset, CUSTOM)
        self._say(DEFAULT_NOTE)
        self._aimed()

    def _say(self, text: str, refused: bool = False) -> None:
        if (text, refused) != self._note:
            self._note = (text, refused)
            self.push_note.content = _note_html(text, refused)

    def _refuse(self, why: str) -> None:
        self._say(f"push refused: {why}", refused=True)
        self._log(f"push refused: {why}")

    def _pressed(self, client: object | None = None) -> None:
        """Push pressed: the fields as they are now, or a refusal that says why."""
        pressed_at = self.push_button.update_timestamp
        read = read_push(self.texts(), self._bounds)
        if not isinstance(read, PushInput):
            self._refuse("; ".join(read))
            return
        typed_at = max(handle.update_timestamp for handle in self.fields.values())
        if client is not None and pressed_at - typed_at < TYPING_GUARD:
            self._refuse(
                f"Push pressed {1000 * max(pressed_at - typed_at, 0.0):.0f} ms after a key: "
                "the page may not have sent the last one; press Push again"
            )
            return
        status = self.live.snapshot().status
        if not status.advancing:
            self._refuse(
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
            return
        self._push = read
        typed = self.fields["direction"].value.strip()
        wrapped = "" if float(typed) == read.direction else f" ({typed} deg wrapped)"
        self._say(
            f"pushed {format_field(read.impulse)} N s towards {format_field(read.direction)} "
            f"deg{wrapped} over {format_field(read.duration)} s"
        )
        self.live.request_push(read)

    def _reset(self) -> None:
        self._say(DEFAULT_NOTE)
        self.live.request_reset()

    def _toggle_pause(self) -> None:
        self._say(DEFAULT_NOTE)
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
            _set_value(self.fields[name], format_field(value))
        self._say(DEFAULT_NOTE)
        self._aimed()

    def _aimed(self) -> None:
        self._aim_until = wallclock.perf_counter() + AIM_TIME
        self._dirty = True

    def _on_click(self, event: viser.SceneClickEvent) -> None:
        point = ray_ground_intersection(event.ray_origin, event.ray_direction)
        state = self.live.snapshot().state
        view = self.view.view_of(event.client)
        if point is None or state is None or view is None:
            return
        target = point + view.offset
        direction = direction_towards(state.com, target)
        if direction is not None:
            x, y = target
            self._log(f"aim direction={direction:.0f} deg towards ({x:.2f}, {y:.2f}) m")
            _set_value(self.fields["direction"], format_field(float(round(direction))))
            _set_value(self.preset, CUSTOM)
            self._say(DEFAULT_NOTE)
            self._aimed()

    # ---------------------------------------------------------------- render thread
    def _frame(self, now: float, dt: float) -> bool:
        """Publish when there is something new (a snapshot, a change, the aim arrow)."""
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
                f"tabs draw {_rates(self.view.tab_rates())} frames/s",
                f"pushes {snap.pushes_applied} · adjusted steps {snap.adjusted_steps}",
                f"<small>last event: {html.escape(s.last_event or '-')}</small>",
            ]
        )
        self.pause_button.label = "Resume" if s.paused else "Pause"
        if self.push_button.disabled == s.advancing:
            self.push_button.disabled = not s.advancing
