"""What the page shows at one instant, from the live simulation or from a replay.

A :class:`Snapshot` is immutable: the live simulation's thread (:mod:`web.live`) or
the replay (:mod:`web.replay_page`) makes a new one, and the page
(:mod:`web.page`) draws the latest.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import ArrayLike, NDArray

from .scene_model import ControllerState

Array = NDArray[np.float64]

TRAIL_TIME = 2.0  # [s] length of the CoM / ZMP / DCM trails
DCM_ERROR_TRAIL_TIME = 4.0  # [s] length of the e_u trail
PLOT_TIME = 10.0  # [s] time window of the plots
FOOT_MARGIN = 0.01  # [m] drawn sole = ZMP window enlarged by this margin
STEP_MARKS = 50  # past steps kept and drawn at most


def sole_corners(window_min: ArrayLike, window_max: ArrayLike) -> tuple[Array, Array]:
    """The drawn sole's corners [m]: the ZMP window enlarged by :data:`FOOT_MARGIN`."""
    return np.asarray(window_min, float) - FOOT_MARGIN, np.asarray(window_max, float) + FOOT_MARGIN


@dataclass(frozen=True)
class RobotPose:
    """Configuration of the full robot (PyBullet or MuJoCo backend).

    Attributes:
        base_position: URDF base (pelvis) position [m], shape (3,).
        base_wxyz: URDF base orientation, quaternion (w, x, y, z).
        joints: Joint angles [rad] by joint name.
    """

    base_position: Array
    base_wxyz: Array
    joints: dict[str, float]


@dataclass(frozen=True)
class PageStatus:
    """What the status line shows.

    Attributes:
        time: Simulated time [s].
        model: Backend (``lipm``, ``pybullet`` or ``mujoco``); robot: robot name.
        controller: Step controller in the loop.
        paused: Paused by the user.
        slow_motion: Requested simulated seconds per wall second [-].
        speed: Measured simulated seconds per wall second [-] (0 when stopped).
        last_event: Last push, step, fall or reset, as printed.
        fell: The robot has fallen; fall_reason: why.
        busy: What the thread is doing instead of simulating (e.g. rebuilding), or "".
        error: The last error of the simulation, or "".
    """

    time: float = 0.0
    model: str = ""
    robot: str = ""
    controller: str = ""
    paused: bool = False
    slow_motion: float = 1.0
    speed: float = 0.0
    last_event: str = ""
    fell: bool = False
    fall_reason: str = ""
    busy: str = ""
    error: str = ""

    @property
    def advancing(self) -> bool:
        """The run moves on: not paused, fallen, busy or stopped by an error."""
        return not (self.paused or self.fell or self.busy or self.error)


@dataclass(frozen=True)
class Snapshot:
    """The state of the run at one instant, immutable.

    Attributes:
        serial: Increases with every snapshot.
        state: Controller state, or None before the first tick.
        robot: Full-robot configuration, or None on the LIPM.
        status: Status line content.
        plot_time: Times [s] of the plot samples (a window of the last seconds).
        plot_lyapunov: V_u at those times.
        plot_time_since_step: s~ [s] at those times.
        level_set: Points of {V_u = level} for a level (the Lyapunov design's).
        foot_lower, foot_upper: Sole corners around the ankle [m], shape (2,).
        mass: Robot mass [kg].
        pushes_applied: Number of pushes applied since the last reset.
        last_push: Impulse of the last push applied [N s], shape (2,), or None.
        adjusted_steps: Number of adjusted steps since the last reset.
    """

    serial: int
    state: ControllerState | None
    robot: RobotPose | None
    status: PageStatus
    plot_time: Array = field(default_factory=lambda: np.zeros(0))
    plot_lyapunov: Array = field(default_factory=lambda: np.zeros(0))
    plot_time_since_step: Array = field(default_factory=lambda: np.zeros(0))
    level_set: Callable[[float], Array] | None = None
    foot_lower: Array = field(default_factory=lambda: np.array([-0.1, -0.05]))
    foot_upper: Array = field(default_factory=lambda: np.array([0.1, 0.05]))
    mass: float = 0.0
    pushes_applied: int = 0
    adjusted_steps: int = 0
    last_push: Array | None = None
