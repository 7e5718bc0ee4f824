"""Models written in Python: a complete example, Henon-Heiles (eq. HH model of the paper),
the same system as the C++ plugin plugins/models/henon_heiles.

    import tsi
    from tsi.models import HenonHeiles
    tsi.register_model("py-hh", HenonHeiles, n_tau=64, nonlinearity_degree=2)
    tsi.run({"model": {"name": "py-hh", "eps": 0.01}, "reference": {}})

Batched functions get one state per column (dim x n numpy arrays) and return a new array of
the same shape; single states (apply_M, apply_J, H1) are 1-d arrays.
"""
import numpy as np


class HenonHeiles:
    """u = (q1, q2, p1, p2), M = diag(1, 0, 1, 0), J = [[0, I2], [-I2, 0]],
    H1 = q2^2/2 + p2^2/2 + q1^2 q2 - q2^3/3."""

    dim = 4
    is_complex = False

    def __init__(self, eps):
        self.eps = eps

    def linear_flow(self, taus, u):
        # e^{JM tau} turns (q1, p1) only.
        c, s = np.cos(taus), np.sin(taus)
        out = u.copy()
        out[0] = c * u[0] + s * u[2]
        out[2] = -s * u[0] + c * u[2]
        return out

    def nonlinear_field(self, u):
        q1, q2, p2 = u[0], u[1], u[3]
        return np.array([np.zeros_like(q1), p2, -2.0 * q1 * q2, -q2 - q1 * q1 + q2 * q2])

    def filtered_field(self, taus, u):
        # The flow, the field and the flow back in one pass: only q1 turns, and the (q1, p1)
        # part of the field, (0, -2 q1 q2), turns back by -tau.
        c, s = np.cos(taus), np.sin(taus)
        q1 = c * u[0] + s * u[2]
        q2, p2 = u[1], u[3]
        g = -2.0 * q1 * q2
        return np.array([-s * g, p2, c * g, -q2 - q1 * q1 + q2 * q2])

    def apply_M(self, u):
        return np.array([u[0], 0.0, u[2], 0.0])

    def apply_J(self, u):
        return np.array([u[2], u[3], -u[0], -u[1]])

    def H1(self, u):
        q1, q2, p2 = u[0], u[1], u[3]
        return 0.5 * q2 * q2 + 0.5 * p2 * p2 + q1 * q1 * q2 - q2 * q2 * q2 / 3.0

    def initial_value(self):
        return np.full(4, 0.12)
