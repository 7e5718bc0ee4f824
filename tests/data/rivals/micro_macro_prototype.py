#!/usr/bin/python3
"""Prototype checks for micro-macro.md (numpy/scipy only, independent of tsi; run with /usr/bin/python3).

Part A  Henon-Heiles in SPEC's form, u = (q1, q2, p1, p2), u' = (1/eps) A u + f(u), A = J M,
        M = diag(1, 0, 1, 0), f = J grad H1, u0 = 0.12 (1, 1, 1, 1), error |u_N - u(1)| / |u(1)|
        against DOP853 (rtol = atol = 1e-12).  Everything is written with the three model
        operations only: flow(u, tau) = e^{A tau} u, f(u), Df(u, z); tau-averages and the
        antiderivative A = (d/dtau)^{-1}(I - Pi) on a uniform grid of N_tau points by FFT.
        Schemes (all with one fixed step h, T = 1):
          MM1-RK2   micro-macro, stroboscopic Phi^[1], explicit midpoint RK2 on (v, w)
          MM2-RK2   micro-macro, stroboscopic Phi^[2], explicit midpoint RK2 on (v, w)
                    (d_u Phi^[2] by central differences: needs no D^2 f)
          CCLM-MP   the scheme of MicroMacro.jl src/ (standard averaging C1 = Phi^[1], macro by
                    midpoint RK2, micro by midpoint with the fast tau-dependence of the frozen
                    field integrated exactly)
          DF2-RK2   derivative-free (no Df at all) standard-averaging Phi^[2] in the style of
                    HOODESolver.jl src/preparephi.jl, micro-macro with explicit midpoint RK2
          NPI1      first-order 'exact tau-integral' Euler = MicroMacro.jl test/ schema 0 =
                    the first-order nested Picard integrator written for the general class
Part B  MicroMacro.jl src/ scheme (schema 2) transcribed for the complex Klein-Gordon CosSin case
        (N_x = 128, N_tau = 32, T = 0.25) against the published reference solutions in
        micromacro-cos-sin/ (relative discrete L2 error of (u, v)).
Part C  Cai-Zhou first-order NPI (newnpi1.m) on the same Klein-Gordon problem against the same
        references (psi_- = u/2, psi_+ = conj(v)/2, Bao's e^2 = eps, lambda_Bao = -1).
"""
import time

import numpy as np
from scipy.integrate import solve_ivp

# ----------------------------------------------------------------------------------------------
# tau-grid tools (last axis = tau).  Nyquist mode set to 0 in A and in the interpolant.
# ----------------------------------------------------------------------------------------------


class Grid:
    def __init__(self, n):
        self.n = n
        self.tau = 2 * np.pi * np.arange(n) / n
        self.k = np.fft.fftfreq(n, 1.0 / n)
        inv = np.zeros(n, complex)
        nz = self.k != 0
        inv[nz] = 1.0 / (1j * self.k[nz])
        inv[n // 2] = 0.0
        self.inv = inv

    def mean(self, g):
        return g.mean(axis=-1)

    def A(self, g):  # (d/dtau)^{-1} (I - Pi), mean-free antiderivative
        return np.fft.ifft(np.fft.fft(g, axis=-1) * self.inv, axis=-1).real

    def At(self, g):  # int_0^tau (g - <g>): the stroboscopic antiderivative, zero at tau = 0
        a = self.A(g)
        return a - a[..., :1]

    def interp(self, g, theta):  # trigonometric interpolant at an arbitrary theta
        c = np.fft.fft(g, axis=-1) / self.n
        c[..., self.n // 2] = 0.0
        return (c * np.exp(1j * self.k * theta)).sum(axis=-1).real


# ----------------------------------------------------------------------------------------------
# Henon-Heiles: the three model operations.  State axis FIRST: arrays (4, ...), tau broadcasts
# against the trailing axes.
# ----------------------------------------------------------------------------------------------


def flow(u, tau):  # e^{A tau} u, A = J M: (q1, p1) rotate, (q2, p2) fixed
    c, s = np.cos(tau), np.sin(tau)
    q1, q2, p1, p2 = u[0], u[1], u[2], u[3]
    return np.array(np.broadcast_arrays(c * q1 + s * p1, q2, -s * q1 + c * p1, p2))


def f(u):  # J grad H1, H1 = q2^2/2 + p2^2/2 + q1^2 q2 - q2^3/3
    q1, q2, p1, p2 = u
    return np.array([0 * q1, p2, -2 * q1 * q2, -(q2 + q1**2 - q2**2)])


def Df(u, z):
    q1, q2, p1, p2 = u
    a, b, c, d = z
    return np.array([0 * q1, d, -2 * (a * q2 + q1 * b), -(b + 2 * q1 * a - 2 * q2 * b)])


def ftau(y, tau):  # filtered field f_tau(y) = e^{-A tau} f(e^{A tau} y)
    return flow(f(flow(y, tau)), -tau)


def Dftau(y, z, tau):
    return flow(Df(flow(y, tau), flow(z, tau)), -tau)


def full_rhs(eps):
    def rhs(t, u):
        q1, q2, p1, p2 = u
        return np.array([p1 / eps, 0.0, -q1 / eps, 0.0]) + f(u)

    return rhs


U0 = 0.12 * np.ones(4)
D = 4
EYE = np.eye(D)


def reference(eps, T=1.0):
    sol = solve_ivp(full_rhs(eps), (0, T), U0, method="DOP853", rtol=1e-12, atol=1e-12)
    return sol.y[:, -1]


# ----------------------------------------------------------------------------------------------
# Stroboscopic micro-macro (CLMV): Phi^[0] = id,
#   F^[k]   = <d_u Phi^[k]>^{-1} <f o Phi^[k]>
#   Phi^[k+1]_theta = id + eps int_0^theta (f_s o Phi^[k]_s - d_u Phi^[k]_s F^[k]) ds
# u(t) = e^{A t/eps} (Phi^[n]_{t/eps}(v) + w),  v' = F^[n](v), v(0) = u0,
# w' = f_{t/eps}(Phi^[n](v) + w) - (1/eps) d_theta Phi^[n](v) - d_u Phi^[n](v) F^[n](v), w(0) = 0.
# v is a batch (4, B) everywhere.
# ----------------------------------------------------------------------------------------------


def rk_step(rhs, t, h, v, w, rk):
    """explicit midpoint (rk = 2) or classical RK4 (rk = 4) on the pair (v, w)"""
    if rk == 2:
        kv, kw = rhs(t, v, w)
        kv, kw = rhs(t + h / 2, v + h / 2 * kv, w + h / 2 * kw)
        return v + h * kv, w + h * kw
    a = rhs(t, v, w)
    b = rhs(t + h / 2, v + h / 2 * a[0], w + h / 2 * a[1])
    c = rhs(t + h / 2, v + h / 2 * b[0], w + h / 2 * b[1])
    d = rhs(t + h, v + h * c[0], w + h * c[1])
    return (v + h / 6 * (a[0] + 2 * b[0] + 2 * c[0] + d[0]),
            w + h / 6 * (a[1] + 2 * b[1] + 2 * c[1] + d[1]))


class Strobo:
    def __init__(self, eps, n, ntau=32, eta=1e-5):
        self.eps, self.n, self.g, self.eta = eps, n, Grid(ntau), eta

    # order 1 ----------------------------------------------------------------------------------
    def phi1(self, v):  # grid (4, B, N)
        return v[..., None] + self.eps * self.g.At(ftau(v[..., None], self.g.tau))

    def dphi1(self, v, z):  # d_u Phi^[1](v) z, grid
        return z[..., None] + self.eps * self.g.At(Dftau(v[..., None], z[..., None], self.g.tau))

    def F1(self, v):
        rhs = self.g.mean(ftau(self.phi1(v), self.g.tau))  # (4, B)
        B = v.shape[1]
        vv = np.repeat(v, D, axis=1)  # (4, B*4)
        zz = np.tile(EYE, (1, B))  # e_j repeated
        M = self.g.mean(self.dphi1(vv, zz)).reshape(D, B, D).transpose(1, 0, 2)  # (B, 4, 4)
        return np.linalg.solve(M, rhs.T[..., None])[..., 0].T

    # order 2 ----------------------------------------------------------------------------------
    def h1(self, v):  # f o Phi^[1] - d_u Phi^[1] F^[1]  (zero tau-mean)
        return ftau(self.phi1(v), self.g.tau) - self.dphi1(v, self.F1(v))

    def phi2(self, v):
        return v[..., None] + self.eps * self.g.At(self.h1(v))

    def dphi2(self, v, z):  # central difference on phi2 - id, z a batch of directions
        e = self.eta
        both = self.phi2(np.concatenate([v + e * z, v - e * z], axis=1)) - np.concatenate(
            [v + e * z, v - e * z], axis=1)[..., None]
        B = v.shape[1]
        return z[..., None] + (both[:, :B] - both[:, B:]) / (2 * e)

    def F2(self, v):
        rhs = self.g.mean(ftau(self.phi2(v), self.g.tau))
        B = v.shape[1]
        M = self.g.mean(self.dphi2(np.repeat(v, D, axis=1), np.tile(EYE, (1, B))))
        M = M.reshape(D, B, D).transpose(1, 0, 2)
        return np.linalg.solve(M, rhs.T[..., None])[..., 0].T

    # pieces at one theta ------------------------------------------------------------------------
    def parts(self, v):
        """grid functions Phi, (1/eps) d_theta Phi, d_u Phi F, and F"""
        g = self.g
        if self.n == 1:
            fg = ftau(v[..., None], g.tau)
            F = self.F1(v)
            return self.phi1(v), fg - g.mean(fg)[..., None], self.dphi1(v, F), F
        h = self.h1(v)
        F = self.F2(v)
        return v[..., None] + self.eps * g.At(h), h - g.mean(h)[..., None], self.dphi2(v, F), F

    def rhs(self, t, v, w):
        th = t / self.eps
        P, dth, dPF, F = self.parts(v)
        P, dth, dPF = (self.g.interp(a, th) for a in (P, dth, dPF))
        return F, ftau(P + w, th) - dth - dPF

    def solve(self, h, T=1.0, rk=2):
        v, w = U0[:, None].copy(), np.zeros((D, 1))
        N = int(round(T / h))
        for j in range(N):
            v, w = rk_step(self.rhs, j * h, h, v, w, rk)
        P = self.parts(v)[0]
        y = self.g.interp(P, N * h / self.eps) + w
        return flow(y, N * h / self.eps)[:, 0]


# ----------------------------------------------------------------------------------------------
# MicroMacro.jl src/ scheme (CCLM 2015, schema 2), general autonomous class:
#   C1(ub)(tau) = ub + eps A[f_.(ub)](tau)          macro: ub' = F(ub) = <f_.(C1(ub))>
#   g(tau) = f_tau(C1(ub)(tau) + w) - (I-Pi) f_tau(ub) - F - eps A[Df_.(ub) F](tau)
#   w(t+s) = w(t) + s <g> + eps [ (A g)((t+s)/eps) - (A g)(t/eps) ]   (g frozen)
#   midpoint: half step with the field at t, full step with the field at the half-step state.
#   init: ub0 = u0 - eps (A f_.(u0))(0), w0 = u0 - C1(ub0)(0).
# ----------------------------------------------------------------------------------------------


class CCLM:
    def __init__(self, eps, ntau=32):
        self.eps, self.g = eps, Grid(ntau)

    def C1(self, ub):
        return ub[:, None] + self.eps * self.g.A(ftau(ub[:, None], self.g.tau))

    def fields(self, ub, w):
        g, eps = self.g, self.eps
        fu = ftau(ub[:, None], g.tau)
        C1 = ub[:, None] + eps * g.A(fu)
        F = g.mean(ftau(C1, g.tau))
        dtC1 = F[:, None] + eps * g.A(Dftau(ub[:, None], F[:, None], g.tau))
        G = ftau(C1 + w[:, None], g.tau) - (fu - g.mean(fu)[:, None]) - dtC1
        return F, g.mean(G), g.A(G)

    def solve(self, h, T=1.0):
        g, eps = self.g, self.eps
        ub = U0 - eps * g.A(ftau(U0[:, None], g.tau))[:, 0]
        w = U0 - self.C1(ub)[:, 0]
        N = int(round(T / h))
        for j in range(N):
            t = j * h
            F, mG, iG = self.fields(ub, w)
            ub2 = ub + h / 2 * F
            w2 = w + h / 2 * mG + eps * (g.interp(iG, (t + h / 2) / eps) - g.interp(iG, t / eps))
            F, mG, iG = self.fields(ub2, w2)
            ub = ub + h * F
            w = w + h * mG + eps * (g.interp(iG, (t + h) / eps) - g.interp(iG, t / eps))
        th = N * h / eps
        return flow(g.interp(self.C1(ub), th) + w, th)


# ----------------------------------------------------------------------------------------------
# Derivative-free standard averaging of order 2 (HOODESolver preparephi.jl, phi()):
#   phi_1(u) = eps A f_.(u)
#   phi_2(u) = eps A[ f_.(u + phi_1(u)) - (phi_1(u + d1 G1) - phi_1(u)) / d1 ],
#              G1 = <f_.(u + phi_1(u))>, d1 = eps
#   macro G2(u) = <f_.(u + phi_2(u))>;  micro term d_u phi_2(u) G2 by a central difference of
#   small fixed step (default) or, as in the recursion, (phi_2(u + d2 G2) - phi_2(u)) / d2,
#   d2 = eps^2 (variant DF2*, inexact decomposition);  base point ub0 = u0 - phi_1(u0)(0), ub0 <- u0 - phi_2(ub0)(0);
#   w0 = u0 - ub0 - phi_2(ub0)(0).  Micro-macro with explicit midpoint RK2.
# ----------------------------------------------------------------------------------------------


class DF2:
    """micro = 'small': d_u phi_2(u) G2 by a central difference with step eta = 1e-5 (keeps the
    decomposition exact to ~1e-10); micro = 'eps^n': one-sided quotient with step eps^2 (as
    inside the recursion) -- then u != Phi(ub) + w by O(eps^3) per unit time (see eps = 1)."""

    def __init__(self, eps, ntau=32, micro="small", eta=1e-5):
        self.eps, self.g, self.micro, self.eta = eps, Grid(ntau), micro, eta

    def p1(self, u):  # u (4, B)
        return self.eps * self.g.A(ftau(u[..., None], self.g.tau))

    def p2(self, u):
        g, eps = self.g, self.eps
        a = self.p1(u)
        fa = ftau(u[..., None] + a, g.tau)
        d1 = eps
        b = self.p1(u + d1 * g.mean(fa))
        return eps * g.A(fa - (b - a) / d1)

    def rhs(self, t, ub, w):
        g, eps = self.g, self.eps
        th = t / eps
        p = self.p2(ub)
        G = g.mean(ftau(ub[..., None] + p, g.tau))
        if self.micro == "small":
            e = self.eta
            dpG = (self.p2(ub + e * G) - self.p2(ub - e * G)) / (2 * e)
        else:
            d2 = eps**2
            dpG = (self.p2(ub + d2 * G) - p) / d2
        P, dpG = g.interp(p, th), g.interp(dpG, th)
        dth = g.interp(np.fft.ifft(np.fft.fft(p, axis=-1) * 1j * g.k * (g.k != g.n // 2),
                                   axis=-1).real, th) / eps
        return G, ftau(ub + P + w, th) - dth - (G + dpG)

    def solve(self, h, T=1.0):
        u0 = U0[:, None]
        ub = u0 - self.p1(u0)[..., 0]
        ub = u0 - self.p2(ub)[..., 0]
        w = u0 - ub - self.p2(ub)[..., 0]
        N = int(round(T / h))
        for j in range(N):
            ub, w = rk_step(self.rhs, j * h, h, ub, w, 2)
        th = N * h / self.eps
        return flow(ub + self.g.interp(self.p2(ub), th) + w, th)[:, 0]


# ----------------------------------------------------------------------------------------------
# NPI1 for the general class (filtered y = e^{-A t/eps} u, field frozen at y_n, fast tau exact)
# ----------------------------------------------------------------------------------------------


def npi1_general(eps, h, T=1.0, ntau=32):
    g = Grid(ntau)
    y = U0.copy()
    N = int(round(T / h))
    for j in range(N):
        t = j * h
        fg = ftau(y[:, None], g.tau)
        a = g.A(fg)
        y = y + h * g.mean(fg) + eps * (g.interp(a, (t + h) / eps) - g.interp(a, t / eps))
    return flow(y, N * h / eps)


def part_a0():
    """defect delta = f o Phi - (1/eps) d_theta Phi - d_u Phi F at v = u0 (sup over the tau grid):
    it must be O(eps^n); it is the forcing of w, so w = O(eps^(n+1)), d^k w/dt^k = O(eps^(n+1-k))"""
    print("Part A0: Henon-Heiles, sup_theta |defect| at v = u0 (N_tau = 32); ratios per eps / 10")
    rows = {}
    for e in [0.1, 0.01, 0.001]:
        v = U0[:, None]
        s = Strobo(e, 1)
        P, dth, dPF, F = s.parts(v)
        d1 = np.abs(ftau(P, s.g.tau) - dth - dPF).max()
        s = Strobo(e, 2)
        P, dth, dPF, F = s.parts(v)
        d2 = np.abs(ftau(P, s.g.tau) - dth - dPF).max()
        c = CCLM(e)
        F, mG, iG = c.fields(U0, np.zeros(D))
        dc = np.abs(mG[:, None] + np.fft.ifft(np.fft.fft(iG, axis=-1) * 1j * c.g.k
                                              * (c.g.k != c.g.n // 2), axis=-1).real).max()
        df = DF2(e)
        p = df.p2(v)
        G = df.g.mean(ftau(v[..., None] + p, df.g.tau))
        dpG = (df.p2(v + 1e-5 * G) - df.p2(v - 1e-5 * G)) / 2e-5
        dthp = np.fft.ifft(np.fft.fft(p, axis=-1) * 1j * df.g.k * (df.g.k != df.g.n // 2), axis=-1).real / e
        ddf = np.abs(ftau(v[..., None] + p, df.g.tau) - dthp - (G[..., None] + dpG)).max()
        rows[e] = (d1, d2, dc, ddf)
    print("    eps      strobo n=1  strobo n=2  CCLM C1     DF n=2 (standard)")
    prev = None
    for e, r in rows.items():
        print(f"    {e:<8g}" + "".join(f"  {x:10.2e}" for x in r)
              + ("" if prev is None else "   ratios " + " ".join(f"{a / b:6.1f}" for a, b in zip(prev, r))))
        prev = r


def part_a():
    print("Part A: Henon-Heiles, T = 1, relative error |u_N - u(1)| / |u(1)|, N_tau = 32")
    epss = [1.0, 0.1, 0.03, 0.01, 1e-3]
    hs = [1 / 4, 1 / 8, 1 / 16, 1 / 32]
    refs = {}
    t0 = time.process_time()
    for e in epss:
        refs[e] = reference(e)
    print(f"  (references: {time.process_time() - t0:.1f} s CPU)")
    schemes = [
        ("MM1-RK2", lambda e, h: Strobo(e, 1).solve(h)),
        ("MM2-RK2", lambda e, h: Strobo(e, 2).solve(h)),
        ("MM1-RK4", lambda e, h: Strobo(e, 1).solve(h, rk=4)),
        ("MM2-RK4", lambda e, h: Strobo(e, 2).solve(h, rk=4)),
        ("CCLM-MP", lambda e, h: CCLM(e).solve(h)),
        ("DF2-RK2", lambda e, h: DF2(e).solve(h)),
        ("DF2*-RK2", lambda e, h: DF2(e, micro="eps^n").solve(h)),
        ("NPI1", lambda e, h: npi1_general(e, h)),
    ]
    for name, run in schemes:
        t0 = time.process_time()
        print(f"  {name:8s} " + "".join(f"   h=1/{int(round(1 / h)):<3d}" for h in hs) + "   orders")
        for e in epss:
            ref = refs[e]
            errs = [np.linalg.norm(run(e, h) - ref) / np.linalg.norm(ref) for h in hs]
            orders = [np.log2(errs[i] / errs[i + 1]) for i in range(len(hs) - 1)]
            print(f"    eps={e:<7g}" + "".join(f"  {x:9.2e}" for x in errs) + "   "
                  + " ".join(f"{o:5.2f}" for o in orders))
        print(f"    ({time.process_time() - t0:.1f} s CPU)")


# ----------------------------------------------------------------------------------------------
# Part B: MicroMacro.jl src/ (schema 2) for complex KG, CosSin data
# ----------------------------------------------------------------------------------------------

NX = 128
XK = np.fft.fftfreq(NX, 1.0 / NX)
FILES = {1.0: "1", 0.1: "0_1", 0.01: "0_01", 0.001: "0_001", 1e-4: "0_0001", 1e-5: "0_00001",
         1e-6: "0_000001"}


def kg_data(eps):
    x = 2 * np.pi * np.arange(NX) / NX
    phi, gam = (1 + 1j) * np.cos(x), (1 - 1j) * np.sin(x)
    A2 = (1 + eps * XK**2) ** -0.5
    u = phi - 1j * np.fft.ifft(A2 * np.fft.fft(gam))
    v = np.conj(phi) - 1j * np.fft.ifft(A2 * np.fft.fft(np.conj(gam)))
    return u, v


def kg_ref(eps):
    here = __file__.rsplit("/", 1)[0]
    r = np.loadtxt(f"{here}/micromacro-cos-sin/donnee_{FILES[eps]}.txt")
    return r[:, 0] + 1j * r[:, 1], r[:, 2] + 1j * r[:, 3]


class KGMicMac:
    """fields of MicroMacro.jl src/ftau.jl, duftau.jl, dtftau.jl, C1.jl, champs_2.jl, init_2.jl"""

    def __init__(self, eps, ntau=32, llambda=-1.0):
        self.eps, self.nt, self.lam = eps, ntau, llambda
        self.tau = 2 * np.pi * np.arange(ntau) / ntau
        kt = np.fft.fftfreq(ntau, 1.0 / ntau)
        self.kt = kt.copy()
        kt[0] = 1.0
        self.ktau = kt  # as in micmac.jl: ktau[1] = 1, Nyquist kept as -N/2
        self.A1 = (np.sqrt(1 + eps * XK**2) - 1) / eps
        self.A2 = (1 + eps * XK**2) ** -0.5
        self.e = np.exp(1j * self.tau)[:, None]

    def _z(self, t, U, V):  # U, V: x-Fourier, shape (nx,) or (ntau, nx)
        ph = np.exp(1j * t * self.A1)
        return (self.e * np.fft.ifft(ph * U, axis=-1) + np.conj(self.e * np.fft.ifft(ph * V, axis=-1))) / 2

    def _out(self, t, g):  # -i lambda A2 e^{-i t A1} FFT_x(e^{-i tau} g), and the same for conj(g)
        m = -1j * self.lam * self.A2 * np.exp(-1j * t * self.A1)
        ec = np.conj(self.e)
        return m * np.fft.fft(ec * g, axis=-1), m * np.fft.fft(ec * np.conj(g), axis=-1)

    def ftau(self, t, U, V):
        z = self._z(t, U, V)
        return self._out(t, np.abs(z) ** 2 * z)

    def duftau(self, t, U, V, dU, dV):
        z, dz = self._z(t, U, V), self._z(t, dU, dV)
        return self._out(t, 2 * np.abs(z) ** 2 * dz + z**2 * np.conj(dz))

    def dtftau(self, t, U, V):
        ia = 1j * self.A1
        z = self._z(t, U, V)
        a = self.duftau(t, U, V, ia * U, ia * V)
        b = self._out(t, np.abs(z) ** 2 * z)
        return a[0] - ia * b[0], a[1] - ia * b[1]

    def mean(self, g):
        return g.mean(axis=0)

    def A(self, g):  # (d/dtau)^{-1}(I - Pi) as in the code: mode 0 zeroed, divided by i*ktau
        c = np.fft.fft(g, axis=0)
        c[0] = 0
        return np.fft.ifft(c / (1j * self.ktau[:, None]), axis=0)

    def reconstr(self, g, s):  # micmac.jl reconstr(): includes the -N/2 mode
        c = np.fft.fft(g, axis=0)
        return (c * np.exp(1j * self.kt * s)[:, None]).sum(axis=0) / self.nt

    def C1(self, t, U, V):
        fu, fv = self.ftau(t, U, V)
        return U + self.eps * self.A(fu), V + self.eps * self.A(fv)

    def champs2(self, t, U, V, WU, WV):
        eps = self.eps
        fu, fv = self.ftau(t, U, V)
        dtau_u, dtau_v = fu - self.mean(fu), fv - self.mean(fv)
        C1u, C1v = U + eps * self.A(fu), V + eps * self.A(fv)
        ffu, ffv = self.ftau(t, C1u + WU, C1v + WV)
        gu, gv = self.ftau(t, C1u, C1v)
        Fu, Fv = self.mean(gu), self.mean(gv)
        a = self.duftau(t, U, V, Fu, Fv)
        b = self.dtftau(t, U, V)
        dtC1u = Fu + eps * self.A(a[0] + b[0])
        dtC1v = Fv + eps * self.A(a[1] + b[1])
        Gu, Gv = ffu - dtau_u - dtC1u, ffv - dtau_v - dtC1v
        return Fu, Fv, self.mean(Gu), self.mean(Gv), self.A(Gu), self.A(Gv)

    def solve(self, dt, Tf=0.25):
        eps = self.eps
        u, v = kg_data(eps)
        U0, V0 = np.fft.fft(u), np.fft.fft(v)
        fu, fv = self.ftau(0.0, U0, V0)
        Ub, Vb = U0 - eps * self.A(fu)[0], V0 - eps * self.A(fv)[0]
        c = self.C1(0.0, Ub, Vb)
        WU, WV = U0 - c[0][0], V0 - c[1][0]
        N = int(round(Tf / dt))
        R = self.reconstr
        for j in range(N):
            t = j * dt
            Fu, Fv, mu, mv, iu, iv = self.champs2(t, Ub, Vb, WU, WV)
            Ub2, Vb2 = Ub + dt / 2 * Fu, Vb + dt / 2 * Fv
            WU2 = WU + dt / 2 * mu + eps * (R(iu, (t + dt / 2) / eps) - R(iu, t / eps))
            WV2 = WV + dt / 2 * mv + eps * (R(iv, (t + dt / 2) / eps) - R(iv, t / eps))
            Fu, Fv, mu, mv, iu, iv = self.champs2(t + dt / 2, Ub2, Vb2, WU2, WV2)
            Ub, Vb = Ub + dt * Fu, Vb + dt * Fv
            WU = WU + dt * mu + eps * (R(iu, (t + dt) / eps) - R(iu, t / eps))
            WV = WV + dt * mv + eps * (R(iv, (t + dt) / eps) - R(iv, t / eps))
        t = N * dt
        c = self.C1(t, Ub, Vb)
        Uf = R(c[0], t / eps) + WU
        Vf = R(c[1], t / eps) + WV
        ph = np.exp(1j * np.sqrt(1 + eps * XK**2) * t / eps)
        return np.fft.ifft(ph * Uf), np.fft.ifft(ph * Vf)


def rel(u, v, ur, vr):
    return np.sqrt(np.sum(abs(u - ur) ** 2 + abs(v - vr) ** 2) / np.sum(abs(ur) ** 2 + abs(vr) ** 2))


def part_b():
    print("Part B: MicroMacro.jl src/ scheme (C1 + midpoint), KG CosSin, N_x = 128, N_tau = 32, T = 0.25;"
          " relative L2 error of (u, v) vs micromacro-cos-sin/")
    dts = [0.25 / 16, 0.25 / 32, 0.25 / 64]
    t0 = time.process_time()
    print("    eps      " + "".join(f"  dt=T/{int(round(0.25 / d)):<4d}" for d in dts) + "  orders")
    for e in [1.0, 0.1, 0.01, 1e-3, 1e-6]:
        ur, vr = kg_ref(e)
        errs = [rel(*KGMicMac(e).solve(d), ur, vr) for d in dts]
        o = [np.log2(errs[i] / errs[i + 1]) for i in range(len(dts) - 1)]
        print(f"    {e:<8g}" + "".join(f"  {x:10.2e}" for x in errs) + "  " + " ".join(f"{x:5.2f}" for x in o))
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


# ----------------------------------------------------------------------------------------------
# Part C: Cai-Zhou NPI1 (newnpi1.m) on the same problem.  Bao's e^2 = eps; lambda_Bao = -1.
# ----------------------------------------------------------------------------------------------


def npi1_kg(eps, tau, Tf=0.25, lam=-1.0):
    beta = np.sqrt(1 + eps * XK**2) / eps  # D_eps on mode l (e^2 = eps)
    A = 1j * lam / (2 * eps * beta)  # i lambda / (2 e^2 D_eps)
    u, v = kg_data(eps)
    up, um = np.fft.fft(np.conj(v)) / 2, np.fft.fft(u) / 2  # psi_+ = conj(v)/2, psi_- = u/2
    s = tau
    em = np.exp(-1j * s / eps)

    def pk(k):  # e^{-is/e^2} int_0^s e^{ikw/e^2} dw
        return em * (np.exp(1j * k * s / eps) - 1) / (1j * k / eps)

    p0, p2, pm2, p4 = s * em, pk(2), pk(-2), pk(4)
    N = int(round(Tf / tau))
    for _ in range(N):
        a, b = np.fft.ifft(up), np.fft.ifft(um)
        F1p = A * np.fft.fft(a**2 * np.conj(b))
        F1m = A * np.fft.fft(b**2 * np.conj(a))
        F2p = A * np.fft.fft((2 * abs(b) ** 2 + abs(a) ** 2) * a)
        F2m = A * np.fft.fft((2 * abs(a) ** 2 + abs(b) ** 2) * b)
        dp = p0 * F2p + p2 * F2m + pm2 * F1p + p4 * F1m
        dm = -np.conj(p0) * F2m - np.conj(p2) * F2p - np.conj(pm2) * F1m - np.conj(p4) * F1p
        up, um = np.exp(-1j * tau * beta) * up + dp, np.exp(1j * tau * beta) * um + dm
    return 2 * np.fft.ifft(um), 2 * np.conj(np.fft.ifft(up))  # (u, v)


def part_c():
    print("Part C: Cai-Zhou NPI1 (newnpi1.m formulas), same KG problem and references, relative L2 of (u, v)")
    taus = [0.25 / 4, 0.25 / 8, 0.25 / 16, 0.25 / 32, 0.25 / 64]
    t0 = time.process_time()
    print("    eps      " + "".join(f"  tau=T/{int(round(0.25 / d)):<3d}" for d in taus) + "  orders")
    for e in [1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-6]:
        ur, vr = kg_ref(e)
        errs = [rel(*npi1_kg(e, d), ur, vr) for d in taus]
        o = [np.log2(errs[i] / errs[i + 1]) for i in range(len(taus) - 1)]
        print(f"    {e:<8g}" + "".join(f"  {x:9.2e}" for x in errs) + "  " + " ".join(f"{x:5.2f}" for x in o))
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


if __name__ == "__main__":
    import sys

    parts = sys.argv[1:] or ["a0", "a", "b", "c"]
    if "a0" in parts:
        part_a0()
    if "a" in parts:
        part_a()
    if "b" in parts:
        part_b()
    if "c" in parts:
        part_c()
