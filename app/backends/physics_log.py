"""Per-physics-step log of a full-robot run: contacts, CoM and soles at every step.

The control tick (10 ms) hides what happens at a touchdown: a sole that lands early
takes the weight within a few milliseconds, an impact of several kN can throw the
whole robot off the ground for tens of milliseconds, and the feet can rock in turn.
``rsg run --physics-log`` records, after every physics step, the whole-body CoM
position and velocity, each foot's normal force and CoP, and each sole's position,
its tilt from flat and its yaw, to ``physics.csv`` (SI units), so such events can be
seen and measured (a sole that rolls onto an edge, or turns on the ground under a
push's yaw moment, turns the whole robot about it); next to them,
what the controller asked for over that tick: the CoP and each foot's normal force of
the wrench distribution, and where it asked the IK to put each sole (so a gap between
plan and ground shows where it arises: a sole that lands off its target, a load the
plan did not give).

The log only observes: the run with it ends in exactly the state of the run without
it (a test checks this). PyBullet refreshes its collision transforms when asked for
forward kinematics, which changes the next contact solution slightly, so the sole
positions are read as PyBullet left them after the step's collision detection:
one physics step behind the CoM columns (3 mm for a sole moving at 1.5 m/s at G1's
2 ms step).
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

import numpy as np
from numpy.typing import NDArray

from app.backends.plant import Plant
from kinematics.robot_model import yaw_of
from planner.exceptions import RsgError
from planner.types import Foot

COLUMNS = (
    "t",
    *(f"com_{a}" for a in "xyz"),
    *(f"com_v{a}" for a in "xyz"),
    *(f"{foot}_{field}" for foot in ("left", "right") for field in ("fz", "cop_x", "cop_y")),
    *(f"{foot}_sole_{a}" for foot in ("left", "right") for a in "xyz"),
    "push_fx",
    "push_fy",
    "planned_cop_x",
    "planned_cop_y",
    "left_fz_planned",
    "right_fz_planned",
    *(f"{foot}_sole_target_{a}" for foot in ("left", "right") for a in "xyz"),
    *(f"{foot}_sole_{angle}" for foot in ("left", "right") for angle in ("tilt", "yaw")),
)


class PhysicsLog:
    """Rows of :data:`COLUMNS`, one per physics step (a foot without contact has
    zero force and its CoP as NaN; a foot given no wrench has a planned force of 0).

    A sole's tilt [rad] is the angle between its normal and the vertical (0: flat), its
    yaw [rad] the angle of its forward axis about the vertical from the world's x."""

    def __init__(self) -> None:
        self.rows: list[list[float]] = []
        self._plan = [float("nan")] * 2 + [0.0, 0.0] + [float("nan")] * 6

    def plan(
        self,
        cop: NDArray[np.float64],
        normal_forces: Mapping[Foot, float],
        sole_targets: Mapping[Foot, NDArray[np.float64]],
    ) -> None:
        """The controller's CoP [m], feet's normal forces [N] and soles' target
        positions [m] (world, shape (3,) each) for the coming tick."""
        self._plan = [float(cop[0]), float(cop[1])] + [
            float(normal_forces.get(foot, 0.0)) for foot in ("left", "right")
        ]
        for foot in ("left", "right"):
            self._plan += [float(v) for v in sole_targets[foot][:3]]

    def record(self, sim: Plant, push_force: NDArray[np.float64] | None) -> None:
        """Append the state after the physics step that ``sim`` has just taken."""
        com, velocity = sim.com_state()
        pressure = sim.foot_pressure()
        row = [sim.time, *com, *velocity]
        for foot in ("left", "right"):
            cop, force = pressure.get(foot, (np.full(2, np.nan), 0.0))
            row += [force, *cop]
        frames = [sim.sole_frame(foot, forward_kinematics=False) for foot in ("left", "right")]
        for position, _ in frames:
            row += list(position)
        push = np.zeros(2) if push_force is None else np.asarray(push_force, float)[:2]
        row += list(push)
        row += self._plan
        for _, rotation in frames:
            row += [
                float(np.arccos(np.clip(rotation[2, 2], -1.0, 1.0))),
                yaw_of(rotation),
            ]
        self.rows.append([float(value) for value in row])

    def write(self, path: Path) -> Path:
        """Write ``physics.csv``; returns ``path``.

        Raises:
            RsgError: The file cannot be written.
        """
        lines = [",".join(COLUMNS)]
        lines += [",".join(f"{value:.6g}" for value in row) for row in self.rows]
        try:
            path.write_text("\n".join(lines) + "\n")
        except OSError as exc:
            raise RsgError(f"cannot write the physics log to {path}: {exc}") from exc
        return path
