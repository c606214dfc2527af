"""The step QP (27): constraints, optimality against brute force, fallback."""

import itertools
import math

import numpy as np
import pytest

from planner.exceptions import ParameterError, StepQpError
from planner.lyapunov import design_lyapunov
from planner.parameters import Constraints, LipmModel, RsgParameters
from planner.step_qp import build_step_qp, solve_box_exact, solve_step_qp

CONSTRAINTS, PARAMS = Constraints(), RsgParameters()
P_U = design_lyapunov(LipmModel(), CONSTRAINTS, PARAMS).matrix


def random_problem(rng, sigma, anisotropic=False):
    p = P_U
    if anisotropic:
        m = rng.normal(size=(2, 2))
        p = m @ m.T + 0.1 * np.eye(2)
    return build_step_qp(
        p,
        dcm_error=rng.normal(0, 0.1, 2),
        xi1=np.array([rng.uniform(-0.2, 0.2), -sigma * rng.uniform(0.0, 0.15)]),
        xi1_reference=np.array([rng.uniform(0.0, 0.12), -sigma * rng.uniform(0.05, 0.1)]),
        sigma=sigma,
        constraints=CONSTRAINTS,
        params=PARAMS,
    )


def brute_force(problem, n=401):
    lo, hi = problem.lower, problem.upper
    xs, ys = np.linspace(lo[0], hi[0], n), np.linspace(lo[1], hi[1], n)
    best, best_value = None, np.inf
    for x, y in itertools.product(xs, ys):
        u = np.array([x, y])
        if problem.max_violation(u) <= 1e-12 and problem.reach_violation(u) <= 1e-12:
            value = problem.objective(u)
            if value < best_value:
                best, best_value = u, value
    return best, best_value


@pytest.mark.parametrize(
    "seed,sigma,anisotropic",
    [(s, sg, a) for s in range(6) for sg in (1, -1) for a in (False, True)],
)
def test_solution_meets_constraints_and_matches_brute_force(seed, sigma, anisotropic):
    rng = np.random.default_rng(seed)
    problem = random_problem(rng, sigma, anisotropic)
    solution = solve_step_qp(problem, "proxqp")
    case = f"{seed=} {sigma=} {anisotropic=}"
    if not solution.feasible:
        pytest.skip(f"infeasible draw: {case}")
    assert problem.max_violation(solution.step) < 1e-6, case  # (27b)-(27d)
    assert problem.reach_violation(solution.step) < 1e-6, case  # leg reach
    _, grid_value = brute_force(problem, n=201)
    grid_step = (problem.upper - problem.lower) / 200
    slack = (
        2
        * float(np.max(np.linalg.eigvalsh(problem.lyapunov_matrix)))
        * float(np.linalg.norm(grid_step))
        * (np.linalg.norm(problem.target) + 1.0)
    )
    assert solution.lyapunov_after <= grid_value + 1e-9, case
    assert solution.lyapunov_after >= grid_value - slack, case
    exact = solve_step_qp(problem, "exact").step
    np.testing.assert_allclose(solution.step, exact, atol=1e-5, err_msg=case)
    if problem.reach_violation(solve_box_exact(problem)) <= 0.0:
        np.testing.assert_allclose(exact, solve_box_exact(problem), atol=1e-12, err_msg=case)


def test_feet_never_cross_in_the_solution():
    rng = np.random.default_rng(7)
    for sigma in (1, -1):
        for _ in range(50):
            problem = random_problem(rng, sigma)
            step = solve_step_qp(problem, "exact").step
            # (27b): the new foot (-sigma) lands on its own side by 2 w_y + mu_2.
            assert -sigma * step[1] >= 2 * CONSTRAINTS.half_width + PARAMS.crossing_margin - 1e-9


def test_unconstrained_optimum_zeroes_the_dcm_error():
    problem = build_step_qp(
        P_U,
        np.array([0.02, 0.01]),
        np.array([0.1, -0.1]),
        np.array([0.1, -0.1]),
        sigma=1,
        constraints=CONSTRAINTS,
        params=PARAMS,
    )
    solution = solve_step_qp(problem)
    assert solution.feasible
    np.testing.assert_allclose(solution.step, problem.target, atol=1e-6)
    assert solution.lyapunov_after == pytest.approx(0.0, abs=1e-10)


def test_infeasible_problem_falls_back_without_27c():
    """The CoM is far beyond the reach of the largest lateral step: (27c) is dropped."""
    sigma = 1  # left stance, the right foot steps (sigma+ = -1)
    problem = build_step_qp(
        P_U,
        np.array([0.0, -0.9]),
        np.array([0.0, -0.9]),
        np.array([0.1, -0.1]),
        sigma=sigma,
        constraints=CONSTRAINTS,
        params=PARAMS,
    )
    lo, hi = problem.box()
    assert lo[1] > hi[1], "the test case must be infeasible"
    for solver in ("proxqp", "exact"):
        solution = solve_step_qp(problem, solver)
        assert not solution.feasible
        assert problem.max_violation(solution.step, with_com=False) < 1e-6
        assert solution.step[1] == pytest.approx(CONSTRAINTS.step_min[1], abs=1e-6)


def test_proxqp_matches_the_exact_minimiser_on_many_problems():
    """proxqp (through qpsolvers) and the exact box method agree on 1000 sampled QPs,
    including those where (27b) and (27c) are both nearly active."""
    rng = np.random.default_rng(0)
    compared = 0
    for index in range(1000):
        sigma = 1 if index % 2 else -1
        xi1_reference = np.array([rng.uniform(-0.1, 0.1), -sigma * rng.uniform(0.0, 0.1)])
        error = rng.normal(0.0, 0.15, 2)
        xi1 = xi1_reference + rng.normal(0.0, 0.05, 2)
        problem = build_step_qp(P_U, error, xi1, xi1_reference, sigma, CONSTRAINTS, PARAMS)
        proxqp = solve_step_qp(problem, "proxqp")
        exact = solve_step_qp(problem, "exact")
        assert proxqp.feasible == exact.feasible
        np.testing.assert_allclose(proxqp.step, exact.step, atol=1e-6, err_msg=f"{index=}")
        compared += 1
    assert compared == 1000


def test_leg_reach_keeps_the_com_within_reach_of_the_new_foot():
    """A large diagonal DCM error asks for a step near the box corner (0.6, 0.6); with
    the leg reach (default 0.58 m) the step leaves the CoM within it, on the reach
    circle, and is the best such step; with com_reach = inf it is (27) as printed."""
    xi1, reference = np.array([0.1, 0.05]), np.array([0.05, -0.1])
    error = np.array([0.6, 0.75])
    problem = build_step_qp(P_U, error, xi1, reference, -1, CONSTRAINTS, PARAMS)
    box_only = solve_box_exact(problem)
    assert np.linalg.norm(xi1 - box_only) > CONSTRAINTS.com_reach + 0.05
    for solver in ("exact", "proxqp"):
        step = solve_step_qp(problem, solver).step
        assert np.linalg.norm(xi1 - step) == pytest.approx(CONSTRAINTS.com_reach, abs=1e-9)
        assert problem.max_violation(step) < 1e-9
    _, grid_value = brute_force(problem, n=401)
    assert solve_step_qp(problem, "exact").lyapunov_after <= grid_value + 1e-9
    off = Constraints(com_reach=math.inf)
    paper = build_step_qp(P_U, error, xi1, reference, -1, off, PARAMS)
    np.testing.assert_allclose(solve_step_qp(paper, "exact").step, box_only, atol=1e-12)


@pytest.mark.parametrize("sigma", [1, -1])
def test_dcm_inset_puts_the_new_sole_outside_the_predicted_dcm(sigma):
    """(27c'): with ``dcm_inset`` the step leaves the DCM at least that far inside the
    new sole's centre line (towards the old foot), which the V_u-optimal step of (27)
    does not; where the box cannot get that far it is the largest step outwards."""
    sigma_new = -sigma
    xi1 = np.array([0.05, -sigma * 0.08])  # the CoM over the stance leg's inner side
    dcm = xi1 + np.array([0.05, sigma_new * 0.18])  # moving fast towards the swing side
    reference = np.array([0.05, -sigma * 0.09])
    error = np.array([0.0, sigma_new * 0.03])
    inset = 0.03
    plain = solve_step_qp(build_step_qp(P_U, error, xi1, reference, sigma, CONSTRAINTS, PARAMS))
    assert sigma_new * (dcm[1] - plain.step[1]) > -inset  # (27) alone leaves it closer
    params = RsgParameters(dcm_inset=inset)
    problem = build_step_qp(P_U, error, xi1, reference, sigma, CONSTRAINTS, params, dcm=dcm)
    for solver in ("exact", "proxqp"):
        solution = solve_step_qp(problem, solver)
        assert solution.feasible
        assert sigma_new * (dcm[1] - solution.step[1]) == pytest.approx(-inset, abs=1e-6)
        assert problem.max_violation(solution.step) < 1e-6
        assert solution.lyapunov_after > plain.lyapunov_after  # paid for in V_u
    # A DCM beyond the largest step: the largest step outwards, still feasible.
    far = xi1 + np.array([0.0, sigma_new * 1.0])
    problem = build_step_qp(P_U, error, xi1, reference, sigma, CONSTRAINTS, params, dcm=far)
    solution = solve_step_qp(problem, "exact")
    assert solution.feasible
    outward = CONSTRAINTS.step_max[1] if sigma_new > 0 else CONSTRAINTS.step_min[1]
    assert solution.step[1] == pytest.approx(outward, abs=1e-9)


def test_dcm_inset_needs_the_dcm_and_a_sane_value():
    params = RsgParameters(dcm_inset=0.02)
    with pytest.raises(StepQpError, match="DCM"):
        build_step_qp(P_U, np.zeros(2), np.zeros(2), np.zeros(2), 1, CONSTRAINTS, params)
    with pytest.raises(ParameterError, match="dcm_inset"):
        RsgParameters(dcm_inset=0.5)
