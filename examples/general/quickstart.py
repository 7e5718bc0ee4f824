"""HOODESolver.jl's quickstart problem without C++: A as a matrix, f as a numpy function.

    u' = (1/eps) A u + f(u),  eps = 1e-4,  u0 = (0.55, 0.12, 0.03, 0.89),  T = 3,
    A turns (u1, u3),  f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2).

Runs eab of order 4 (n_tau 32, h = 0.1) and collocation with f in Python, and measures their
errors against rk78 on the filtered problem (tol 1e-13) and on the direct problem u' = A u /
eps + f(u) (tol 1e-13, the stiff equation as it stands), both computed with the core's C++
field "quickstart" (the same f). Run with the package on PYTHONPATH:

    PYTHONPATH=build/python python3 examples/general/quickstart.py
"""
import numpy as np

import tsi

A = [[0, 0, 1, 0],
     [0, 0, 0, 0],
     [-1, 0, 0, 0],
     [0, 0, 0, 0]]
U0 = [0.55, 0.12, 0.03, 0.89]


@tsi.register_field("quickstart-py", dim=4)
def f(t, u):
    # t: one time per column (unused: f is autonomous); u: 4 x n, one state per column.
    u1, u2, u4 = u[0], u[1], u[3]
    return np.array([np.zeros_like(u1), u4, 2 * u1 * u2, -u2 - u1 * u1 + u2 * u2])


def config(f_name, scheme, reference=None):
    c = {"model": {"name": "matrix", "eps": 1e-4, "A": A, "f": f_name, "u0": U0},
         "reformulation": {"name": "two-scale", "n_tau": 32},
         "scheme": scheme,
         "time": {"h": 0.1, "t_end": 3.0}}
    if reference is not None:
        c["reference"] = reference
    return c


# Two independent references, computed with the C++ field (the same f).
references = {}
for reformulation in ("filtered", "direct"):
    r = tsi.run(config("quickstart", {"name": "se1"}, {"reformulation": reformulation, "tol": 1e-13}))
    references[reformulation] = r.reference
gap = np.linalg.norm(references["filtered"] - references["direct"]) / np.linalg.norm(references["direct"])
print(f"references: rk78 on filtered and on direct agree to {gap:.1e}")

for scheme in ({"name": "eab", "order": 4}, {"name": "collocation"}):
    r = tsi.run(config("quickstart-py", scheme))
    assert r.status == "completed", r.message
    errors = {k: np.linalg.norm(r.u_final - ref) / np.linalg.norm(ref) for k, ref in references.items()}
    print(f"{scheme['name']:12s} u(3) = {np.array2string(r.u_final, precision=10)}  "
          f"error {errors['filtered']:.2e} (filtered), {errors['direct']:.2e} (direct)  {r.wall_seconds:.2f} s")
