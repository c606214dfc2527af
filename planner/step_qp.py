"""The discrete controller: the step-location QP (27).

    minimize_{u_d}  V_u(e_u^+),  e_u^+ = e_u - u_d + 2 xi1*                  (27a)
    subject to      sigma+ u_d,y >= 2 w_y + mu_2          (no crossing)       (27b)
                    sigma+ xi1,y^+ <= w_y - mu_3           (CoM inside feet)   (27c)
                    u_d^m <= u_d <= u_d^M                  (step bounds)       (27d)

with sigma+ = -sigma the new stance foot and xi1^+ = xi1 - u_d.

Sign convention: we keep the paper's text definition sigma = +1 for the left stance
foot with y to the left. The printed (12b), (27b), (27c) and D_T,2 carry the opposite
sign of sigma (they hold as printed for sigma = +1 on the right foot); written as
above they say what Section III-B states in words: the new foot lands at least
2 w_y + mu_2 on its own side of the old one, and the CoM stays inside the outer edge
of the new stance foot.

Leg reach (an extension, ``Constraints.com_reach``; ``math.inf`` gives (27) as
printed): the step also keeps the CoM within reach of the new stance ankle,
|xi1^+| = |xi1 - u_d| <= com_reach. The box (27d) lets a diagonal step reach
0.85 m, and the V_u-optimal step for a large diagonal push leaves the CoM more than
the 0.6 m leg reach of the LIPM backend from the new ankle (a fall there), where a
slightly shorter step and a small residual error recover. The disc is convex; the
box optimum is kept when it meets it, otherwise the optimum lies on the reach circle
inside the box (:func:`_solve_on_reach_circle`). If no allowed step meets the reach,
the box optimum is kept.

DCM inset (an extension, ``RsgParameters.dcm_inset``; None gives (27c) as printed):
(27c) keeps the CoM inside the new sole, but what the stance can hold is the DCM. A
sole about 5 cm wide holds a lateral DCM error of only a few centimetres, and the
no-crossing rule (27b) keeps the next foot from stepping back across to catch one
that leaves it outwards, so the row (27c) also bounds the DCM predicted at the step,
xi_dcm = xi1 + xi2 / omega (relative to the old stance):

    sigma+ (xi_dcm,y - u_d,y) <= -dcm_inset                                  (27c')

(the new sole's centre line at least ``dcm_inset`` outside the DCM). Both bound
sigma+ u_d,y from below, so the row keeps the tighter bound; the DCM part never asks
for more than the largest lateral step (27d) allows, so it never makes (27) infeasible
on its own: beyond that it is the largest step outwards.

Infeasibility: (27b)-(27d) reduce to a box on u_d. (27c) can make it empty when the
CoM is already beyond where the largest lateral step can reach. The documented
fallback is then to drop (27c) and take the step that minimises V_u within (27b),
(27d): the largest step the robot can make towards the DCM. The solution reports
``feasible=False`` and the run counts it in ``qp_infeasible``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import qpsolvers

from .exceptions import StepQpError
from .parameters import Constraints, RsgParameters
from .qp import solve_polished


@dataclass(frozen=True)
class StepQpProblem:
    """Data of the QP (27) in the form min (d - u)^T P (d - u) s.t. G u <= h.

    Attributes:
        lyapunov_matrix: P_u (2x2).
        target: d = e_u + 2 xi1*, the step that zeroes e_u^+ [m].
        inequality_matrix: G (k x 2) of (27b), (27c) (and (27d) as rows).
        inequality_vector: h (k,).
        lower: Lower bound of u_d (27d) [m].
        upper: Upper bound of u_d (27d) [m].
        com_row: Index of the (27c) row in G, h.
    """

    lyapunov_matrix: np.ndarray
    target: np.ndarray
    inequality_matrix: np.ndarray
    inequality_vector: np.ndarray
    lower: np.ndarray
    upper: np.ndarray
    com_row: int = 1
    reach_center: np.ndarray | None = None
    reach: float = math.inf

    def objective(self, step: np.ndarray) -> float:
        """V_u(e_u^+) for the step u_d."""
        diff = self.target - np.asarray(step, dtype=float)
        return float(diff @ self.lyapunov_matrix @ diff)

    def max_violation(self, step: np.ndarray, with_com: bool = True) -> float:
        """Largest violation of (27b)-(27d) by ``step`` [m] (<= 0 when feasible)."""
        step = np.asarray(step, dtype=float)
        rows = self.inequality_matrix @ step - self.inequality_vector
        if not with_com:
            rows = np.delete(rows, self.com_row)
        return float(max(rows.max(), (self.lower - step).max(), (step - self.upper).max()))

    def without_com_constraint(self) -> StepQpProblem:
        """The same problem without (27c): the fallback."""
        keep = [i for i in range(len(self.inequality_vector)) if i != self.com_row]
        return StepQpProblem(
            self.lyapunov_matrix,
            self.target,
            self.inequality_matrix[keep],
            self.inequality_vector[keep],
            self.lower,
            self.upper,
            com_row=-1,
            reach_center=self.reach_center,
            reach=self.reach,
        )

    def reach_violation(self, step: np.ndarray) -> float:
        """|xi1 - u_d| - com_reach [m] (<= 0 when the CoM stays within reach)."""
        if self.reach_center is None or not math.isfinite(self.reach):
            return -math.inf
        return float(np.linalg.norm(self.reach_center - np.asarray(step, dtype=float)) - self.reach)

    def box(self) -> tuple[np.ndarray, np.ndarray]:
        """The feasible set as a box [lo, hi] (it is one: (27b), (27c) bound u_d,y only)."""
        lo, hi = self.lower.copy(), self.upper.copy()
        for row, bound in zip(self.inequality_matrix, self.inequality_vector, strict=True):
            axes = np.flatnonzero(row)
            if len(axes) != 1:
                raise StepQpError("a constraint couples x and y: not a box", self)
            axis = int(axes[0])
            if row[axis] > 0.0:
                hi[axis] = min(hi[axis], bound / row[axis])
            else:
                lo[axis] = max(lo[axis], bound / row[axis])
        return lo, hi


@dataclass(frozen=True)
class StepQpSolution:
    """Solution of (27).

    Attributes:
        step: u_d [m].
        lyapunov_after: V_u(e_u^+).
        feasible: False when (27c) had to be dropped (fallback).
    """

    step: np.ndarray
    lyapunov_after: float
    feasible: bool


def build_step_qp(
    lyapunov_matrix: np.ndarray,
    dcm_error: np.ndarray,
    xi1: np.ndarray,
    xi1_reference: np.ndarray,
    sigma: int,
    constraints: Constraints,
    params: RsgParameters,
    dcm: np.ndarray | None = None,
) -> StepQpProblem:
    """Problem (27) at the current state.

    Args:
        lyapunov_matrix: P_u.
        dcm_error: e_u before the step [m].
        xi1: c_H - o_H before the step [m].
        xi1_reference: xi1* before the step [m].
        sigma: Current stance foot (+1 left, -1 right); the new one is -sigma.
        constraints: Bounds w_y, u_d^m, u_d^M.
        params: Margins mu_2, mu_3 and the DCM inset of (27c').
        dcm: xi_dcm - o_H before the step [m], for (27c') (needed when
            ``params.dcm_inset`` is set).
    """
    sigma_new = -sigma
    w_y = constraints.half_width
    com_bound = w_y - params.com_margin - sigma_new * float(xi1[1])
    if params.dcm_inset is not None:
        if dcm is None:
            raise StepQpError("dcm_inset is set: the QP needs the DCM before the step", None)
        # The largest step outwards (27d) allows: sigma+ u_y <= outward.
        outward = constraints.step_max[1] if sigma_new > 0 else -constraints.step_min[1]
        dcm_bound = -params.dcm_inset - sigma_new * float(dcm[1])
        com_bound = min(com_bound, max(dcm_bound, -outward))
    g = np.array(
        [
            [0.0, -sigma_new],  # (27b): -sigma+ u_y <= -(2 w_y + mu_2)
            [0.0, -sigma_new],  # (27c): -sigma+ u_y <= w_y - mu_3 - sigma+ xi1_y, (27c')
        ]
    )
    h = np.array(
        [
            -(2.0 * w_y + params.crossing_margin),
            com_bound,
        ]
    )
    return StepQpProblem(
        lyapunov_matrix=np.asarray(lyapunov_matrix, dtype=float),
        target=np.asarray(dcm_error, dtype=float) + 2.0 * np.asarray(xi1_reference, dtype=float),
        inequality_matrix=g,
        inequality_vector=h,
        lower=np.array(constraints.step_min, dtype=float),
        upper=np.array(constraints.step_max, dtype=float),
        com_row=1,
        reach_center=np.asarray(xi1, dtype=float).copy(),
        reach=constraints.com_reach,
    )


def _is_feasible(problem: StepQpProblem) -> bool:
    lo, hi = problem.box()
    return bool(np.all(lo <= hi + 1e-12))


def solve_with_qpsolvers(problem: StepQpProblem, solver: str = "proxqp") -> np.ndarray | None:
    """Solve min (d-u)^T P (d-u) s.t. (27b)-(27d) with qpsolvers.

    (27b) and (27c) both bound sigma+ u_d,y from below, so with (27d) the feasible set
    is the box :meth:`StepQpProblem.box`, which is what the solver receives (as lb,
    ub). Given as two parallel inequality rows, the active constraints are not
    linearly independent when both are near-active, and proxqp then stopped up to
    1.3 cm from the optimum on 7 of 1000 sampled problems; as bounds it matches the
    exact minimiser to 1e-9 m on all of them (tests/test_step_qp.py).

    Returns:
        u_d, or None if the solver reports no solution or the box is empty.
    """
    lower, upper = problem.box()
    if np.any(lower > upper):
        return None
    p = 2.0 * problem.lyapunov_matrix
    q = -2.0 * problem.lyapunov_matrix @ problem.target
    try:
        if solver == "proxqp":
            x = solve_polished(p, q, lb=lower, ub=upper, eps_abs=1e-9)
        else:
            x = qpsolvers.solve_qp(p, q, lb=lower, ub=upper, solver=solver, eps_abs=1e-9)
    except (qpsolvers.SolverError, ValueError) as exc:
        raise StepQpError(f"qpsolvers/{solver} failed: {exc}", problem) from exc
    return None if x is None else np.asarray(x, dtype=float)


def solve_box_exact(problem: StepQpProblem) -> np.ndarray | None:
    """Exact minimiser of the 2-variable convex QP over its box (no iterations).

    The minimum of a convex quadratic over a box is the unconstrained minimum if it
    lies inside, and otherwise lies on an edge, where it is a clipped 1-D minimum.

    Returns:
        u_d, or None if the box is empty.
    """
    lo, hi = problem.box()
    if np.any(lo > hi + 1e-12):
        return None
    hi = np.maximum(hi, lo)
    d, p = problem.target, problem.lyapunov_matrix
    if np.all(d >= lo) and np.all(d <= hi):
        return d.copy()
    best, best_value = None, np.inf
    for axis in (0, 1):
        other = 1 - axis
        for fixed in (lo[axis], hi[axis]):
            # Minimise over u_other with u_axis = fixed.
            u = np.empty(2)
            u[axis] = fixed
            # d/du_o of (d-u)^T P (d-u) = 0 -> u_o = d_o + P_ao (d_a - fixed) / P_oo
            u[other] = d[other] + p[axis, other] * (d[axis] - fixed) / p[other, other]
            u[other] = np.clip(u[other], lo[other], hi[other])
            value = problem.objective(u)
            if value < best_value:
                best, best_value = u, value
    return best


def solve_step_qp(problem: StepQpProblem, solver: str = "proxqp") -> StepQpSolution:
    """Solve (27), falling back to the problem without (27c) when it is infeasible.

    Args:
        problem: The QP.
        solver: ``"proxqp"`` (qpsolvers backend) or ``"exact"`` (box method).

    Raises:
        StepQpError: If even the fallback problem cannot be solved (the bounds are
            inconsistent; :class:`~planner.parameters.PlannerConfig` prevents that).
    """
    feasible = _is_feasible(problem)
    to_solve = problem if feasible else problem.without_com_constraint()
    if solver == "exact":
        step = solve_box_exact(to_solve)
    else:
        step = solve_with_qpsolvers(to_solve, solver)
    if step is None:
        raise StepQpError("the step QP (27) without (27c) has no solution", to_solve)
    if to_solve.reach_violation(step) > 0.0:
        step = _solve_on_reach_circle(to_solve, step)
    return StepQpSolution(step=step, lyapunov_after=problem.objective(step), feasible=feasible)


REACH_SAMPLES = 1440  # points on the reach circle before the local refinement


def _solve_on_reach_circle(problem: StepQpProblem, box_step: np.ndarray) -> np.ndarray:
    """Minimiser of (27a) over the box and the disc |xi1 - u_d| <= com_reach.

    ``box_step`` (the box optimum) lies outside the disc, so by convexity (P_u > 0)
    the reach is active at the optimum: it is the best point of the circle's arcs
    inside the box, found on a fine grid of angles and refined by golden-section
    search. If no point of the circle is inside the box (the CoM is beyond the reach
    of every allowed step), the box optimum is kept.
    """
    assert problem.reach_center is not None
    lo, hi = problem.box()
    center, radius = problem.reach_center, problem.reach

    def point(angle: float) -> np.ndarray:
        return center + radius * np.array([math.cos(angle), math.sin(angle)])

    def inside(u: np.ndarray) -> bool:
        return bool(np.all(u >= lo - 1e-12) and np.all(u <= hi + 1e-12))

    spacing = 2.0 * math.pi / REACH_SAMPLES
    angles = spacing * np.arange(REACH_SAMPLES)
    points = center + radius * np.column_stack([np.cos(angles), np.sin(angles)])
    ok = np.all((points >= lo - 1e-12) & (points <= hi + 1e-12), axis=1)
    if not np.any(ok):
        return box_step
    diff = problem.target - points
    values = np.einsum("ij,jk,ik->i", diff, problem.lyapunov_matrix, diff)
    values[~ok] = np.inf
    best = int(np.argmin(values))
    best_angle, best_value = float(angles[best]), float(values[best])
    a, b = best_angle - spacing, best_angle + spacing
    ratio = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(40):
        c, d = b - ratio * (b - a), a + ratio * (b - a)
        fc = problem.objective(point(c)) if inside(point(c)) else math.inf
        fd = problem.objective(point(d)) if inside(point(d)) else math.inf
        if fc <= fd:
            b = d
        else:
            a = c
    refined = point(0.5 * (a + b))
    if inside(refined) and problem.objective(refined) <= best_value:
        return refined
    return point(best_angle)
