"""DCM error dynamics (18), (19) and the Lyapunov function (20), (21).

The DCM error e_u = xi_u - xi_u* flows as

    e_u' = A_u e_u + B_u u_c + E_u Delta_c                                  (19a)

with A_u = omega I, B_u = [-omega I, H / (omega m c_z)] and
E_u = [-omega I, I / (omega m)]. (The paper prints B_u = [-omega I, sqrt(c_z/g) H]
and E_u = [.., (1/m) sqrt(g/c_z) I]; differentiating (18) along (11) gives the
factors above, which is what this module uses.)

Design of K_u and P_u (the paper says only "LQR"): continuous-time LQR on (19a)
with Bryson's rule,

    Q = I / e_max^2,   R = diag(1/p_max^2, 1/p_max^2, 1/h_max^2, 1/h_max^2),

e_max = 5 cm of DCM error, p_max = 5 cm of ZMP offset and h_max = 20 N m by default
(``RsgParameters.lqr_*``): the scales are the sizes one is willing to see of each,
so the DCM error is corrected through the ZMP and the angular momentum in proportion
to what the foot and the upper body of a robot of the class can give. The Riccati solution
P gives K_u = -R^-1 B_u^T P and (A_u + B_u K_u)^T P + P (A_u + B_u K_u) = -Q - K^T R K
< 0. Any positive multiple of P is a Lyapunov function with the same K_u; we scale
P_u = alpha P so that (21) holds with equality: {V_u <= gamma_v} is the largest
level set on which the feedback K_u e_u stays inside the input bounds u_c^m, u_c^M.
So "V_u below gamma_v" means exactly "the unsaturated continuous controller alone
brings the DCM error back", which is the paper's meaning of the threshold.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import scipy.linalg

from .exceptions import ParameterError
from .hybrid_lipm import H_MATRIX
from .parameters import Constraints, LipmModel, RsgParameters


def dcm_error_matrices(model: LipmModel) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """A_u (2x2), B_u (2x4), E_u (2x4) of (19a)."""
    w, m, cz = model.omega, model.mass, model.com_height
    eye = np.eye(2)
    a_u = w * eye
    b_u = np.hstack([-w * eye, H_MATRIX / (w * m * cz)])
    e_u = np.hstack([-w * eye, eye / (w * m)])
    return a_u, b_u, e_u


@dataclass(frozen=True)
class LyapunovDesign:
    """K_u, P_u and gamma_v of (20), (21).

    Attributes:
        gain: K_u (4x2), feedback u_c = K_u e_u.
        matrix: P_u (2x2), symmetric positive definite.
        threshold: gamma_v.
        lqr_cost: Q (2x2) and R (4x4) used by the LQR.
    """

    gain: np.ndarray
    matrix: np.ndarray
    threshold: float
    state_cost: np.ndarray
    input_cost: np.ndarray

    def level(self, dcm_error: np.ndarray) -> float:
        """V_u(e_u) = e_u^T P_u e_u (20)."""
        e = np.asarray(dcm_error, dtype=float)
        return float(e @ self.matrix @ e)

    def max_feedback_on_threshold(self) -> np.ndarray:
        """max |K_u,i e_u| over {V_u <= gamma_v}, per input i (4,)."""
        p_inv = np.linalg.inv(self.matrix)
        return np.sqrt(self.threshold * np.einsum("ij,jk,ik->i", self.gain, p_inv, self.gain))

    def level_set(self, level: float, count: int = 100) -> np.ndarray:
        """Points e_u on {V_u = level}, shape (count, 2) [m]."""
        return level_set(self.matrix, level, count)


def level_set(matrix: np.ndarray, level: float, count: int = 100) -> np.ndarray:
    """Points e_u on {e_u^T P_u e_u = level} of a 2x2 P_u, shape (count, 2) [m], closed."""
    angles = np.linspace(0.0, 2.0 * math.pi, count)
    circle = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    chol = np.linalg.cholesky(np.linalg.inv(np.asarray(matrix, dtype=float)))
    return math.sqrt(max(level, 0.0)) * circle @ chol.T


def design_lyapunov(
    model: LipmModel, constraints: Constraints, params: RsgParameters
) -> LyapunovDesign:
    """LQR design of K_u and P_u, with P_u scaled so that (21) holds with equality.

    Raises:
        ParameterError: If the Riccati equation has no stabilising solution.
    """
    a_u, b_u, _ = dcm_error_matrices(model)
    q = np.eye(2) / params.lqr_dcm_error_scale**2
    r = np.diag(
        [
            1.0 / params.lqr_zmp_scale**2,
            1.0 / params.lqr_zmp_scale**2,
            1.0 / params.lqr_angular_momentum_scale**2,
            1.0 / params.lqr_angular_momentum_scale**2,
        ]
    )
    try:
        p = scipy.linalg.solve_continuous_are(a_u, b_u, q, r)
    except (np.linalg.LinAlgError, ValueError) as exc:
        raise ParameterError("lqr weights", (q.tolist(), r.tolist()), "a stabilisable LQR") from exc
    gain = -np.linalg.solve(r, b_u.T @ p)
    # (21): max over {e^T (alpha P) e <= gamma} of |k_i e| = sqrt(gamma k_i P^-1 k_i^T / alpha).
    bounds = np.minimum(np.abs(constraints.input_min()), np.abs(constraints.input_max()))
    reach = np.einsum("ij,jk,ik->i", gain, np.linalg.inv(p), gain)
    alpha = float(np.max(params.lyapunov_threshold * reach / bounds**2))
    return LyapunovDesign(
        gain=gain,
        matrix=alpha * p,
        threshold=params.lyapunov_threshold,
        state_cost=q,
        input_cost=r,
    )
