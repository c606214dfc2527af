"""Polished QP answers: exact optima (KKT to rounding), and an answer when degenerate."""

import numpy as np
import pytest
import qpsolvers

from planner.qp import solve_polished


def random_problem(seed: int, n: int = 8, m: int = 12):
    """A strictly convex QP whose unconstrained minimum lies outside G x <= h."""
    rng = np.random.default_rng(seed)
    root = rng.standard_normal((n, n))
    P = root @ root.T + 0.1 * np.eye(n)
    q = 5.0 * rng.standard_normal(n)
    G = rng.standard_normal((m, n))
    h = rng.random(m)
    return P, q, G, h


def kkt_residual(P, q, G, h, x):
    """Stationarity residual with the best non-negative multipliers on active rows."""
    active = G @ x >= h - 1e-9
    gradient = P @ x + q
    if not active.any():
        return float(np.abs(gradient).max())
    multipliers, *_ = np.linalg.lstsq(G[active].T, -gradient, rcond=None)
    assert np.all(multipliers >= -1e-9)
    return float(np.abs(gradient + G[active].T @ multipliers).max())


@pytest.mark.parametrize("seed", range(20))
def test_polished_answer_is_a_kkt_point_to_rounding(seed):
    P, q, G, h = random_problem(seed)
    x = solve_polished(P, q, G, h, eps_abs=1e-6)
    assert np.all(G @ x <= h + 1e-12)
    assert kkt_residual(P, q, G, h, x) < 1e-11
    raw = qpsolvers.solve_qp(P, q, G, h, solver="proxqp", eps_abs=1e-6, eps_rel=0.0)
    assert np.abs(raw - x).max() > 1e-12  # proxqp alone stops short of the optimum


def test_bounds_are_polished_like_inequalities():
    P = np.diag([2.0, 1.0])
    q = np.array([-10.0, 1.0])  # unconstrained minimum (5, -1)
    x = solve_polished(P, q, lb=np.array([-1.0, 0.0]), ub=np.array([2.0, 3.0]), eps_abs=1e-5)
    np.testing.assert_array_equal(x, [2.0, 0.0])


def test_a_degenerate_active_set_is_polished_on_its_independent_rows():
    """The same constraint twice (as an unloaded foot's cone rows are): exact anyway."""
    P = np.eye(2)
    q = np.array([-2.0, -2.0])
    G = np.array([[1.0, 1.0], [1.0, 1.0]])
    h = np.array([1.0, 1.0])
    x = solve_polished(P, q, G, h, eps_abs=1e-6)
    np.testing.assert_array_equal(x, [0.5, 0.5])


def test_an_infeasible_problem_has_no_answer():
    P = np.eye(1)
    q = np.zeros(1)
    G = np.array([[1.0], [-1.0]])
    h = np.array([-1.0, -1.0])  # x <= -1 and x >= 1
    assert solve_polished(P, q, G, h) is None
