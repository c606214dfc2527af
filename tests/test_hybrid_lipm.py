"""The LIPM (1) and its hybrid form (11): closed form against numerical integration."""

import numpy as np
import pytest

from planner.hybrid_lipm import (
    H_MATRIX,
    dcm,
    flow_autonomous,
    flow_matrices,
    integrate_lipm,
    orbital_energy,
)
from planner.lyapunov import dcm_error_matrices
from planner.parameters import LipmModel

MODEL = LipmModel()


def lipm_acceleration(c, p, hdot, f, model=MODEL):
    """(1) written out."""
    w2 = model.gravity / model.com_height
    return w2 * (c - p) + H_MATRIX @ hdot / (model.mass * model.com_height) + f / model.mass


def rk4(c, v, p, hdot, f, duration, n=4000):
    h = duration / n
    for _ in range(n):

        def deriv(c_, v_):
            return v_, lipm_acceleration(c_, p, hdot, f)

        k1 = deriv(c, v)
        k2 = deriv(c + h / 2 * k1[0], v + h / 2 * k1[1])
        k3 = deriv(c + h / 2 * k2[0], v + h / 2 * k2[1])
        k4 = deriv(c + h * k3[0], v + h * k3[1])
        c = c + h / 6 * (k1[0] + 2 * k2[0] + 2 * k3[0] + k4[0])
        v = v + h / 6 * (k1[1] + 2 * k2[1] + 2 * k3[1] + k4[1])
    return c, v


@pytest.mark.parametrize("seed", range(5))
def test_closed_form_matches_runge_kutta(seed):
    rng = np.random.default_rng(seed)
    c0, v0 = rng.normal(0, 0.1, 2), rng.normal(0, 0.3, 2)
    p, hdot, f = rng.normal(0, 0.05, 2), rng.normal(0, 10, 2), rng.normal(0, 50, 2)
    c_exact, v_exact = integrate_lipm(MODEL, c0, v0, p, hdot, f, 0.4)
    c_num, v_num = rk4(c0, v0, p, hdot, f, 0.4)
    np.testing.assert_allclose(c_exact, c_num, atol=1e-9, err_msg=f"{seed=}")
    np.testing.assert_allclose(v_exact, v_num, atol=1e-9, err_msg=f"{seed=}")


def test_flow_map_is_the_lipm_in_xi_coordinates():
    """(11): A xi + B u_c + E Delta_c equals (1) with p = o + p~ + r~."""
    rng = np.random.default_rng(1)
    a, b, e = flow_matrices(MODEL)
    o, xi1, xi2 = rng.normal(size=2), rng.normal(size=2), rng.normal(size=2)
    p_offset, hdot, r_offset, force = (
        rng.normal(size=2),
        rng.normal(size=2),
        rng.normal(size=2),
        rng.normal(size=2),
    )
    xi_dot = a @ np.r_[xi1, xi2] + b @ np.r_[p_offset, hdot] + e @ np.r_[r_offset, force]
    expected = lipm_acceleration(o + xi1, o + p_offset + r_offset, hdot, force)
    np.testing.assert_allclose(xi_dot[:2], xi2)
    np.testing.assert_allclose(xi_dot[2:], expected)


def test_dcm_error_dynamics_19a_match_the_flow():
    """d/dt of the DCM along (11) equals A_u xi_u + B_u u_c + E_u Delta_c."""
    rng = np.random.default_rng(2)
    a, b, e = flow_matrices(MODEL)
    a_u, b_u, e_u = dcm_error_matrices(MODEL)
    xi, u, delta = rng.normal(size=4), rng.normal(size=4), rng.normal(size=4)
    xi_dot = a @ xi + b @ u + e @ delta
    dcm_dot = xi_dot[:2] + xi_dot[2:] / MODEL.omega
    np.testing.assert_allclose(dcm_dot, a_u @ dcm(MODEL.omega, xi) + b_u @ u + e_u @ delta)


def test_free_flow_conserves_orbital_energy():
    rng = np.random.default_rng(3)
    xi = rng.normal(size=4)
    w = MODEL.omega
    before = [orbital_energy(w, xi[i], xi[i + 2]) for i in (0, 1)]
    after_xi = flow_autonomous(w, xi, 0.73)
    after = [orbital_energy(w, after_xi[i], after_xi[i + 2]) for i in (0, 1)]
    np.testing.assert_allclose(before, after, rtol=1e-10)
