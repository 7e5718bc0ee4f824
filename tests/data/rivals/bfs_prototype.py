#!/usr/bin/python3
"""Prototype for bfs.md: exponential-type integrators on the twisted Klein-Gordon variables
(Baumstark-Faou-Schratz construction, RECONSTRUCTED -- the paper's own scheme formulas could
not be read; see bfs.md sections 0 and 6).  numpy only, run with /usr/bin/python3 (~2 s CPU).

Problem: MicroMacro.jl's CosSin Klein-Gordon data, complex z, N_x = 128 on [0, 2 pi),
T = 0.25, eps = 1/c^2, references in micromacro-cos-sin/ (as in micro_macro_prototype.py).

Variables (all identical to BFS's first-order form, bfs.md section 1):
  u = z - i c^-1 <nabla>_c^-1 z_t ,  v = conj(z) - i c^-1 <nabla>_c^-1 conj(z)_t ,
  <nabla>_c = sqrt(c^2 - Laplacian),  z = (u + conj v)/2,
  i u_t = -c<nabla>_c u + c<nabla>_c^-1 f(z),  f(z) = lam |z|^2 z   (lam = -1 for CosSin)
  twisted u_* = e^{-i c^2 t} u,  v_* = e^{-i c^2 t} v:
  d/dt u_* = i A u_* - i kap sum_l e^{2 i l c^2 t} N_l(u_*, v_*),   A = c<nabla>_c - c^2,
  kap = lam c<nabla>_c^-1 / 8,  d/dt v_* = same with N_l(v_*, u_*),  l in {0, 1, -1, -2}:
  N_0 = (|u|^2 + 2|v|^2) u,  N_1 = u^2 v,  N_-1 = (2|u|^2 + |v|^2) conj(v),  N_-2 = conj(u v^2).
Schemes:
  BFS1-R   first order: u^{n+1} = e^{i tau A} [u^n - i kap tau sum_l E_l phi1(2 i l c^2 tau) N_l(u^n, v^n)]
  BFS2-R   second order: midpoint (Strang-like) dispersion, oscillatory phases and their
           pairwise interactions integrated exactly, first-order Taylor of the dispersion under
           the oscillatory weights (term L_l); see bfs.md section 4.
  BFS2-R-noL  the same without the L_l term (shows that it is needed for uniformity).
"""
import time

import numpy as np

from micro_macro_prototype import NX, XK, kg_data, kg_ref, rel

LAM = -1.0
LS = (0, 1, -1, -2)


# ---------------------------------------------------------------------------------------------
# scalar weights (x real): phi1(ix) = (e^{ix}-1)/(ix), psi1(ix) = int_0^1 th e^{ix th} dth
# ---------------------------------------------------------------------------------------------


def phi1(x):
    z = 1j * x
    if abs(x) < 1e-3:
        return 1 + z / 2 + z * z / 6 + z**3 / 24 + z**4 / 120
    return (np.exp(z) - 1) / z


def psi1(x):
    z = 1j * x
    if abs(x) < 5e-2:
        s, t = 0.0, 1.0
        for n in range(10):
            s += t / (n + 2)
            t *= z / (n + 1)
        return s
    return (np.exp(z) * (z - 1) + 1) / (z * z)


def K(a, b, tau):
    """int_0^tau e^{i a s} int_0^s e^{i b r} dr ds  (a, b real frequencies)"""
    if b == 0:
        return tau * tau * psi1(a * tau)
    return tau / (1j * b) * (phi1((a + b) * tau) - phi1(a * tau))


# ---------------------------------------------------------------------------------------------
# the four phase components and their derivative coefficients
#   DN_l(u, v)[du, dv] = P du + Q conj(du) + R dv + S conj(dv)
# ---------------------------------------------------------------------------------------------


def N(l, u, v):
    if l == 0:
        return (abs(u) ** 2 + 2 * abs(v) ** 2) * u
    if l == 1:
        return u * u * v
    if l == -1:
        return (2 * abs(u) ** 2 + abs(v) ** 2) * np.conj(v)
    return np.conj(u) * np.conj(v) ** 2  # l == -2


def PQRS(l, u, v):
    cu, cv = np.conj(u), np.conj(v)
    z = np.zeros_like(u)
    if l == 0:
        return 2 * abs(u) ** 2 + 2 * abs(v) ** 2, u * u, 2 * u * cv, 2 * u * v
    if l == 1:
        return 2 * u * v, z, u * u, z
    if l == -1:
        return 2 * cu * cv, 2 * u * cv, cv * cv, 2 * abs(u) ** 2 + 2 * abs(v) ** 2
    return z, cv * cv, z, 2 * cu * cv  # l == -2


class BFS:
    def __init__(self, eps, lam=LAM):
        self.eps, self.c2, self.lam = eps, 1.0 / eps, lam
        # c<nabla>_c - c^2 = (sqrt(1 + eps k^2) - 1)/eps, written without cancellation (the
        # difference form loses ~1e-16/(eps k^2) relative: 1e-6 at eps = 1e-10, k = 1)
        self.A = XK**2 / (np.sqrt(1 + eps * XK**2) + 1)
        self.B = (1 + eps * XK**2) ** -0.5  # c<nabla>_c^-1

    # Fourier multipliers on physical-space arrays
    def mult(self, m, g):
        return np.fft.ifft(m * np.fft.fft(g))

    def kap(self, g):
        return self.lam / 8 * self.mult(self.B, g)

    def eA(self, s, g):
        return self.mult(np.exp(1j * s * self.A), g)

    # ---- first order -------------------------------------------------------------------------
    def step1(self, t, tau, u, v):
        c2 = self.c2
        du, dv = 0, 0
        for l in LS:
            w = np.exp(2j * l * c2 * t) * tau * phi1(2 * l * c2 * tau)
            du = du + w * N(l, u, v)
            dv = dv + w * N(l, v, u)
        return self.eA(tau, u - 1j * self.kap(du)), self.eA(tau, v - 1j * self.kap(dv))

    # ---- second order ------------------------------------------------------------------------
    def step2(self, t, tau, u, v, withL=True):
        c2 = self.c2
        w, wv = self.eA(tau / 2, u), self.eA(tau / 2, v)
        E = {l: np.exp(2j * l * c2 * t) for l in LS}
        om = {l: 2 * l * c2 for l in LS}
        # kap N_m at the midpoint state, for both components (delta(s) of bfs.md (4.2))
        kN = {m: (self.kap(N(m, w, wv)), self.kap(N(m, wv, w))) for m in LS}
        Aw, Awv = 1j * self.mult(self.A, w), 1j * self.mult(self.A, wv)
        out = []
        for (x, y, Ax, Ay, comp) in ((w, wv, Aw, Awv, 0), (wv, w, Awv, Aw, 1)):
            acc = 0
            for l in LS:
                I0 = tau * phi1(om[l] * tau)
                term = I0 * N(l, x, y)
                if withL and l != 0:
                    I1 = tau * tau * psi1(om[l] * tau) - tau / 2 * I0
                    P, Q, R, S = PQRS(l, x, y)
                    L = (-1j * self.mult(self.A, N(l, x, y))
                         + P * Ax + Q * np.conj(Ax) + R * Ay + S * np.conj(Ay))
                    term = term + I1 * L
                # interactions: int_0^tau e^{i om_l s} DN_l[delta(s)] ds
                P, Q, R, S = PQRS(l, x, y)
                for m in LS:
                    kx, ky = kN[m][comp], kN[m][1 - comp]
                    term = term + (-1j * E[m] * K(om[l], om[m], tau) * (P * kx + R * ky)
                                   + 1j * np.conj(E[m]) * K(om[l], -om[m], tau)
                                   * (Q * np.conj(kx) + S * np.conj(ky)))
                acc = acc + E[l] * term
            out.append(self.eA(tau / 2, x - 1j * self.kap(acc)))
        return out[0], out[1]

    def solve(self, tau, order, Tf=0.25, withL=True):
        u, v = kg_data(self.eps)
        n = int(round(Tf / tau))
        for j in range(n):
            if order == 1:
                u, v = self.step1(j * tau, tau, u, v)
            else:
                u, v = self.step2(j * tau, tau, u, v, withL)
        ph = np.exp(1j * self.c2 * n * tau)
        return ph * u, ph * v


# ---------------------------------------------------------------------------------------------
# limit (c = infinity) schemes on the coupled NLS  i u_t = 1/2 Lap u + lam/8 (|u|^2+2|v|^2) u
# ---------------------------------------------------------------------------------------------


def limit_scheme(u, v, tau, n, order, lam=LAM):
    eA = lambda s, g: np.fft.ifft(np.exp(1j * s * XK**2 / 2) * np.fft.fft(g))
    for _ in range(n):
        if order == 1:  # Lie, nonlinear sub-step by one explicit Euler step
            Vu, Vv = abs(u) ** 2 + 2 * abs(v) ** 2, abs(v) ** 2 + 2 * abs(u) ** 2
            u, v = eA(tau, u - 1j * lam * tau / 8 * Vu * u), eA(tau, v - 1j * lam * tau / 8 * Vv * v)
        else:  # Strang, nonlinear sub-step by its 2nd-order Taylor polynomial
            u, v = eA(tau / 2, u), eA(tau / 2, v)
            Vu, Vv = abs(u) ** 2 + 2 * abs(v) ** 2, abs(v) ** 2 + 2 * abs(u) ** 2
            a, b = -1j * lam * tau / 8 * Vu, -1j * lam * tau / 8 * Vv
            u, v = eA(tau / 2, u * (1 + a + a * a / 2)), eA(tau / 2, v * (1 + b + b * b / 2))
    return u, v


def ode_ref(eps):
    """eps without a published reference: kg_complex_if_solve.py (DOP853, 1e-12, same problem)"""
    from kg_complex_if_solve import solve as if_solve
    return if_solve(eps)


def table(name, run, epss, taus, ref=kg_ref):
    t0 = time.process_time()
    where = "micromacro-cos-sin/" if ref is kg_ref else "kg_complex_if_solve.py (DOP853, tol 1e-12)"
    print(f"{name}: relative L2 error of (u, v) at T = 0.25 vs {where}")
    print("    eps      " + "".join(f"  tau=T/{int(round(0.25 / d)):<3d}" for d in taus) + "  orders")
    for e in epss:
        ur, vr = ref(e)
        errs = [rel(*run(e, d), ur, vr) for d in taus]
        o = [np.log2(errs[i] / errs[i + 1]) for i in range(len(taus) - 1)]
        print(f"    {e:<8g}" + "".join(f"  {x:9.2e}" for x in errs) + "  " + " ".join(f"{x:5.2f}" for x in o))
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


def limit_check():
    """BFS*-R at eps -> 0 against the limit splitting of bfs.md section 5 (same data, twisted)."""
    print("Limit check: max |scheme(eps) - limit splitting| on the twisted variables, tau = T/16, 16 steps")
    tau, n = 0.25 / 16, 16
    u0, v0 = kg_data(1e-12)  # c<nabla>_c^-1 -> 1: u(0) -> phi - i gamma
    for order in (1, 2):
        lu, lv = limit_scheme(u0.copy(), v0.copy(), tau, n, order)
        row = []
        for e in (1e-4, 1e-6, 1e-8, 1e-10):
            s = BFS(e)
            u, v = kg_data(e)
            for j in range(n):
                u, v = s.step1(j * tau, tau, u, v) if order == 1 else s.step2(j * tau, tau, u, v)
            row.append(max(abs(u - lu).max(), abs(v - lv).max()))
        print(f"    order {order}: eps = 1e-4, 1e-6, 1e-8, 1e-10: " + "  ".join(f"{x:9.2e}" for x in row))


if __name__ == "__main__":
    epss = [1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-6]
    taus = [0.25 / 2**k for k in range(2, 7)]
    table("BFS1-R (first order)", lambda e, d: BFS(e).solve(d, 1), epss, taus)
    table("BFS2-R (second order)", lambda e, d: BFS(e).solve(d, 2), epss, taus)
    table("BFS2-R-noL (second order without the L_l term)", lambda e, d: BFS(e).solve(d, 2, withL=False),
          epss, taus)
    table("BFS2-R, intermediate regime, smaller steps", lambda e, d: BFS(e).solve(d, 2),
          [0.03, 0.01, 0.003], [0.25 / 2**k for k in range(4, 9)], ref=ode_ref)
    limit_check()
