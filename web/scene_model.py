"""What the browser demo draws for a given controller state: a pure model, no viser.

Everything here is plain NumPy so it can be tested without a browser:

- :class:`ControllerState`: one snapshot of the closed loop (CoM, ZMP, window
  centre r_H, footholds, DCM error e_u, Lyapunov level V_u, recent trails);
- :func:`draw_scene`: what is drawn in the 3-D view for it (:class:`SceneDrawing`):
  footholds with their colours, the ZMP window W(r_H) as a rectangle, ZMP/CoM/DCM
  points and trails, and the push arrow while a push acts;
- the click on the ground (:func:`ray_ground_intersection`, :func:`direction_towards`).

The DCM-error plot and V_u(t) are drawn by :mod:`web.plots`; the push input is
:mod:`web.push_input`.

Frames: world frame, x forward, y left, z up [m]. Colours are RGB 0-255.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np
from numpy.typing import NDArray

from planner.types import Foot

Array = NDArray[np.float64]
Colour = tuple[int, int, int]

STANCE_COLOUR: Colour = (30, 110, 230)  # current stance foot: blue
PREVIOUS_COLOUR: Colour = (120, 120, 120)  # previous stance foot: grey
NEXT_COLOUR: Colour = (20, 170, 70)  # planned next step: green
TRAIL_COLOUR: Colour = (190, 190, 190)  # past nominal steps: light grey
ADJUSTED_COLOUR: Colour = (225, 30, 30)  # steps adjusted by the RSG: red
WINDOW_COLOUR: Colour = (245, 150, 0)  # ZMP window W(r_H): orange
ZMP_COLOUR: Colour = (200, 0, 200)  # ZMP: magenta
COM_COLOUR: Colour = (20, 20, 20)  # CoM: black
DCM_COLOUR: Colour = (0, 170, 200)  # DCM: cyan
PUSH_COLOUR: Colour = (225, 30, 30)  # acting push: red
PREVIEW_COLOUR: Colour = (255, 190, 60)  # push about to be applied: light orange
THRESHOLD_COLOUR: Colour = (225, 30, 30)  # {V_u = gamma_v}: red
LEVEL_COLOUR: Colour = (30, 110, 230)  # {V_u = current level}: blue
EU_TRAIL_COLOUR: Colour = (20, 20, 20)  # recent e_u: black

RAY_EPSILON = 1e-9  # [-] |ray z component| below which a ray is parallel to the ground


# ------------------------------------------------------------------------ click on ground
def ray_ground_intersection(
    origin: Array | tuple[float, float, float],
    direction: Array | tuple[float, float, float],
    height: float = 0.0,
) -> Array | None:
    """Where a ray meets the horizontal plane z = ``height``.

    Args:
        origin: Ray origin [m], shape (3,).
        direction: Ray direction, shape (3,) (any length > 0).
        height: Height of the plane [m].

    Returns:
        The (x, y) point [m], or None when the ray is parallel to the plane, points
        away from it, or is not finite.
    """
    o = np.asarray(origin, dtype=float).reshape(-1)
    d = np.asarray(direction, dtype=float).reshape(-1)
    if (
        o.shape != (3,)
        or d.shape != (3,)
        or not (np.all(np.isfinite(o)) and np.all(np.isfinite(d)))
    ):
        return None
    norm = float(np.linalg.norm(d))
    if norm == 0.0:
        return None
    d = d / norm
    if abs(d[2]) < RAY_EPSILON:
        return None
    distance = (height - o[2]) / d[2]
    if distance < 0.0:
        return None
    return (o + distance * d)[:2]


def direction_towards(start: Array, target: Array) -> float | None:
    """Direction [deg] from ``start`` to ``target`` in the ground plane, None if they coincide."""
    delta = np.asarray(target, dtype=float)[:2] - np.asarray(start, dtype=float)[:2]
    if float(np.linalg.norm(delta)) < 1e-6:
        return None
    return math.degrees(math.atan2(delta[1], delta[0]))


# -------------------------------------------------------------------------- state & trails
class Trail:
    """The last ``capacity`` points of a path, oldest first.

    Args:
        capacity: Number of points kept (>= 2).
        dimension: Size of one point.
    """

    def __init__(self, capacity: int, dimension: int = 2) -> None:
        if capacity < 2:
            raise ValueError(f"trail capacity {capacity}: expected >= 2")
        self._buffer = np.zeros((capacity, dimension))
        self._count = 0
        self._next = 0

    def append(self, point: Array | tuple[float, ...]) -> None:
        """Add a point (drops the oldest one when full)."""
        self._buffer[self._next] = point
        self._next = (self._next + 1) % len(self._buffer)
        self._count = min(self._count + 1, len(self._buffer))

    def clear(self) -> None:
        """Forget every point."""
        self._count = 0
        self._next = 0

    def __len__(self) -> int:
        return self._count

    def points(self) -> Array:
        """The points, oldest first, shape (n, dimension) (a copy)."""
        if self._count < len(self._buffer):
            return self._buffer[: self._count].copy()
        return np.roll(self._buffer, -self._next, axis=0)


@dataclass(frozen=True)
class StepMark:
    """A step taken: where, which foot, and whether the RSG adjusted it.

    Attributes:
        time: Step time [s].
        foot: The new stance foot.
        position: Its ankle position [m], shape (2,).
        adjusted: Step time or location adjusted by the RSG.
    """

    time: float
    foot: Foot
    position: Array
    adjusted: bool


@dataclass(frozen=True)
class ControllerState:
    """One snapshot of the closed loop, as the page needs it.

    Attributes:
        time: Simulated time [s].
        com: Horizontal CoM c_H [m], shape (2,).
        com_velocity: Horizontal CoM velocity [m/s], shape (2,).
        com_height: CoM height c_z [m].
        omega: LIPM natural frequency sqrt(g / c_z) [1/s].
        zmp: Commanded ZMP [m], shape (2,).
        window_center: r_H, the centre of the ZMP window [m], shape (2,).
        window_min: Lower corner w^m of W around r_H [m], shape (2,).
        window_max: Upper corner w^M of W around r_H [m], shape (2,).
        stance_foot: Current stance foot; stance: its ankle position [m].
        previous_foot: Previous stance foot; previous: its ankle position [m].
        next_foot: Foot of the planned next step; next_step: its position [m]
            (moves as the QP re-plans).
        steps: Steps taken so far (most recent last).
        dcm_error: e_u [m], shape (2,).
        lyapunov: V_u(e_u) [m^2 scale of P_u].
        threshold: gamma_v.
        time_since_step: s~ [s].
        push_impulse: Impulse of the push acting now [N s], or None.
        fell: The robot has fallen; fall_reason: why.
        com_trail, zmp_trail, dcm_trail: Recent positions [m], shape (n, 2), oldest first.
        dcm_error_trail: Recent e_u [m], shape (n, 2), oldest first.
    """

    time: float
    com: Array
    com_velocity: Array
    com_height: float
    omega: float
    zmp: Array
    window_center: Array
    window_min: Array
    window_max: Array
    stance_foot: Foot
    stance: Array
    previous_foot: Foot
    previous: Array
    next_foot: Foot
    next_step: Array
    steps: tuple[StepMark, ...] = ()
    dcm_error: Array = field(default_factory=lambda: np.zeros(2))
    lyapunov: float = 0.0
    threshold: float = 1.0
    time_since_step: float = 0.0
    push_impulse: Array | None = None
    fell: bool = False
    fall_reason: str = ""
    com_trail: Array = field(default_factory=lambda: np.zeros((0, 2)))
    zmp_trail: Array = field(default_factory=lambda: np.zeros((0, 2)))
    dcm_trail: Array = field(default_factory=lambda: np.zeros((0, 2)))
    dcm_error_trail: Array = field(default_factory=lambda: np.zeros((0, 2)))

    @property
    def dcm(self) -> Array:
        """DCM xi = c + c_dot / omega [m], shape (2,)."""
        return np.asarray(self.com, float) + np.asarray(self.com_velocity, float) / self.omega


# ------------------------------------------------------------------------------ drawing
@dataclass(frozen=True)
class FootholdDrawing:
    """A foothold outline on the ground.

    Attributes:
        role: ``"stance"``, ``"previous"``, ``"next"`` (outlines) or ``"trail"``
            (past steps, drawn filled).
        foot: Which foot.
        corners: Closed outline [m], shape (5, 2).
        colour: RGB colour.
        adjusted: The step was adjusted by the RSG.
    """

    role: str
    foot: Foot
    corners: Array
    colour: Colour
    adjusted: bool = False


@dataclass(frozen=True)
class SceneDrawing:
    """Everything drawn for one controller state (world frame, z up) [m].

    Attributes:
        footholds: Trail of past steps first, then previous, next and stance outlines.
        window: ZMP window W(r_H), closed rectangle, shape (5, 2).
        zmp, com, dcm: Points, shape (3,) (ZMP and DCM on the ground, CoM at c_z).
        zmp_trail, com_trail, dcm_trail: Recent paths, shape (n, 3).
        push_arrow: Start and end of the push arrow (ends at the CoM), shape (2, 3),
            or None when no push acts.
    """

    footholds: list[FootholdDrawing]
    window: Array
    zmp: Array
    com: Array
    dcm: Array
    zmp_trail: Array
    com_trail: Array
    dcm_trail: Array
    push_arrow: Array | None


def rectangle(center: Array, lower: Array, upper: Array) -> Array:
    """Closed outline of the box [center + lower, center + upper] [m], shape (5, 2)."""
    c = np.asarray(center, dtype=float)
    lo = c + np.asarray(lower, dtype=float)
    hi = c + np.asarray(upper, dtype=float)
    return np.array([[lo[0], lo[1]], [hi[0], lo[1]], [hi[0], hi[1]], [lo[0], hi[1]], lo])


def polyline_segments(points: Array) -> Array:
    """Consecutive points as segments, shape (n - 1, 2, k) (empty for n < 2)."""
    p = np.asarray(points, dtype=float)
    if len(p) < 2:
        return np.zeros((0, 2, p.shape[-1] if p.ndim == 2 else 3))
    return np.stack([p[:-1], p[1:]], axis=1)


def on_ground(points: Array, height: float = 0.0) -> Array:
    """(x, y) points [m] (shape (..., 2)) lifted to z = ``height``, shape (..., 3)."""
    p = np.asarray(points, dtype=float)
    return np.concatenate([p, np.full((*p.shape[:-1], 1), height)], axis=-1)


def push_arrow(com: Array, com_height: float, impulse: Array | None) -> Array | None:
    """Arrow of a push: pointing along ``impulse`` and ending at the CoM.

    Its length grows with the impulse: 0.15 m + 0.05 m per N s, at most 0.8 m.

    Returns:
        Start and end [m], shape (2, 3), or None without a (non-zero) impulse.
    """
    if impulse is None:
        return None
    i = np.asarray(impulse, dtype=float)
    magnitude = float(np.linalg.norm(i))
    if not math.isfinite(magnitude) or magnitude < 1e-9:
        return None
    length = min(0.15 + 0.05 * magnitude, 0.8)
    end = np.array([com[0], com[1], com_height])
    start = end - length * np.array([i[0], i[1], 0.0]) / magnitude
    return np.stack([start, end])


def footholds(
    state: ControllerState, foot_lower: Array, foot_upper: Array, trail_length: int = 12
) -> list[FootholdDrawing]:
    """Foothold outlines: past steps (adjusted ones red), previous, next and stance.

    Args:
        state: The controller state.
        foot_lower: Sole corner behind/right of the ankle [m], shape (2,).
        foot_upper: Sole corner ahead/left of the ankle [m], shape (2,).
        trail_length: Number of past steps drawn.
    """
    drawings = [
        FootholdDrawing(
            "trail",
            step.foot,
            rectangle(step.position, foot_lower, foot_upper),
            ADJUSTED_COLOUR if step.adjusted else TRAIL_COLOUR,
            step.adjusted,
        )
        for step in state.steps[-trail_length:]
    ]
    stance_adjusted = bool(
        state.steps
        and state.steps[-1].foot == state.stance_foot
        and np.allclose(state.steps[-1].position, state.stance)
        and state.steps[-1].adjusted
    )
    drawings += [
        FootholdDrawing(
            "previous",
            state.previous_foot,
            rectangle(state.previous, foot_lower, foot_upper),
            PREVIOUS_COLOUR,
        ),
        FootholdDrawing(
            "next", state.next_foot, rectangle(state.next_step, foot_lower, foot_upper), NEXT_COLOUR
        ),
        FootholdDrawing(
            "stance",
            state.stance_foot,
            rectangle(state.stance, foot_lower, foot_upper),
            STANCE_COLOUR,
            stance_adjusted,
        ),
    ]
    return drawings


def draw_scene(state: ControllerState, foot_lower: Array, foot_upper: Array) -> SceneDrawing:
    """What is drawn in the 3-D view for ``state``.

    Args:
        state: The controller state.
        foot_lower, foot_upper: Sole corners around the ankle [m], shape (2,).
    """
    return SceneDrawing(
        footholds=footholds(state, foot_lower, foot_upper),
        window=rectangle(state.window_center, state.window_min, state.window_max),
        zmp=on_ground(state.zmp),
        com=on_ground(state.com, state.com_height),
        dcm=on_ground(state.dcm),
        zmp_trail=on_ground(state.zmp_trail),
        com_trail=on_ground(state.com_trail, state.com_height),
        dcm_trail=on_ground(state.dcm_trail),
        push_arrow=push_arrow(state.com, state.com_height, state.push_impulse),
    )


def follow(current: Array, target: Array, dt: float, time_constant: float = 0.5) -> Array:
    """First-order smoothing of the view centre towards ``target`` [m] over ``dt`` [s]."""
    if dt <= 0.0:
        return np.asarray(current, dtype=float)
    alpha = 1.0 - math.exp(-dt / time_constant)
    c = np.asarray(current, dtype=float)
    return c + alpha * (np.asarray(target, dtype=float) - c)
