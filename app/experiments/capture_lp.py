"""The capture bound's computation: one linear relaxation per set of step-time windows,
refined by branch and bound (the model and its limits: :mod:`app.experiments.capturability`; the
derivation: ``docs/bound.md``).

Why one long module: the relaxation and its branch and bound share the programme's
construction (``_Programme``).

A node is a tuple of windows [a_k, b_k] holding the times tau_k of the first steps after
the push start; the last may be open, [a, inf): that step, and all later ones, come at a
or later, or never. For a node one linear programme maximises the impulse over what a
controller chooses (the CMP over time, the steps), each limit relaxed so that every
trajectory whose step times lie in the windows stays feasible. Its value is an upper
limit for those step times:

- Time is cut into cells (at most ``CELL`` long, split at the push end, the windows and
  the ends of double support). In a cell the CMP r(t) is free within [L, U]; it moves
  the state at later instants only through two weighted means, P (weight e^(-omega s),
  moves xi) and Q (weight e^(omega s), moves zeta). Over all r(t) in [L, U], (P, Q)
  covers L + (U - L) S, S a thin convex lens; the programme keeps (P, Q) inside
  ``LENS_SIDES`` tangent half-planes of it (exact support values), a superset.
- [L, U] is affine in the steps: the stance foot's window; in double support, and while
  a step may or may not have happened, the hull of both feet's windows (max(0, u) over
  a step range of both signs replaced by its chord, which lies above it).
- The leg reach holds at every cell boundary, on the circumscribed ``POLYGON_SIDES``-gon
  of the disc; while a step may or may not have happened, within reach of either foot,
  relaxed to the hull of the two discs.
- At the end (``min_step_time`` after the last window opens, or where an open window
  opens) the DCM offset from the stance ankle lies in the per-axis capture interval
  (:func:`app.experiments.capturability.capture_edges`, no reach), a push still acting counted as
  the DCM jump of what is left of it.

Branch and bound: the root is [t_first, inf). An open window [a, inf) is split into
[a, a + ``LEAF_WIDTH``] and [a + ``LEAF_WIDTH``, inf); a closed one is followed by the
next step's open window, [a + T_min, inf), until ``EXPLICIT_STEPS`` steps are explicit.
The node of largest value is refined first. Its value bounds every open node, hence all
step times, whenever the search stops: at an explicit leaf, at an open window a whole
T_min after its earliest time, when splitting an open window no longer lowers it
(stepping later does no better), within ``TOLERANCE`` of a leaf, or at ``MAX_NODES``.
"""

from __future__ import annotations

import heapq
import math
from dataclasses import dataclass
from functools import lru_cache

import numpy as np
from scipy.optimize import linprog
from scipy.sparse import csr_matrix

from app.experiments.capturability import CaptureEdges, CaptureModel, capture_edges
from planner.exceptions import RsgError

CELL = 0.04  # [s] longest time cell of the CMP means (finer cells gave the same bounds)
LEAF_WIDTH = 0.01  # [s] width of a step-time window
EXPLICIT_STEPS = 2  # steps with their own window; later ones through the capture interval
POLYGON_SIDES = 16  # of the reach polygon (circumradius 1.02 x the reach)
LENS_SIDES = 8  # tangent half-planes of each cell's lens (16 gave the same bounds)
REACH_DELAY = 1e-3  # [s] the LIPM backend checks a new foot's reach one 1 ms tick on
MAX_NODES = 300
TOLERANCE = 5e-3  # [-] relative

Window = tuple[float, float]


def _unit_circle(sides: int) -> list[tuple[float, float]]:
    angles = [2.0 * math.pi * k / sides for k in range(sides)]
    return [(math.cos(angle), math.sin(angle)) for angle in angles]


_POLYGON = _unit_circle(POLYGON_SIDES)


@dataclass(frozen=True)
class PushCase:
    """The state and the push the bound is computed for.

    Attributes:
        com: c - o at the push start, relative to the stance ankle [m], shape (2,).
        velocity: cdot at the push start [m/s], shape (2,).
        sigma: Stance foot (+1 left, -1 right).
        time_since_step: s~ at the push start [s].
        previous_step: The step that began the stance, o - o_previous [m], shape (2,).
        direction: Unit push direction, shape (2,).
        duration: Push duration Delta [s] (constant force).
    """

    com: np.ndarray
    velocity: np.ndarray
    sigma: int
    time_since_step: float
    previous_step: np.ndarray
    direction: np.ndarray
    duration: float


@dataclass(frozen=True)
class BoundResult:
    """Result of :func:`largest_impulse`.

    Attributes:
        impulse: The upper limit [N s].
        windows: Step-time windows of the node that gave it [s] (from the push start).
        nodes: Nodes refined.
        programs: Linear programmes solved.
    """

    impulse: float
    windows: tuple[Window, ...]
    nodes: int
    programs: int


def largest_impulse(model: CaptureModel, case: PushCase) -> BoundResult:
    """Upper limit on the impulse [N s] any controller captures (module docstring).

    Raises:
        RsgError: No step times are feasible even without a push, or a programme failed.
    """
    edges = capture_edges(model)
    t_first = max(0.0, model.min_step_time - case.time_since_step)

    def earliest(node: tuple[Window, ...]) -> float:  # for the last window's step
        return t_first if len(node) == 1 else node[-2][0] + model.min_step_time

    def is_final(node: tuple[Window, ...]) -> bool:
        start, end = node[-1]
        if math.isinf(end):
            return start - earliest(node) >= model.min_step_time - 1e-9
        return len(node) == EXPLICIT_STEPS

    root: tuple[Window, ...] = ((t_first, math.inf),)
    # Entries: (-value, order, node, value of the open window it was split from).
    heap = [(-_relaxed_impulse(model, case, edges, root), 0, root, math.inf)]
    best_final, nodes, programs = -math.inf, 0, 1
    while heap:
        negative, _, node, parent = heapq.heappop(heap)
        value = -negative  # an upper limit over every open node, hence over all step times
        nodes += 1
        start, end = node[-1]
        flat = math.isinf(end) and math.isfinite(parent) and value >= parent * (1 - TOLERANCE)
        if is_final(node) or flat or value <= best_final * (1.0 + TOLERANCE) or nodes >= MAX_NODES:
            return BoundResult(max(value, 0.0), node, nodes, programs)
        if math.isinf(end):
            split = start + LEAF_WIDTH
            children = [node[:-1] + ((start, split),), node[:-1] + ((split, end),)]
        else:
            children = [node + ((start + model.min_step_time, math.inf),)]
        for child in children:
            child_value = _relaxed_impulse(model, case, edges, child)
            programs += 1
            if is_final(child):
                best_final = max(best_final, child_value)
            if child_value > -math.inf:
                origin = value if math.isinf(end) and math.isinf(child[-1][1]) else math.inf
                heapq.heappush(heap, (-child_value, programs, child, origin))
    raise RsgError("the capture bound found no feasible step times, even without a push")


def _chord_of_max(low: float, high: float) -> tuple[float, float]:
    """(c0, c1) with c0 + c1 u >= max(0, u) on [low, high], equal at both ends."""
    if low >= 0.0:
        return 0.0, 1.0
    if high <= 0.0:
        return 0.0, 0.0
    slope = high / (high - low)
    return -slope * low, slope


def _chord_of_min(low: float, high: float) -> tuple[float, float]:
    """(c0, c1) with c0 + c1 u <= min(0, u) on [low, high], equal at both ends."""
    if low >= 0.0:
        return 0.0, 0.0
    if high <= 0.0:
        return 0.0, 1.0
    slope = -low / (high - low)
    return -slope * high, slope


@lru_cache(maxsize=4096)
def _lens(omega: float, length: float) -> tuple[tuple[float, float, float], ...]:
    """(alpha, beta, support) of the lens S of a cell ``length`` [s] long.

    S = {(int_0^h e^(-w t) v / K1, int_0^h e^(w t) v / K2) : 0 <= v(t) <= 1}, with K1, K2
    the integrals of the weights; its support in (alpha, beta) is the integral of the
    positive part of alpha e^(-w t) / K1 + beta e^(w t) / K2, which changes sign at most
    once.
    """
    w, h = omega, length
    k1, k2 = (1.0 - math.exp(-w * h)) / w, (math.exp(w * h) - 1.0) / w
    out = []
    for alpha, beta in _unit_circle(LENS_SIDES):
        a, b = alpha / k1, beta / k2
        cuts = [0.0, h]
        if a * b < 0.0 and 0.0 < math.log(-a / b) / (2.0 * w) < h:
            cuts = [0.0, math.log(-a / b) / (2.0 * w), h]
        support = 0.0
        for t0, t1 in zip(cuts, cuts[1:], strict=False):
            middle = 0.5 * (t0 + t1)
            if a * math.exp(-w * middle) + b * math.exp(w * middle) > 0.0:
                support += a * (math.exp(-w * t0) - math.exp(-w * t1)) / w
                support += b * (math.exp(w * t1) - math.exp(w * t0)) / w
        out.append((alpha, beta, support))
    return tuple(out)


class _Programme:
    """The relaxation of one node: variables, state rows and constraint rows.

    Variables: z = (i [N s], u_1, ..., u_n [m] (x, y each), P per cell and axis, Q per
    cell and axis [m]). The state at a time point is affine in z.
    """

    def __init__(self, model: CaptureModel, case: PushCase, windows: tuple[Window, ...]) -> None:
        self.model, self.case = model, case
        open_last = math.isinf(windows[-1][1])
        self.steps = windows[:-1] if open_last else windows
        self.end = windows[-1][0] if open_last else windows[-1][0] + model.min_step_time
        self.points = self._time_points()
        n_cells = len(self.points) - 1
        self.n_steps, self.n_cells = len(self.steps), n_cells
        self.n_var = 1 + 2 * self.n_steps + 4 * n_cells
        self.rows: list[np.ndarray] = []
        self.limits: list[float] = []
        w, points = model.omega, self.points
        lag = points[:, None] - points[None, 1:]
        lead = points[:, None] - points[None, :-1]
        mask = lag >= -1e-12
        # xi(t_b) = e^(w t_b) xi0 + sum_c g_xi[b, c] P_c + i d push_xi[b]; zeta alike.
        self.g_xi = np.where(mask, np.exp(w * lag) - np.exp(w * lead), 0.0)
        self.g_zeta = np.where(mask, np.exp(-w * lag) - np.exp(-w * lead), 0.0)
        self.scale = model.mass * w * w * case.duration
        pushed = np.minimum(points, case.duration)
        self.push_xi = (np.exp(w * points) - np.exp(w * (points - pushed))) / self.scale
        self.push_zeta = (np.exp(-w * points) - np.exp(-w * (points - pushed))) / self.scale
        self.xi0 = case.com + case.velocity / w
        self.zeta0 = case.com - case.velocity / w

    def _time_points(self) -> np.ndarray:
        model, case = self.model, self.case
        marks = {self.end, case.duration, model.double_support_duration - case.time_since_step}
        for start, stop in self.steps:
            marks.update((start, stop, stop + REACH_DELAY, stop + model.double_support_duration))
        marks.update(np.arange(0.0, self.end, CELL).tolist())
        points = [0.0]
        for mark in sorted(m for m in marks if 0.0 < m <= self.end + 1e-12):
            if mark - points[-1] > 1e-9:
                points.append(mark)
        return np.array(points)

    # -- indices and affine expressions
    def step_var(self, k: int, axis: int) -> int:
        """Index of u_k (k >= 1) along ``axis``."""
        return 1 + 2 * (k - 1) + axis

    def sigma_before(self, k: int) -> int:
        """The stance step k is taken from."""
        return self.case.sigma * (-1 if (k - 1) % 2 else 1)

    def foot(self, j: int, axis: int) -> np.ndarray:
        """o_j - o_0 as a row over the variables."""
        row = np.zeros(self.n_var)
        for k in range(1, j + 1):
            row[self.step_var(k, axis)] = 1.0
        return row

    def window_at(self, t: float, delay: float = 0.0) -> int | None:
        """k when step k may or may not have happened at ``t`` (``delay`` after its window)."""
        for k, (start, stop) in enumerate(self.steps, 1):
            if start - 1e-9 <= t < stop + delay - 1e-9:
                return k
        return None

    def stance_at(self, t: float) -> int:
        """Number of steps certainly taken at ``t``."""
        return sum(1 for _, stop in self.steps if stop <= t + 1e-9)

    def dcm(self, index: int, axis: int, whole_push: bool = False) -> tuple[np.ndarray, float]:
        """xi at ``points[index]`` as (row, constant); ``whole_push``: with what is left
        of the push added as a jump."""
        t, w = float(self.points[index]), self.model.omega
        row = np.zeros(self.n_var)
        push = self.push_xi[index]
        if whole_push:
            push = (math.exp(w * t) - math.exp(w * (t - self.case.duration))) / self.scale
        row[0] = self.case.direction[axis] * push
        first = 1 + 2 * self.n_steps + axis
        row[first : first + 2 * self.n_cells : 2] = self.g_xi[index]
        return row, math.exp(w * t) * self.xi0[axis]

    def com(self, index: int, axis: int) -> tuple[np.ndarray, float]:
        """c = (xi + zeta) / 2 at ``points[index]`` as (row, constant)."""
        t, w = float(self.points[index]), self.model.omega
        row, const = self.dcm(index, axis)
        row = 0.5 * row
        row[0] += 0.5 * self.case.direction[axis] * self.push_zeta[index]
        first = 1 + 2 * self.n_steps + 2 * self.n_cells + axis
        row[first : first + 2 * self.n_cells : 2] += 0.5 * self.g_zeta[index]
        return row, 0.5 * (const + math.exp(-w * t) * self.zeta0[axis])

    # -- constraints
    def add(self, row: np.ndarray, limit: float) -> None:
        self.rows.append(row)
        self.limits.append(limit)

    def cmp_rows(self) -> None:
        """(P, Q) of each cell inside the lens of its CMP bounds."""
        model, case = self.model, self.case
        t_dsp = model.double_support_duration
        for cell in range(self.n_cells):
            t0, t1 = float(self.points[cell]), float(self.points[cell + 1])
            middle = 0.5 * (t0 + t1)
            window = self.window_at(middle)
            var = window if window is not None else self.stance_at(middle)
            for axis in (0, 1):
                r_lo, r_hi = model.cmp_min[axis], model.cmp_max[axis]
                # U = o_ref + up0 + up1 u_var, L = o_ref + lo0 + lo1 u_var
                if var == 0:
                    back = -case.previous_step[axis]  # the previous foot, from this one
                    in_dsp = case.time_since_step + t0 < t_dsp - 1e-12
                    up0 = r_hi + (max(0.0, back) if in_dsp else 0.0)
                    lo0 = r_lo + (min(0.0, back) if in_dsp else 0.0)
                    up1 = lo1 = 0.0
                    base = self.foot(0, axis)
                else:
                    in_dsp = window is not None or t0 < self.steps[var - 1][1] + t_dsp - 1e-12
                    low, high = model.step_range(axis, self.sigma_before(var))
                    up0, up1, lo0, lo1 = r_hi, 1.0, r_lo, 1.0
                    if in_dsp:  # between o_{var-1} and o_var = o_{var-1} + u
                        (c0, up1), (d0, lo1) = _chord_of_max(low, high), _chord_of_min(low, high)
                        up0, lo0 = r_hi + c0, r_lo + d0
                    base = self.foot(var - 1, axis)
                first = 1 + 2 * self.n_steps + axis
                for alpha, beta, support in _lens(model.omega, t1 - t0):
                    # alpha (P - L) + beta (Q - L) <= support (U - L)
                    row = -(alpha + beta) * base
                    row[first + 2 * cell] += alpha
                    row[first + 2 * self.n_cells + 2 * cell] += beta
                    if var:
                        slope = (alpha + beta - support) * lo1 + support * up1
                        row[self.step_var(var, axis)] -= slope
                    self.add(row, (alpha + beta - support) * lo0 + support * up0)

    def reach_rows(self) -> None:
        """n . (c - o_j) <= reach; while step k may or may not have happened (until a tick
        after its window), n . (c - o_{k-1}) <= reach + max(0, n . u_k), max by its chord."""
        model = self.model
        for index in range(1, len(self.points)):
            t = float(self.points[index])
            window = self.window_at(t, REACH_DELAY)
            stance = self.stance_at(t) if window is None else window - 1
            com = [self.com(index, axis) for axis in (0, 1)]
            rows = [com[axis][0] - self.foot(stance, axis) for axis in (0, 1)]
            for nx, ny in _POLYGON:
                row = nx * rows[0] + ny * rows[1]
                limit = model.leg_reach - nx * com[0][1] - ny * com[1][1]
                if window is not None:
                    sigma = self.sigma_before(window)
                    spans = [
                        sorted((n * lo, n * hi))
                        for n, (lo, hi) in ((nx, model.step_range(0, sigma)),
                                            (ny, model.step_range(1, sigma)))
                    ]  # fmt: skip
                    c0, c1 = _chord_of_max(spans[0][0] + spans[1][0], spans[0][1] + spans[1][1])
                    row[self.step_var(window, 0)] -= c1 * nx
                    row[self.step_var(window, 1)] -= c1 * ny
                    limit += c0
                self.add(row, limit)

    def end_rows(self, edges: CaptureEdges) -> None:
        """The DCM offset at the end inside the capture interval of the stance foot. A push
        still acting counts as a jump of what is left of it: the same controls give the
        same DCM once it is over (linearity), so that state is viable if the pushed one is."""
        sigma = self.case.sigma * (-1 if self.n_steps % 2 else 1)
        for axis in (0, 1):
            row, const = self.dcm(len(self.points) - 1, axis, whole_push=True)
            row = row - self.foot(self.n_steps, axis)
            low, high = edges.interval(axis, sigma)
            self.add(row, high - const)
            self.add(-row, const - low)

    def solve(self) -> float:
        """max i (+inf: unbounded; -inf: infeasible)."""
        bounds: list[tuple[float | None, float | None]] = [(0.0, None)]
        for k in range(1, self.n_steps + 1):
            bounds.extend(self.model.step_range(axis, self.sigma_before(k)) for axis in (0, 1))
        bounds.extend([(None, None)] * (4 * self.n_cells))
        cost = np.zeros(self.n_var)
        cost[0] = -1.0
        result = linprog(
            cost,
            A_ub=csr_matrix(np.array(self.rows)),
            b_ub=np.array(self.limits),
            bounds=bounds,
            method="highs",
        )
        if result.status == 2:
            return -math.inf
        if result.status == 3:
            return math.inf
        if result.status != 0:
            raise RsgError(f"the capture bound's linear programme failed: {result.message}")
        return float(-result.fun)


def _relaxed_impulse(
    model: CaptureModel, case: PushCase, edges: CaptureEdges, windows: tuple[Window, ...]
) -> float:
    """The relaxation's largest impulse [N s] for step times in ``windows``."""
    programme = _Programme(model, case, windows)
    programme.cmp_rows()
    programme.reach_rows()
    programme.end_rows(edges)
    return programme.solve()
