#!/usr/bin/env python3
"""Boris-type integrators for x' = v, v' = v x B(x) + E(x), B(x) = B0/eps + B1(x).

Written from the papers (not from any peer code):
  classical : Boris (1970) in the form of Hairer-Lubich-Wang, Numer. Math. 144 (2020) 787-809,
              eq. (2.1), with the rotation t = h B/2, s = 2t/(1+|t|^2).
  exp-A     : filtered Boris, HLW 2020 Algorithm 2.1 with theta = 1 (x_bar = x), explicit.
  imp-A     : filtered Boris, HLW 2020 Algorithm 2.1 with theta(xi) = 1/sinc(xi/2)^2, eq. (2.5),
              solved by the fixed-point iteration of HLW Sect. 2 (around eq. (2.8)).
  imp-A1    : the same with exactly one fixed-point iteration (HLW: "just one iteration is
              sufficient").
  twoP-A    : two-point filtered Boris, HLW 2020 Algorithm 7.1 (bonus, not asked for).
  large-step: classical Boris whose initial velocity has its component normal to B(x0) removed
              (HLS 2022 abstract; Lubich-Shi BIT 2023 intro). The exact starting formula of HLS 2022
              could NOT be read; this is an INFERRED reading, see boris.md.

Test (HLW 2020 Sect. 8; SPEC.md section 8): B = (-x1, 0, x3 + 1/eps),
E = (x1, x2, 0)/(x1^2+x2^2)^{3/2}, x0 = (1/3, 1/4, 1/2), v0 = (2/5, 2/3, 1), T = 1.
Reference: scipy DOP853, rtol = atol = 1e-13.

Run: OMP_NUM_THREADS=1 nice python3 boris_variants.py   (system python: /usr/bin/python3)
"""
import os
os.environ.setdefault("OMP_NUM_THREADS", "1")
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
import sys
import numpy as np
from scipy.integrate import solve_ivp

X0 = np.array([1 / 3, 1 / 4, 1 / 2])
V0 = np.array([2 / 5, 2 / 3, 1.0])


def make_fields(eps):
    def B(x):
        return np.array([-x[0], 0.0, x[2] + 1.0 / eps])

    def E(x):
        r2 = x[0] ** 2 + x[1] ** 2
        return np.array([x[0], x[1], 0.0]) / r2 ** 1.5

    return B, E


# ---------------------------------------------------------------- matrix functions g(h Bhat)
def hat(b):
    """Bhat v = b x v  (HLW (2.2): v x B = -Bhat v)."""
    return np.array([[0.0, -b[2], b[1]], [b[2], 0.0, -b[0]], [-b[1], b[0], 0.0]])


def matfun(g0, gi, b, h):
    """g(h Bhat) for a function g with g(0) = g0 and gi(y) = g(i y) (complex), y = h|b|.
    On span(b): g(0); on the normal plane Bhat = |b| J, J^2 = -I, so
    g(h Bhat) = g0 I + (g0 - Re g(i h|b|)) Bhat^2/|b|^2 + Im g(i h|b|) Bhat/|b|
    (the Rodriguez-type formula of HLW Appendix, (8.1))."""
    bn = np.linalg.norm(b)
    K = hat(b) / bn
    val = gi(h * bn)
    return g0 * np.eye(3) + (g0 - val.real) * (K @ K) + val.imag * K


def expm_neg(b, h):          # exp(-h Bhat)
    return matfun(1.0, lambda y: np.exp(-1j * y), b, h)


def Psi(b, h):               # Psi(z) = tanh(z/2)/(z/2); Psi(iy) = tan(y/2)/(y/2)
    return matfun(1.0, lambda y: complex(np.tan(y / 2) / (y / 2)), b, h)


def Phi1(b, h):              # Phi1(z) = 1/sinch(z) = z/sinh(z); Phi1(iy) = y/sin(y)
    return matfun(1.0, lambda y: complex(y / np.sin(y)), b, h)


def Phi2(b, h):              # Phi2(z) = 1/sinch(z/2)^2; Phi2(iy) = ((y/2)/sin(y/2))^2
    return matfun(1.0, lambda y: complex(((y / 2) / np.sin(y / 2)) ** 2), b, h)


def Ups(b, h):               # Upsilon(z) = (Phi1(z)-1)/z; Upsilon(iy) = -i (y/sin y - 1)/y
    return matfun(0.0, lambda y: -1j * (y / np.sin(y) - 1.0) / y, b, h)


def phi1m(b, h):             # phi1(-h Bhat), phi1(z) = (e^z - 1)/z; phi1(-iy) = (1 - e^{-iy})/(iy)
    return matfun(1.0, lambda y: (1 - np.exp(-1j * y)) / (1j * y), b, h)


def phi1p(b, h):             # phi1(+h Bhat)
    return matfun(1.0, lambda y: (np.exp(1j * y) - 1) / (1j * y), b, h)


def sinch(b, h):             # sinch(z) = sinh(z)/z; sinch(iy) = sin(y)/y
    return matfun(1.0, lambda y: complex(np.sin(y) / y), b, h)


def theta_fn(xi):            # HLW (2.5)
    return 1.0 / (np.sin(xi / 2) / (xi / 2)) ** 2


def guiding_center(x, v, b):  # HLW (2.3)
    return x + np.cross(v, b) / np.dot(b, b)


# ---------------------------------------------------------------- integrators
def classical(B, E, x0, v0, h, N, filter_v0=False):
    """HLW (2.1), staggered (x^n, v^{n-1/2}) -> (x^{n+1}, v^{n+1/2}).
    Start: v^{1/2} = v^0 + h/2 (v^0 x B^0 + E^0)   [from v^{n+-1/2} = v^n +- h/2 (v^n x B^n + E^n),
    which is HLW's relation v^{n-1/2} = v^n - h/2 v^n x B^n - h/2 E^n with v^n = (x^{n+1}-x^{n-1})/2h].
    Output velocity: v^N = (I + h/2 Bhat^N)^{-1} (v^{N-1/2} + h/2 E^N) = (v^{N-1/2}+v^{N+1/2})/2.
    filter_v0: large-step reading (v^0 -> its component along B(x^0))."""
    x = x0.copy()
    v = v0.copy()
    b0 = B(x)
    if filter_v0:
        u = b0 / np.linalg.norm(b0)
        v = np.dot(u, v) * u
    vh = v + 0.5 * h * (np.cross(v, b0) + E(x))      # v^{1/2}
    x = x + h * vh                                   # x^1
    for n in range(1, N):
        b = B(x)
        e = E(x)
        vm = vh + 0.5 * h * e                        # v_+^{n-1/2} in HLW's notation
        t = 0.5 * h * b
        s = 2 * t / (1 + np.dot(t, t))
        vp = vm + np.cross(vm, t)
        vrot = vm + np.cross(vp, s)                  # v_-^{n+1/2}
        vh = vrot + 0.5 * h * e
        x = x + h * vh
    b = B(x)
    vN = np.linalg.solve(np.eye(3) + 0.5 * h * hat(b), vh + 0.5 * h * E(x))
    return x, vN


def filtered(B, E, x0, v0, h, N, mode="imp", maxit=60, tol=1e-15):
    """HLW 2020 Algorithm 2.1 (2.6)-(2.7); mode 'exp' (theta=1), 'imp' (theta of (2.5), iterated to
    convergence), 'imp1' (one fixed-point iteration starting from x_bar = x^n).
    Start: v^{1/2} = phi1(-h Bbar^0)(v^0 + h Ups(h B^0) E^0) + h/2 Psi(h B^0) E^0, eq. (2.10), n = 0,
    with x_bar^0 from x^0, v^0 (explicit).
    Output velocity: v^N from (2.7) (one more velocity half-step at x^N)."""

    def xbar_of(x, v, b, th):
        if mode == "exp":
            return x
        return th * x + (1 - th) * guiding_center(x, v, b)

    x = x0.copy()
    b = B(x)
    e = E(x)
    th = theta_fn(h * np.linalg.norm(b))
    bb = B(xbar_of(x, v0, b, th))
    vh = phi1m(bb, h) @ (v0 + h * (Ups(b, h) @ e)) + 0.5 * h * (Psi(b, h) @ e)
    x = x + h * vh
    vn = None
    for n in range(1, N + 1):
        b = B(x)
        e = E(x)
        ps = Psi(b, h) @ e
        up = Ups(b, h) @ e
        th = theta_fn(h * np.linalg.norm(b))
        vplus = vh + 0.5 * h * ps
        xb = x.copy()                                  # start of the iteration: x_bar = x^n
        its = 1 if mode in ("exp", "imp1") else maxit
        for k in range(its):
            bb = B(xb)
            vminus = expm_neg(bb, h) @ vplus
            vn = Phi1(bb, h) @ (0.5 * (vminus + vplus)) - h * up      # (2.7) with (2.8)
            if mode == "exp":
                break
            xb_new = xbar_of(x, vn, b, th)
            if mode == "imp1":
                bb = B(xb_new)
                vminus = expm_neg(bb, h) @ vplus
                vn = Phi1(bb, h) @ (0.5 * (vminus + vplus)) - h * up
                break
            d = np.linalg.norm(xb_new - xb)
            xb = xb_new
            if d <= tol * (1 + np.linalg.norm(xb)):
                bb = B(xb)
                vminus = expm_neg(bb, h) @ vplus
                vn = Phi1(bb, h) @ (0.5 * (vminus + vplus)) - h * up
                break
        if n == N:
            return x, vn                               # x^N and v^N (2.7)
        vh = vminus + 0.5 * h * ps
        x = x + h * vh


def two_point(B, E, x0, v0, h, N, maxit=60, tol=1e-15):
    """HLW 2020 Algorithm 7.1: Phi2(h Bhat_c)(v_- - v_+) = h/2 Phi1(h Bhat^n)(v_- + v_+) x B^n,
    B_c = B(x_c^n), x_c^n the guiding centre (2.3) built from v^n of (2.7) (with B^n for B_bar).
    Start: v^{1/2} = Phi_+ v^0 + h/2 Psi_+ E^0, Phi_+ = (I - 1/2 Lambda h Bhat) sinch(h Bhat),
    Lambda = Phi2(h Bhat_c)^{-1} Phi1(h Bhat), Psi_+ = Psi + 2 Phi_+ Ups (HLW p. 804)."""
    x = x0.copy()
    b = B(x)
    e = E(x)
    bc = B(guiding_center(x, v0, b))
    Lam = np.linalg.solve(Phi2(bc, h), Phi1(b, h))
    Php = (np.eye(3) - 0.5 * h * Lam @ hat(b)) @ sinch(b, h)
    Psp = Psi(b, h) + 2 * Php @ Ups(b, h)
    vh = Php @ v0 + 0.5 * h * (Psp @ e)
    x = x + h * vh
    for n in range(1, N + 1):
        b = B(x)
        e = E(x)
        ps = Psi(b, h) @ e
        up = Ups(b, h) @ e
        P1 = Phi1(b, h)
        Bh = hat(b)
        vplus = vh + 0.5 * h * ps
        vminus = expm_neg(b, h) @ vplus
        for k in range(maxit):
            vn = P1 @ (0.5 * (vminus + vplus)) - h * up
            bc = B(guiding_center(x, vn, b))
            P2 = Phi2(bc, h)
            M = 0.5 * h * Bh @ P1
            vnew = np.linalg.solve(P2 + M, (P2 - M) @ vplus)
            d = np.linalg.norm(vnew - vminus)
            vminus = vnew
            if d <= tol * np.linalg.norm(vnew):
                break
        vn = P1 @ (0.5 * (vminus + vplus)) - h * up
        if n == N:
            return x, vn
        vh = vminus + 0.5 * h * ps
        x = x + h * vh


# ---------------------------------------------------------------- reference
_ref_cache = {}


def reference(eps, T, rtol=1e-13, atol=1e-13):
    key = (eps, T, rtol, atol)
    if key in _ref_cache:
        return _ref_cache[key]
    B, E = make_fields(eps)

    def f(t, y):
        x, v = y[:3], y[3:]
        return np.concatenate([v, np.cross(v, B(x)) + E(x)])

    sol = solve_ivp(f, (0.0, T), np.concatenate([X0, V0]), method="DOP853",
                    rtol=rtol, atol=atol)
    _ref_cache[key] = sol.y[:, -1]
    return sol.y[:, -1]


METHODS = {
    "classical": lambda B, E, h, N: classical(B, E, X0, V0, h, N),
    "exp-A": lambda B, E, h, N: filtered(B, E, X0, V0, h, N, mode="exp"),
    "imp-A": lambda B, E, h, N: filtered(B, E, X0, V0, h, N, mode="imp"),
    "imp-A1": lambda B, E, h, N: filtered(B, E, X0, V0, h, N, mode="imp1"),
    "twoP-A": lambda B, E, h, N: two_point(B, E, X0, V0, h, N),
    "large-step*": lambda B, E, h, N: classical(B, E, X0, V0, h, N, filter_v0=True),
}


def errors(eps, h, N):
    B, E = make_fields(eps)
    T = N * h
    yref = reference(eps, T)
    xr, vr = yref[:3], yref[3:]
    br = B(xr)
    u = br / np.linalg.norm(br)
    out = {}
    for name, m in METHODS.items():
        x, v = m(B, E, h, N)
        bx = B(x)
        un = bx / np.linalg.norm(bx)
        vpar, vpar_r = np.dot(un, v) * un, np.dot(u, vr) * u
        out[name] = (np.linalg.norm(x - xr), np.linalg.norm(vpar - vpar_r),
                     np.linalg.norm((v - vpar) - (vr - vpar_r)))
    return T, out


def main():
    np.set_printoptions(precision=3)
    # reference self-check
    e10 = 2.0 ** -10
    y1 = reference(e10, 1.0)
    y2 = reference(e10, 1.0, rtol=1e-11, atol=1e-11)
    print(f"# reference check eps=2^-10: |x(1e-13) - x(1e-11)| = {np.linalg.norm(y1[:3]-y2[:3]):.2e}")
    print(f"# x_ref(T=1, eps=2^-10) = {y1[:3]}, v_ref = {y1[3:]}")
    names = list(METHODS)
    print("\n## Table 1: position error |x^N - x(T)| (Euclidean), h = r*eps exactly, N = round(1/h),"
          " T = N h")
    print("## columns: eps, r = h/eps, N, T, then one column per method")
    print("eps\tr\tN\tT\t" + "\t".join(names))
    res = {}
    for j in (8, 9, 10, 11, 12):
        eps = 2.0 ** -j
        for r in (2, 4, 8, 14):
            h = r * eps
            N = int(round(1.0 / h))
            T, out = errors(eps, h, N)
            res[(j, r)] = out
            print(f"2^-{j}\t{r}\t{N}\t{T:.4f}\t" + "\t".join(f"{out[k][0]:.2e}" for k in names))
            sys.stdout.flush()
    print("\n## Table 2: 'order at fixed ratio' = err(eps, h) / err(eps/2, h/2) (position);"
          " ~4 means second order, ~2 first order")
    print("r\tj->j+1\t" + "\t".join(names))
    for r in (2, 4, 8, 14):
        for j in (8, 9, 10, 11):
            a, b = res[(j, r)], res[(j + 1, r)]
            print(f"{r}\t{j}->{j+1}\t" + "\t".join(f"{a[k][0]/b[k][0]:.2f}" for k in names))
    print("\n## Table 3: velocity errors at eps=2^-10: |v_par err| / |v_perp err|")
    print("r\t" + "\t".join(names))
    for r in (2, 4, 8, 14):
        out = res[(10, r)]
        print(f"{r}\t" + "\t".join(f"{out[k][1]:.1e}/{out[k][2]:.1e}" for k in names))
    print("\n## Table 4: HLS regime eps = h^2 (h = 2^-k, eps = 2^-2k, T = 1): position error")
    print("h\teps\th/eps\t" + "\t".join(names))
    prev = None
    for k in (3, 4, 5, 6):
        h = 2.0 ** -k
        eps = h * h
        N = int(round(1.0 / h))
        T, out = errors(eps, h, N)
        print(f"2^-{k}\t2^-{2*k}\t{h/eps:.0f}\t" + "\t".join(f"{out[m][0]:.2e}" for m in names))
        if prev is not None:
            print("  ratio\t\t\t" + "\t".join(f"{prev[m][0]/out[m][0]:.2f}" for m in names))
        prev = out
        sys.stdout.flush()
    print("\n## Table 5: fixed eps = 2^-10, h = 1/k (HLW Fig. 2 style) position error")
    print("k\th/eps\t" + "\t".join(names))
    for k in (512, 256, 128, 73):
        h = 1.0 / k
        T, out = errors(2.0 ** -10, h, k)
        print(f"{k}\t{h/2**-10:.2f}\t" + "\t".join(f"{out[m][0]:.2e}" for m in names))


if __name__ == "__main__":
    main()
