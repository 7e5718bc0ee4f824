"""A model written in Python: the general class with A as a matrix and f in numpy, then a
Hamiltonian model as a class, then the one-call form tsi.solve."""
import numpy as np

import tsi

# 1. u' = (1/eps) A u + f(u): A turns (u1, u3) with period 2 pi, f is any numpy function.
A = [[0, 0, 1, 0],
     [0, 0, 0, 0],
     [-1, 0, 0, 0],
     [0, 0, 0, 0]]


@tsi.register_field("my-f", dim=4)
def f(t, u):
    # t: one time per column; u: 4 x n, one state per column (a whole tau grid at once).
    u1, u2, u4 = u[0], u[1], u[3]
    return np.array([np.zeros_like(u1), u4, 2 * u1 * u2, -u2 - u1 * u1 + u2 * u2])


config = {"model": {"name": "matrix", "eps": 1e-4, "A": A, "f": "my-f",
                    "u0": [0.55, 0.12, 0.03, 0.89]},
          "reformulation": {"name": "two-scale", "n_tau": 32},
          "scheme": {"name": "eab", "order": 4},
          "time": {"h": 0.1, "t_end": 3}}
r = tsi.run(config)
print(f"f in Python: {r.status}, u(3) = {r.u_final}")

# The same run with the core's C++ field "quickstart" (the same f) gives the same numbers.
r_cpp = tsi.run({**config, "model": {**config["model"], "f": "quickstart"}})
print(f"f in C++ differs by {np.abs(r.u_final - r_cpp.u_final).max():.1e}")

# A that is not 2 pi-periodic is refused before anything runs, naming the field.
try:
    tsi.run({**config, "model": {**config["model"], "A": (1.1 * np.array(A)).tolist()}})
except tsi.ConfigError as e:
    print(f"refused: {e.field}")


# 2. A Hamiltonian model as a class: u' = J [ (1/eps) M u + grad H1(u) ].
#    Here the Henon-Heiles system of the paper, u = (q1, q2, p1, p2).
class MyHenonHeiles:
    dim = 4
    is_complex = False

    def __init__(self, eps):
        self.eps = eps

    def linear_flow(self, taus, u):          # e^{JM tau} on every column: turns (q1, p1)
        c, s = np.cos(taus), np.sin(taus)
        out = u.copy()
        out[0] = c * u[0] + s * u[2]
        out[2] = -s * u[0] + c * u[2]
        return out

    def nonlinear_field(self, u):            # J grad H1 on every column
        q1, q2, p2 = u[0], u[1], u[3]
        return np.array([np.zeros_like(q1), p2, -2.0 * q1 * q2, -q2 - q1 * q1 + q2 * q2])

    def apply_M(self, u):
        return np.array([u[0], 0.0, u[2], 0.0])

    def apply_J(self, u):
        return np.array([u[2], u[3], -u[0], -u[1]])

    def H1(self, u):
        q1, q2, p2 = u[0], u[1], u[3]
        return 0.5 * q2 * q2 + 0.5 * p2 * p2 + q1 * q1 * q2 - q2 ** 3 / 3.0

    def initial_value(self):
        return np.full(4, 0.12)


tsi.register_model("my-hh", MyHenonHeiles, n_tau=64, nonlinearity_degree=2)
for name in ("my-hh", "henon-heiles"):   # the Python model and the shipped C++ one
    r = tsi.run({"model": {"name": name, "eps": 1e-3}, "scheme": {"name": "se1"},
                 "time": {"h": 0.125, "t_end": 1}, "reference": {}})
    print(f"{name:13s} error {r.error:.6e}, max err_H {r.invariants['err_H'].max():.2e}")

# 3. In one call, as HOODESolver.jl's solve: u at every step, one row per time.
t, u, r = tsi.solve(A, f, 1e-4, [0.55, 0.12, 0.03, 0.89], (0, 3), h=0.1)
print(f"tsi.solve: {len(t)} times, u(3) = {u[-1]}")
