"""Small convex QPs: proxqp through qpsolvers, then polished on the active set.

proxqp stops within ``eps_abs`` of the optimum, and where it stops depends on where
its workspace lands in memory (its vectorised sums start at the first aligned
element), so two processes given the same problem may differ by ~1e-8. Polishing
(Stellato et al., "OSQP: an operator splitting solver for quadratic programs",
Math. Prog. Comp. 2020, Sec. 4) takes the constraints proxqp found active and solves
the equality-constrained problem exactly: the answer is the exact optimum, and the
same bits in every process.

    minimize 1/2 x^T P x + q^T x  subject to  G x <= h,  lb <= x <= ub
"""

from __future__ import annotations

import numpy as np
import qpsolvers
from numpy.typing import NDArray

DUAL_TOLERANCE = 1e-9  # a multiplier above this marks its row active; below -this, not
ACTIVE_TOLERANCE = 1e-7  # a row this close to its bound (relative) starts active
FEASIBILITY_TOLERANCE = 1e-12  # relative violation allowed to the polished point
MAX_CORRECTIONS = 20  # rows added or dropped before proxqp's own answer is kept


def solve_polished(
    P: NDArray[np.float64],
    q: NDArray[np.float64],
    G: NDArray[np.float64] | None = None,
    h: NDArray[np.float64] | None = None,
    lb: NDArray[np.float64] | None = None,
    ub: NDArray[np.float64] | None = None,
    eps_abs: float = 1e-9,
) -> NDArray[np.float64] | None:
    """The QP's minimiser, or None if proxqp finds none.

    Falls back to proxqp's own answer when the polished point is not a KKT point
    (a degenerate active set); that answer is within ``eps_abs`` of the optimum.

    Raises:
        qpsolvers.SolverError, ValueError: from qpsolvers, on malformed input.
    """
    problem = qpsolvers.Problem(P, q, G, h, lb=lb, ub=ub)
    solution = qpsolvers.solve_problem(problem, "proxqp", eps_abs=eps_abs, eps_rel=0.0)
    if not solution.found or solution.x is None:
        return None
    rows, bounds, duals = _inequalities(len(q), G, h, lb, ub, solution)
    polished = _polish(P, q, rows, bounds, duals, np.asarray(solution.x, float))
    return np.asarray(solution.x, float) if polished is None else polished


def _inequalities(
    n: int,
    G: NDArray[np.float64] | None,
    h: NDArray[np.float64] | None,
    lb: NDArray[np.float64] | None,
    ub: NDArray[np.float64] | None,
    solution: qpsolvers.Solution,
) -> tuple[NDArray[np.float64], NDArray[np.float64], NDArray[np.float64]]:
    """All inequalities as rows <= bounds, with their multipliers (>= 0)."""
    rows, bounds, duals = [np.zeros((0, n))], [np.zeros(0)], [np.zeros(0)]
    if G is not None and h is not None:
        rows.append(np.atleast_2d(G))
        bounds.append(np.atleast_1d(h))
        duals.append(np.asarray(solution.z, float))
    z_box = np.zeros(n) if solution.z_box is None else np.asarray(solution.z_box, float)
    if ub is not None:  # qpsolvers: z_box > 0 where an upper bound is active
        rows.append(np.eye(n))
        bounds.append(np.asarray(ub, float))
        duals.append(np.maximum(z_box, 0.0))
    if lb is not None:
        rows.append(-np.eye(n))
        bounds.append(-np.asarray(lb, float))
        duals.append(np.maximum(-z_box, 0.0))
    return np.vstack(rows), np.concatenate(bounds), np.concatenate(duals)


def _polish(
    P: NDArray[np.float64],
    q: NDArray[np.float64],
    rows: NDArray[np.float64],
    bounds: NDArray[np.float64],
    duals: NDArray[np.float64],
    x: NDArray[np.float64],
) -> NDArray[np.float64] | None:
    """Exact minimiser on the active set, refined from proxqp's guess.

    The guess (rows nearly tight or with a multiplier) is corrected one row at a time:
    a row whose multiplier is negative leaves, the most violated row joins. The
    optimum's active set does not depend on the guess, so neither do the bits.
    """
    n = len(q)
    slack = bounds - rows @ x
    scale = np.maximum(1.0, abs(bounds))
    active = (duals > DUAL_TOLERANCE) | (slack < ACTIVE_TOLERANCE * scale)
    for _ in range(MAX_CORRECTIONS):
        active = _independent(rows, active)
        A = rows[active]
        kkt = np.block([[P, A.T], [A, np.zeros((len(A), len(A)))]])
        try:
            solution = np.linalg.solve(kkt, np.concatenate([-np.asarray(q, float), bounds[active]]))
        except np.linalg.LinAlgError:  # active rows not independent
            return None
        candidate, multipliers = solution[:n], solution[n:]
        if not np.all(np.isfinite(candidate)):
            return None
        if len(multipliers) and multipliers.min() < -DUAL_TOLERANCE:
            active[np.flatnonzero(active)[np.argmin(multipliers)]] = False
            continue
        violation = (rows @ candidate - bounds) / scale
        if violation.max(initial=0.0) > FEASIBILITY_TOLERANCE:
            active[np.argmax(violation)] = True
            continue
        return candidate
    return None


def _independent(rows: NDArray[np.float64], active: NDArray[np.bool_]) -> NDArray[np.bool_]:
    """The first rows of ``active``, in order, that are linearly independent."""
    kept = np.zeros_like(active)
    rank = 0
    for index in np.flatnonzero(active):
        kept[index] = True
        if np.linalg.matrix_rank(rows[kept]) > rank:
            rank += 1
        else:
            kept[index] = False
    return kept
