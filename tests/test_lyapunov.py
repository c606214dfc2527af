"""K_u, P_u, gamma_v of (20), (21)."""

import numpy as np
import pytest

from planner.lyapunov import dcm_error_matrices, design_lyapunov
from planner.parameters import Constraints, LipmModel, RsgParameters

MODEL, CONSTRAINTS, PARAMS = LipmModel(), Constraints(), RsgParameters()
DESIGN = design_lyapunov(MODEL, CONSTRAINTS, PARAMS)


def test_closed_loop_lyapunov_inequality():
    """(A_u + B_u K_u)^T P_u + P_u (A_u + B_u K_u) < 0."""
    a_u, b_u, _ = dcm_error_matrices(MODEL)
    closed = a_u + b_u @ DESIGN.gain
    lhs = closed.T @ DESIGN.matrix + DESIGN.matrix @ closed
    assert np.all(np.linalg.eigvalsh(DESIGN.matrix) > 0)
    assert np.max(np.linalg.eigvalsh(lhs)) < 0


def test_threshold_implies_unsaturated_feedback_21():
    """On {V_u <= gamma_v} the feedback K_u e_u stays inside u_c^m, u_c^M, tightly."""
    boundary = DESIGN.level_set(DESIGN.threshold, count=2000)
    feedback = boundary @ DESIGN.gain.T
    assert np.all(feedback >= CONSTRAINTS.input_min() - 1e-12)
    assert np.all(feedback <= CONSTRAINTS.input_max() + 1e-12)
    bounds = np.minimum(-CONSTRAINTS.input_min(), CONSTRAINTS.input_max())
    assert np.max(np.abs(feedback) / bounds) == pytest.approx(1.0, rel=1e-3)


def test_level_set_points_have_the_level():
    points = DESIGN.level_set(0.01, count=50)
    levels = [DESIGN.level(p) for p in points]
    np.testing.assert_allclose(levels, 0.01, rtol=1e-9)
