#!/usr/bin/python3
"""Nested Picard integrators (NPI) of Cai & Zhou for the cubic Klein-Gordon equation, orders 1-3,
prototype for npi-higher.md (numpy only; scipy for one quadrature check; sympy only with --closed-forms).
Run with /usr/bin/python3.  Independent of tsi.

Problem (Bao scaling, paper (1.1)):  e^2 psi_tt - psi_xx + psi/e^2 = lambda |psi|^2 psi on [0, 2 pi),
E := e^2 = eps of MicroMacro.jl, lambda = -1, CosSin data of MicroMacro.jl, N_x = 128, T = 0.25; the
twisted variables psi_- = u/2, psi_+ = conj(v)/2 (u, v: MicroMacro.jl's unknowns; micro-macro.md 5.2).
Error: relative discrete L2 of (u, v) against micromacro-cos-sin/donnee_*.txt.

What is here:
  PP            exact algebra of "phase polynomials"  g(s) = sum c_{m,p} s^p e^{i m s/E}:  +, *, conj,
                int_0^s, the Duhamel kernel; every NPI coefficient integral is such a g evaluated at s = tau.
  code_coeffs   the coefficient definitions of symbolNPI_complex.m (p, p1, p2, q, q1..q4, r, m1..m3) as PPs
                (closed forms; checked against scipy quadrature of the definitions).
  NPI           the k-th order NPI of paper (2.21)-(2.23) for any k, written with PPs (the generic recipe of
                npi-higher.md section 2).
  newnpi2_step, newnpi3_step
                machine translations of the loop bodies of newnpi2.m / newnpi3.m (the explicit second- and
                third-order formulas, npi-higher.md sections 3-4); newnpi3.m line 309 has a typo (FIX309).
Checks printed: coefficient closed forms vs quadrature; one step of the ports vs the generic recipe;
order 1 vs micro_macro_prototype.py Part C; error tables for orders 1, 2, 3; the port of newnpi3.m as
published vs with line 309 fixed; accuracy of the references.
"""
import math
import sys
import time

import numpy as np

from micro_macro_prototype import FILES, XK, kg_data, kg_ref, npi1_kg, rel

TF = 0.25
LAM = -1.0


# ----------------------------------------------------------------------------------------------
# Phase polynomials g(s) = sum_{(m,p)} c_{m,p} s^p exp(i m s / E);  m, p integers.
# ----------------------------------------------------------------------------------------------
class FloatField:
    def __init__(self, E):
        self.E = E

    def inv_ia(self, m):  # 1 / (i m / E)
        return -1j * self.E / m

    def conj(self, c):
        return np.conj(c)

    def rat(self, a, b):
        return a / b


class SymField:  # exact coefficients (sympy), for --closed-forms
    def __init__(self):
        import sympy

        self.sp = sympy
        self.E = sympy.Symbol("E", positive=True)

    def inv_ia(self, m):
        return -self.sp.I * self.E / m

    def conj(self, c):
        return self.sp.conjugate(c)

    def rat(self, a, b):
        return self.sp.Rational(a, b)


class PP:
    """phase polynomial  g(s) = sum_{(m,p)} c_{m,p} s^p exp(i m s / E),  m, p integers"""

    def __init__(self, F, t=None):
        self.F = F
        self.t = dict(t) if t else {}

    @classmethod
    def mono(cls, F, m, p, c=1):
        return cls(F, {(m, p): c})

    def __add__(self, o):
        t = dict(self.t)
        for k, c in o.t.items():
            t[k] = t.get(k, 0) + c
        return PP(self.F, t)

    def __neg__(self):
        return PP(self.F, {k: -c for k, c in self.t.items()})

    def __sub__(self, o):
        return self + (-o)

    def __mul__(self, o):
        if isinstance(o, PP):
            t = {}
            for (m1, p1), c1 in self.t.items():
                for (m2, p2), c2 in o.t.items():
                    k = (m1 + m2, p1 + p2)
                    t[k] = t.get(k, 0) + c1 * c2
            return PP(self.F, t)
        return PP(self.F, {k: c * o for k, c in self.t.items()})

    __rmul__ = __mul__

    def conj(self):  # s real
        return PP(self.F, {(-m, p): self.F.conj(c) for (m, p), c in self.t.items()})

    def shift(self, m0):  # * exp(i m0 s / E)
        return PP(self.F, {(m + m0, p): c for (m, p), c in self.t.items()})

    def spow(self, p0):  # * s^p0
        return PP(self.F, {(m, p + p0): c for (m, p), c in self.t.items()})

    def integ(self):  # int_0^s g(w) dw
        t = {}
        for (m, p), c in self.t.items():
            if m == 0:
                t[(0, p + 1)] = t.get((0, p + 1), 0) + c * self.F.rat(1, p + 1)
                continue
            ia_inv = self.F.inv_ia(m)
            # int_0^s w^p e^{iaw} dw = sum_r (-1)^{p-r} p!/r! s^r e^{ias} /(ia)^{p-r+1} - (-1)^p p!/(ia)^{p+1}
            for r in range(p + 1):
                k = (m, r)
                t[k] = t.get(k, 0) + c * (-1) ** (p - r) * (math.factorial(p) // math.factorial(r)) * ia_inv ** (p - r + 1)
            t[(0, 0)] = t.get((0, 0), 0) - c * (-1) ** p * math.factorial(p) * ia_inv ** (p + 1)
        return PP(self.F, t)

    def conv(self, sigma=1):  # e^{-sigma i s/E} int_0^s e^{sigma i w/E} g(w) dw
        return self.shift(sigma).integ().shift(-sigma)

    def __call__(self, s):
        E = self.F.E
        return sum(c * s**p * np.exp(1j * m * s / E) for (m, p), c in self.t.items())


# ----------------------------------------------------------------------------------------------
# The coefficient integrals of symbolNPI_complex.m (MATLAB index k -> Python index k-1), as PPs in s.
# Code naming: p{1..4} = p_0, p_2, p_-2, p_4 (lines 14-17); p1 = p_{.,1} (24-27); p2 = p_{.,2} (55-58);
# conv(g)(s) = int_0^s e^{-i(s-w)/E} g(w) dw.
# ----------------------------------------------------------------------------------------------
def code_coeffs(F):
    M = lambda m, p: PP.mono(F, m, p)
    c = lambda g: g.conj()
    p = [M(k, 0).integ().shift(-1) for k in (0, 2, -2, 4)]  # e^{-is/E} int_0^s e^{ikw/E} dw
    p1 = [M(k, 1).integ().shift(-1) for k in (0, 2, -2, 4)]  # e^{-is/E} int_0^s w e^{ikw/E} dw
    p2 = [M(k, 2).integ().shift(-1) for k in (0, 2, -2, 4)]  # e^{-is/E} int_0^s w^2 e^{ikw/E} dw
    w = M(0, 1)

    def qfam(a1p, a1m, a2p, a2m):
        # rows (MATLAB j): 1, 2: conv(a); 3, 4: conv(e^{+2iw/E} a) for '+', conv(e^{-2iw/E} a) for '-';
        # 5, 6: conv(e^{-2iw/E} a) for '+', conv(e^{+2iw/E} a) for '-'.  Odd rows use a1, even rows a2.
        return [[a1p.conv(), a1m.conv()], [a2p.conv(), a2m.conv()],
                [a1p.shift(2).conv(), a1m.shift(-2).conv()], [a2p.shift(2).conv(), a2m.shift(-2).conv()],
                [a1p.shift(-2).conv(), a1m.shift(2).conv()], [a2p.shift(-2).conv(), a2m.shift(2).conv()]]

    P0, P2, Pm2, P4 = p
    Q0, Q2, Qm2, Q4 = p1
    q = qfam(-c(Pm2) + P4, -c(P4) + Pm2, -c(P0) + P2, -c(P2) + P0)  # lines 32-45
    q1 = qfam((-c(Pm2) + P4) * w, (-c(P4) + Pm2) * w, (-c(P0) + P2) * w, (-c(P2) + P0) * w)  # 64-77
    q2 = qfam(c(Qm2) + Q4, c(Q4) + Qm2, c(Q0) + Q2, c(Q2) + Q0)  # 79-92
    q3 = qfam((-c(Pm2) - P4) * w, (-c(P4) - Pm2) * w, (-c(P0) - P2) * w, (-c(P2) - P0) * w)  # 94-107
    q4 = qfam(-c(Qm2) + Q4, -c(Q4) + Qm2, -c(Q0) + Q2, -c(Q2) + Q0)  # 110-123
    # r (135-173): a = p3 - conj(p4), b = -conj(p3) + p4, cc = p1 - conj(p2), d = -conj(p1) + p2;
    # r{J,k} = e^{-is/E} int_0^s X_k(w) dw (J = 1..4),  r{J+4,k} = e^{-is/E} int_0^s e^{2iw/E} X_k(w) dw,
    # X_1..4 = x1 y1, x1 y2, x2 y1, x2 y2 with (x1, x2), (y1, y2) = (a,b),(a,b) | (a,b),(cc,d) | (cc,d),(a,b) | (cc,d),(cc,d)
    a, b = Pm2 - c(P4), -c(Pm2) + P4
    cc, d = P0 - c(P2), -c(P0) + P2
    firsts = [(a, b), (a, b), (cc, d), (cc, d)]
    seconds = [(a, b), (cc, d), (a, b), (cc, d)]
    r = [[None] * 4 for _ in range(8)]
    for J in range(4):
        (x1, x2), (y1, y2) = firsts[J], seconds[J]
        for kk, X in enumerate([x1 * y1, x1 * y2, x2 * y1, x2 * y2]):
            r[J][kk] = X.integ().shift(-1)
            r[J + 4][kk] = X.shift(2).integ().shift(-1)
    m1, m2, m3 = [], [], []
    for k in range(6):  # lines 180-187
        hp, hm = q[k][0] + c(q[k][1]), c(q[k][0]) + q[k][1]
        m1.append([hp.conv(), hm.conv()])
        m2.append([hp.shift(2).conv(), hm.shift(-2).conv()])
        m3.append([hp.shift(-2).conv(), hm.shift(2).conv()])
    return dict(p=p, p1=p1, p2=p2, q=q, q1=q1, q2=q2, q3=q3, q4=q4, r=r, m1=m1, m2=m2, m3=m3)


def coeff_tables(E, tau):
    """the numbers ps, p1s, ..., m3s that newnpi2.m / newnpi3.m load (lines 89-117), at s = tau"""
    C = code_coeffs(FloatField(E))
    out = {}
    for k, v in C.items():
        if isinstance(v[0], list):
            out[k + "s"] = np.array([[g(tau) for g in row] for row in v])
        else:
            out[k + "s"] = np.array([g(tau) for g in v])
    return out


# ----------------------------------------------------------------------------------------------
# Generic k-th order NPI, paper (2.21)-(2.23):
#   psi^{(0)}(w) = e^{-iw/E} psi_+ + e^{iw/E} psi_-
#   psi^{(j)}(w) = delta_+^j(w) + delta_-^j(w) + e^{-iw/E} (-w B)^j/j! psi_+ + e^{iw/E} (w B)^j/j! psi_-
#   delta_sig^k(s) = sig A sum_{j=0}^{k-1} (-sig B)^j/j! int_0^s e^{-sig i(s-w)/E} (s-w)^j N_{k-1-j}(w) dw
#   N_r = sum_{j1+j2+j3=r} psi^{(j1)} psi^{(j2)} conj(psi^{(j3)}),  A = i lambda/(2 E D_E), B = i sin(tau D)/tau
#   psi_sig^{n+1} = e^{-sig i tau D_E} psi_sig^n + sum_{k=1}^{K} delta_sig^k(tau)
# Every psi^{(j)} and delta^k is kept as {(m, p): vector}, meaning sum_{m,p} w^p e^{imw/E} vector.
# ----------------------------------------------------------------------------------------------
class NPI:
    def __init__(self, E, tau, mu, lam, order):
        self.E, self.tau, self.K = E, tau, order
        self.F = FloatField(E)
        De = np.sqrt(1 + E * mu**2) / E
        self.De = De
        self.A = 1j * lam / (2 * E * De)
        self.B = 1j * np.sin(tau * (De - 1 / E)) / tau
        self.ph = {1: np.exp(-1j * tau * De), -1: np.exp(1j * tau * De)}
        self._K = {}

    def kern(self, sigma, j, m, p):
        """int_0^s e^{-sigma i(s-w)/E} (s-w)^j w^p e^{imw/E} dw as a PP in s"""
        key = (sigma, j, m, p)
        if key not in self._K:
            F = self.F
            g = PP(F)
            for l in range(j + 1):
                g = g + (math.comb(j, l) * (-1) ** l) * PP.mono(F, m, p + l).conv(sigma).spow(j - l)
            self._K[key] = g
        return self._K[key]

    @staticmethod
    def dprod(D1, D2):
        out = {}
        for (m1, p1), v1 in D1.items():
            for (m2, p2), v2 in D2.items():
                k = (m1 + m2, p1 + p2)
                if k in out:
                    out[k] = out[k] + v1 * v2
                else:
                    out[k] = v1 * v2
        return out

    @staticmethod
    def dadd(D, D2):
        for k, v in D2.items():
            D[k] = D[k] + v if k in D else v
        return D

    def deltas(self, up, um):
        """returns list over k=1..K of (dict_plus, dict_minus): delta_{+/-}^{n,k}(s) = sum c s^p e^{ims/E} vec"""
        K, B, A, tau = self.K, self.B, self.A, self.tau
        ifft, fft = np.fft.ifft, np.fft.fft
        P = [{(-1, 0): ifft(up), (1, 0): ifft(um)}]  # psi^{(0)}(w) in physical space
        Pc = [{(-m, p): np.conj(v) for (m, p), v in P[0].items()}]
        S = []
        N = []
        out = []
        for k in range(1, K + 1):
            r = k - 1
            # S_r = sum_{j1+j2=r} P[j1] P[j2];  N_r = sum_{j3} S_{r-j3} conj(P[j3])
            Sr = {}
            for j1 in range(r + 1):
                self.dadd(Sr, self.dprod(P[j1], P[r - j1]))
            S.append(Sr)
            Nr = {}
            for j3 in range(r + 1):
                self.dadd(Nr, self.dprod(S[r - j3], Pc[j3]))
            N.append({key: fft(v) for key, v in Nr.items()})
            dp, dm = {}, {}
            for sigma, D in ((1, dp), (-1, dm)):
                for j in range(k):
                    op = sigma * A * (-sigma * B) ** j / math.factorial(j)
                    for (m, p), Fv in N[k - 1 - j].items():
                        g = self.kern(sigma, j, m, p)
                        w = op * Fv
                        for key, c in g.t.items():
                            if key in D:
                                D[key] = D[key] + c * w
                            else:
                                D[key] = c * w
            out.append((dp, dm))
            if k < K:
                Pk = {}
                for key in set(dp) | set(dm):
                    v = dp.get(key, 0) + dm.get(key, 0)
                    Pk[key] = ifft(v)
                lin = {(-1, k): ifft((-B) ** k / math.factorial(k) * up),
                       (1, k): ifft(B**k / math.factorial(k) * um)}
                self.dadd(Pk, lin)
                P.append(Pk)
                Pc.append({(-m, p): np.conj(v) for (m, p), v in Pk.items()})
        return out

    def evald(self, D, s):
        E = self.E
        tot = 0
        for (m, p), v in D.items():
            tot = tot + (s**p * np.exp(1j * m * s / E)) * v
        return tot

    def step(self, up, um):
        ds = self.deltas(up, um)
        nup, num = self.ph[1] * up, self.ph[-1] * um
        for dp, dm in ds:
            nup = nup + self.evald(dp, self.tau)
            num = num + self.evald(dm, self.tau)
        return nup, num


# ----------------------------------------------------------------------------------------------
# Explicit formulas of the MATLAB code: newnpi2.m / newnpi3.m loop bodies, machine-translated
# (.* -> *, .^ -> **, 1i -> 1j, x(k) -> x[k-1], '...' joined; names kept).  up, um: Fourier
# coefficients of psi_+, psi_- (MATLAB fft convention = numpy's); A, B, betal = D_E: multipliers.
# ----------------------------------------------------------------------------------------------
def newnpi2_step(up, um, A, B, tau, betal, C):
    """newnpi2.m lines 99-154, machine-translated (MATLAB -> numpy), loop body of one step"""
    ps, p1s, p2s = C["ps"], C["p1s"], C["p2s"]
    qs, q1s, q2s, q3s, q4s = C["qs"], C["q1s"], C["q2s"], C["q3s"], C["q4s"]
    rs, m1s, m2s, m3s = C["rs"], C["m1s"], C["m2s"], C["m3s"]
    fft, ifft, conj, abs_, exp = np.fft.fft, np.fft.ifft, np.conj, np.abs, np.exp
    ups = ifft(up)
    ums = ifft(um)
    ups1 = ifft(B*up)
    ums1 = ifft(B*um)
    F_1p = ifft(A*fft(ups**2*conj(ums)))
    F_1m = ifft(A*fft(ums**2*conj(ups)))
    F_2p = ifft(A*fft((2*abs_(ums)**2+abs_(ups)**2)*ups))
    F_2m = ifft(A*fft((2*abs_(ups)**2+abs_(ums)**2)*ums))
    G_1p = A*fft(ifft(B*fft(ups**2*conj(ums))) )
    G_1m = A*fft(ifft(B*fft(ums**2*conj(ups))) )
    G_2p = A*fft( ifft(B*fft( (2*abs_(ums)**2+ abs_(ups)**2)*ups)) )
    G_2m = A*fft( ifft(B*fft( (2*abs_(ups)**2+ abs_(ums)**2)*ums)))
    G_3p = A*fft( ups**2*conj(ums1)- 2*ups1*ups*conj(ums) )
    G_3m = -A*fft( ums**2*conj(ups1)- 2*ums1*ums*conj(ups) )
    G_4p = (
        A*fft( 2*ups*conj(ums)*ums1- 2*( abs_(ups)**2+ abs_(ums)**2)*ups1- ups**2*conj(ups1)+
        2*ups*ums*conj(ums1) )
    )
    G_4m = (
        -A*fft( 2*ums*conj(ups)*ups1- 2*( abs_(ums)**2+ abs_(ups)**2)*ums1- ums**2*conj(ums1)+
        2*ums*ups*conj(ups1) )
    )
    F_21p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_1m- 2*ups*ums*conj(F_1p))
    F_21m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_1p- 2*ups*ums*conj(F_1m))
    F_22p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_2m- 2*ups*ums*conj(F_2p))
    F_22m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_2p- 2*ups*ums*conj(F_2m))
    F_23p = A*fft( 2*ums*conj(ups)*F_1m- ums**2*conj(F_1p))
    F_23m = A*fft( 2*ups*conj(ums)*F_1p- ups**2*conj(F_1m))
    F_24p = A*fft( 2*ums*conj(ups)*F_2m- ums**2*conj(F_2p))
    F_24m = A*fft( 2*ups*conj(ums)*F_2p- ups**2*conj(F_2m))
    F_25p = A*fft( 2*ups*conj(ums)*F_1m- ups**2*conj(F_1p))
    F_25m = A*fft( 2*ums*conj(ups)*F_1p- ums**2*conj(F_1m))
    F_26p = A*fft( 2*ups*conj(ums)*F_2m- ups**2*conj(F_2p))
    F_26m = A*fft( 2*ums*conj(ups)*F_2p- ums**2*conj(F_2m))
    delta_n1p = ps[0]*F_2p + ps[1]*F_2m+ ps[2]*F_1p + ps[3]*F_1m
    delta_n1m = -conj(ps[0])*F_2m + -conj(ps[1])*F_2p+ -conj(ps[2])*F_1m + -conj(ps[3])*F_1p
    delta_n2p = (
        p1s[0]*(G_2p+G_4p) + p1s[1]*(G_2m+G_4m)+ p1s[2]*(G_1p+ G_3p) + p1s[3]*(G_1m+G_3m)
        -tau*ps[0]*B*fft(F_2p) - tau*ps[1]*B*fft(F_2m)- tau*ps[2]*B*fft(F_1p) - tau*ps[3]*B*fft(F_1m)+
        qs[0,0]*F_21p+ qs[0,1]*F_21m +qs[1,0]*F_22p+ qs[1,1]*F_22m +qs[2,0]*F_23p+ qs[2,1]*F_23m+
        qs[3,0]*F_24p+ qs[3,1]*F_24m +qs[4,0]*F_25p+ qs[4,1]*F_25m +qs[5,0]*F_26p+ qs[5,1]*F_26m
    )
    delta_n2m = (
        conj(p1s[0])*(G_2m-G_4m) + conj(p1s[1])*(G_2p- G_4p)+ conj(p1s[2])*(G_1m- G_3m) +
        conj(p1s[3])*(G_1p-G_3p) -tau*conj(ps[0])*B*fft(F_2m) - tau*conj(ps[1])*B*fft(F_2p)-
        tau*conj(ps[2])*B*fft(F_1m) - tau*conj(ps[3])*B*fft(F_1p)+ conj(qs[0,0])*F_21m+
        conj(qs[0,1])*F_21p + conj(qs[1,0])*F_22m+ conj(qs[1,1])*F_22p + conj(qs[2,0])*F_23m+
        conj(qs[2,1])*F_23p+ conj(qs[3,0])*F_24m+ conj(qs[3,1])*F_24p + conj(qs[4,0])*F_25m+
        conj(qs[4,1])*F_25p + conj(qs[5,0])*F_26m+ conj(qs[5,1])*F_26p
    )
    ups = exp(-1j*tau*betal)*up+ fft(delta_n1p)+ delta_n2p
    ums = exp(1j*tau*betal)*um+ fft(delta_n1m)+ delta_n2m
    return ups, ums


def newnpi3_step(up, um, A, B, tau, betal, C, FIX309=True):
    """newnpi3.m lines 119-409, machine-translated (MATLAB -> numpy), loop body of one step.
    FIX309: line 309 reads F_26m where every sibling line has F_2kp; True uses F_26p"""
    ps, p1s, p2s = C["ps"], C["p1s"], C["p2s"]
    qs, q1s, q2s, q3s, q4s = C["qs"], C["q1s"], C["q2s"], C["q3s"], C["q4s"]
    rs, m1s, m2s, m3s = C["rs"], C["m1s"], C["m2s"], C["m3s"]
    fft, ifft, conj, abs_, exp = np.fft.fft, np.fft.ifft, np.conj, np.abs, np.exp
    ups = ifft(up)
    ums = ifft(um)
    ups1 = ifft(B*up)
    ums1 = ifft(B*um)
    ups2 = ifft(B**2*up)
    ums2 = ifft(B**2*um)
    F_1p = A*fft(ups**2*conj(ums))
    F_1m = A*fft(ums**2*conj(ups))
    F_2p = A*fft((2*abs_(ums)**2+abs_(ups)**2)*ups)
    F_2m = A*fft((2*abs_(ups)**2+abs_(ums)**2)*ums)
    delta_n1p = ps[0]*F_2p + ps[1]*F_2m+ ps[2]*F_1p + ps[3]*F_1m
    delta_n1m = -conj(ps[0])*F_2m + -conj(ps[1])*F_2p+ -conj(ps[2])*F_1m + -conj(ps[3])*F_1p
    F_1p = ifft(F_1p)
    F_1m = ifft(F_1m)
    F_2p = ifft(F_2p)
    F_2m = ifft(F_2m)
    G_1p = A*B*fft(ups**2*conj(ums))
    G_1m = A*B*fft(ums**2*conj(ups))
    G_2p = A*B*fft( (2*abs_(ums)**2+ abs_(ups)**2)*ups)
    G_2m = A*B*fft( (2*abs_(ups)**2+ abs_(ums)**2)*ums)
    G_3p = A*fft( ups**2*conj(ums1)- 2*ups1*ups*conj(ums) )
    G_3m = -A*fft( ums**2*conj(ups1)- 2*ums1*ums*conj(ups) )
    G_4p = (
        A*fft( 2*ups*conj(ums)*ums1- 2*( abs_(ups)**2+ abs_(ums)**2)*ups1- ups**2*conj(ups1)+
        2*ups*ums*conj(ums1) )
    )
    G_4m = (
        -A*fft( 2*ums*conj(ups)*ups1- 2*( abs_(ums)**2+ abs_(ups)**2)*ums1- ums**2*conj(ums1)+
        2*ums*ups*conj(ups1) )
    )
    F_21p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_1m- 2*ups*ums*conj(F_1p))
    F_21m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_1p- 2*ups*ums*conj(F_1m))
    F_22p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_2m- 2*ups*ums*conj(F_2p))
    F_22m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_2p- 2*ups*ums*conj(F_2m))
    F_23p = A*fft( 2*ums*conj(ups)*F_1m- ums**2*conj(F_1p))
    F_23m = A*fft( 2*ups*conj(ums)*F_1p- ups**2*conj(F_1m))
    F_24p = A*fft( 2*ums*conj(ups)*F_2m- ums**2*conj(F_2p))
    F_24m = A*fft( 2*ups*conj(ums)*F_2p- ups**2*conj(F_2m))
    F_25p = A*fft( 2*ups*conj(ums)*F_1m- ups**2*conj(F_1p))
    F_25m = A*fft( 2*ums*conj(ups)*F_1p- ums**2*conj(F_1m))
    F_26p = A*fft( 2*ups*conj(ums)*F_2m- ups**2*conj(F_2p))
    F_26m = A*fft( 2*ums*conj(ups)*F_2p- ums**2*conj(F_2m))
    delta_n2p = (
        p1s[0]*(G_2p+G_4p) + p1s[1]*(G_2m+G_4m)+ p1s[2]*(G_1p+ G_3p) + p1s[3]*(G_1m+G_3m)
        -tau*ps[0]*B*fft(F_2p) - tau*ps[1]*B*fft(F_2m)- tau*ps[2]*B*fft(F_1p) - tau*ps[3]*B*fft(F_1m)+
        qs[0,0]*F_21p+ qs[0,1]*F_21m +qs[1,0]*F_22p+ qs[1,1]*F_22m +qs[2,0]*F_23p+ qs[2,1]*F_23m+
        qs[3,0]*F_24p+ qs[3,1]*F_24m +qs[4,0]*F_25p+ qs[4,1]*F_25m +qs[5,0]*F_26p+ qs[5,1]*F_26m
    )
    delta_n2m = (
        conj(p1s[0])*(G_2m-G_4m) + conj(p1s[1])*(G_2p- G_4p)+ conj(p1s[2])*(G_1m- G_3m) +
        conj(p1s[3])*(G_1p-G_3p) -tau*conj(ps[0])*B*fft(F_2m) - tau*conj(ps[1])*B*fft(F_2p)-
        tau*conj(ps[2])*B*fft(F_1m) - tau*conj(ps[3])*B*fft(F_1p)+ conj(qs[0,0])*F_21m+
        conj(qs[0,1])*F_21p + conj(qs[1,0])*F_22m+ conj(qs[1,1])*F_22p + conj(qs[2,0])*F_23m+
        conj(qs[2,1])*F_23p+ conj(qs[3,0])*F_24m+ conj(qs[3,1])*F_24p + conj(qs[4,0])*F_25m+
        conj(qs[4,1])*F_25p + conj(qs[5,0])*F_26m+ conj(qs[5,1])*F_26p
    )
    G_1p = ifft(G_1p)
    G_1m = ifft(G_1m)
    G_2p = ifft(G_2p)
    G_2m = ifft(G_2m)
    G_3p = ifft(G_3p)
    G_3m = ifft(G_3m)
    G_4p = ifft(G_4p)
    G_4m = ifft(G_4m)
    F_21p = ifft(F_21p)
    F_21m = ifft(F_21m)
    F_22p = ifft(F_22p)
    F_22m = ifft(F_22m)
    F_23p = ifft(F_23p)
    F_23m = ifft(F_23m)
    F_24p = ifft(F_24p)
    F_24m = ifft(F_24m)
    F_25p = ifft(F_25p)
    F_25m = ifft(F_25m)
    F_26p = ifft(F_26p)
    F_26m = ifft(F_26m)
    G_13p = A*fft( 1/2*ups**2*conj(ums2)+ ups2*ups*conj(ums) )
    G_13m = A*fft( 1/2*ums**2*conj(ups2)+ ums2*ums*conj(ups) )
    G_23p = (
        A*fft( ups*conj(ums)*ums2 + (ups*conj(ups)+ums*conj(ums))*ups2 + 1/2*ups**2*conj(ups2)+
        conj(ums2)*ups*ums )
    )
    G_23m = (
        A*fft( ums*conj(ups)*ups2 + (ups*conj(ups)+ums*conj(ums))*ums2 + 1/2*ums**2*conj(ums2)+
        conj(ups2)*ums*ups )
    )
    E_1p = A*fft( -2*ups*ups1*conj(ums1) + conj(ums)*ups1**2 )
    E_1m = A*fft( -2*ums*ums1*conj(ups1) + conj(ups)*ums1**2 )
    E_2p = (
        A*fft( 2*ups*abs_(ums1)**2 +2*ups*abs_(ups1)**2 -2*ums*ups1*conj(ums1) -2*conj(ums)*ups1*ums1+
        conj(ups)*ups1**2 )
    )
    E_2m = (
        A*fft( 2*ums*abs_(ups1)**2 +2*ums*abs_(ums1)**2 -2*ups*ums1*conj(ups1) -2*conj(ups)*ums1*ups1+
        conj(ums)*ums1**2 )
    )
    F_31p = (
        A*fft( 2*(ums*conj(ums1)- ups*conj(ups1) -conj(ups)*ups1+ conj(ums)* ums1 )*F_1m- 2*(ups*ums1-
        ums*ups1)*conj(F_1p))
    )
    F_31m = (
        A*fft( 2*(ums*conj(ums1)- ups*conj(ups1) -conj(ups)*ups1+ conj(ums)* ums1 )*F_1p- 2*(ups*ums1-
        ums*ups1)*conj(F_1m))
    )
    F_32p = (
        A*fft( 2*(ums*conj(ums1)- ups*conj(ups1) -conj(ups)*ups1+ conj(ums)* ums1 )*F_2m- 2*(ups*ums1-
        ums*ups1)*conj(F_2p))
    )
    F_32m = (
        A*fft( 2*(ums*conj(ums1)- ups*conj(ups1) -conj(ups)*ups1+ conj(ums)* ums1 )*F_2p- 2*(ups*ums1-
        ums*ups1)*conj(F_2m))
    )
    F_33p = A*fft( 2*(-ums*conj(ups1)+ conj(ups)*ums1 )*F_1m- 2*(ums*ums1)*conj(F_1p))
    F_33m = A*fft( 2*(ups*conj(ums1)- conj(ums)*ups1 )*F_1p- 2*(-ups*ups1)*conj(F_1m))
    F_34p = A*fft( 2*(-ums*conj(ups1)+ conj(ups)*ums1 )*F_2m- 2*(ums*ums1)*conj(F_2p))
    F_34m = A*fft( 2*(ups*conj(ums1)- conj(ums)*ups1 )*F_2p- 2*(-ups*ups1)*conj(F_2m))
    F_35p = A*fft( 2*(ups*conj(ums1)- conj(ums)*ups1 )*F_1m- 2*(-ups*ups1)*conj(F_1p))
    F_35m = A*fft( 2*(-ums*conj(ups1)+ conj(ups)*ums1 )*F_1p- 2*(ums*ums1)*conj(F_1m))
    F_36p = A*fft( 2*(ups*conj(ums1)- conj(ums)*ups1 )*F_2m- 2*(-ups*ups1)*conj(F_2p))
    F_36m = A*fft( 2*(-ums*conj(ups1)+ conj(ups)*ums1 )*F_2p- 2*(ums*ums1)*conj(F_2m))
    F_41p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_1m+ 2*ups*ums*conj(G_1p))
    F_41m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_1p+ 2*ups*ums*conj(G_1m))
    F_42p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_2m+ 2*ups*ums*conj(G_2p))
    F_42m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_2p+ 2*ups*ums*conj(G_2m))
    F_43p = A*fft( 2*ums*conj(ups)*G_1m+ ums**2*conj(G_1p))
    F_43m = A*fft( 2*ups*conj(ums)*G_1p+ ups**2*conj(G_1m))
    F_44p = A*fft( 2*ums*conj(ups)*G_2m+ ums**2*conj(G_2p))
    F_44m = A*fft( 2*ups*conj(ums)*G_2p+ ups**2*conj(G_2m))
    F_45p = A*fft( 2*ups*conj(ums)*G_1m+ ups**2*conj(G_1p))
    F_45m = A*fft( 2*ums*conj(ups)*G_1p+ ums**2*conj(G_1m))
    F_46p = A*fft( 2*ups*conj(ums)*G_2m+ ups**2*conj(G_2p))
    F_46m = A*fft( 2*ums*conj(ups)*G_2p+ ums**2*conj(G_2m))
    F_47p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_3m- 2*ups*ums*conj(G_3p))
    F_47m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_3p- 2*ups*ums*conj(G_3m))
    F_48p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_4m- 2*ups*ums*conj(G_4p))
    F_48m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*G_4p- 2*ups*ums*conj(G_4m))
    F_49p = A*fft( 2*ums*conj(ups)*G_3m- ums**2*conj(G_3p))
    F_49m = A*fft( 2*ups*conj(ums)*G_3p- ups**2*conj(G_3m))
    F_410p = A*fft( 2*ums*conj(ups)*G_4m- ums**2*conj(G_4p))
    F_410m = A*fft( 2*ups*conj(ums)*G_4p- ups**2*conj(G_4m))
    F_411p = A*fft( 2*ups*conj(ums)*G_3m- ups**2*conj(G_3p))
    F_411m = A*fft( 2*ums*conj(ups)*G_3p- ums**2*conj(G_3m))
    F_412p = A*fft( 2*ups*conj(ums)*G_4m- ups**2*conj(G_4p))
    F_412m = A*fft( 2*ums*conj(ups)*G_4p- ums**2*conj(G_4m))
    F_51p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*ifft(B*fft(F_1m))+ 2*ups*ums*conj(ifft(B*fft(F_1p))))
    F_51m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*ifft(B*fft(F_1p))+2*ups*ums*conj(ifft(B*fft(F_1m))))
    F_52p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*ifft(B*fft(F_2m))+ 2*ups*ums*conj(ifft(B*fft(F_2p))))
    F_52m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*ifft(B*fft(F_2p))+ 2*ups*ums*conj(ifft(B*fft(F_2m))))
    F_53p = A*fft( 2*ums*conj(ups)*ifft(B*fft(F_1m))+ ums**2*conj(ifft(B*fft(F_1p))))
    F_53m = A*fft( 2*ups*conj(ums)*ifft(B*fft(F_1p))+ ups**2*conj(ifft(B*fft(F_1m))))
    F_54p = A*fft( 2*ums*conj(ups)*ifft(B*fft(F_2m))+ ums**2*conj(ifft(B*fft(F_2p))))
    F_54m = A*fft( 2*ups*conj(ums)*ifft(B*fft(F_2p))+ ups**2*conj(ifft(B*fft(F_2m))))
    F_55p = A*fft( 2*ups*conj(ums)*ifft(B*fft(F_1m))+ ups**2*conj(ifft(B*fft(F_1p))))
    F_55m = A*fft( 2*ums*conj(ups)*ifft(B*fft(F_1p))+ ums**2*conj(ifft(B*fft(F_1m))))
    F_56p = A*fft( 2*ups*conj(ums)*ifft(B*fft(F_2m))+ ups**2*conj(ifft(B*fft(F_2p))))
    F_56m = A*fft( 2*ums*conj(ups)*ifft(B*fft(F_2p))+ ums**2*conj(ifft(B*fft(F_2m))))
    F_61_1p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_21p+ 2*ups*ums*conj(F_21m))
    F_61_1m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_21m+ 2*ups*ums*conj(F_21p))
    F_61_2p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_22p+ 2*ups*ums*conj(F_22m))
    F_61_2m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_22m+ 2*ups*ums*conj(F_22p))
    F_61_3p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_23p+ 2*ups*ums*conj(F_23m))
    F_61_3m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_23m+ 2*ups*ums*conj(F_23p))
    F_61_4p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_24p+ 2*ups*ums*conj(F_24m))
    F_61_4m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_24m+ 2*ups*ums*conj(F_24p))
    F_61_5p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_25p+ 2*ups*ums*conj(F_25m))
    F_61_5m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_25m+ 2*ups*ums*conj(F_25p))
    F_61_6p = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_26p+ 2*ups*ums*conj(F_26m))
    F_61_6m = A*fft( 2*(abs_(ups)**2+abs_(ums)**2)*F_26m+ 2*ups*ums*conj(F_26p))
    F_62_1p = A*fft( 2*ums*conj(ups)*F_21p+ ums**2*conj(F_21m))
    F_62_1m = A*fft( 2*ups*conj(ums)*F_21m+ ups**2*conj(F_21p))
    F_62_2p = A*fft( 2*ums*conj(ups)*F_22p+ ums**2*conj(F_22m))
    F_62_2m = A*fft( 2*ups*conj(ums)*F_22m+ ups**2*conj(F_22p))
    F_62_3p = A*fft( 2*ums*conj(ups)*F_23p+ ums**2*conj(F_23m))
    F_62_3m = A*fft( 2*ups*conj(ums)*F_23m+ ups**2*conj(F_23p))
    F_62_4p = A*fft( 2*ums*conj(ups)*F_24p+ ums**2*conj(F_24m))
    F_62_4m = A*fft( 2*ups*conj(ums)*F_24m+ ups**2*conj(F_24p))
    F_62_5p = A*fft( 2*ums*conj(ups)*F_25p+ ums**2*conj(F_25m))
    F_62_5m = A*fft( 2*ups*conj(ums)*F_25m+ ups**2*conj(F_25p))
    F_62_6p = A*fft( 2*ums*conj(ups)*F_26p+ ums**2*conj(F_26m))
    F_62_6m = A*fft( 2*ups*conj(ums)*F_26m+ ups**2*conj(F_26p))
    F_63_1p = A*fft( 2*ups*conj(ums)*F_21p+ ups**2*conj(F_21m))
    F_63_1m = A*fft( 2*ums*conj(ups)*F_21m+ ums**2*conj(F_21p))
    F_63_2p = A*fft( 2*ups*conj(ums)*F_22p+ ups**2*conj(F_22m))
    F_63_2m = A*fft( 2*ums*conj(ups)*F_22m+ ums**2*conj(F_22p))
    F_63_3p = A*fft( 2*ups*conj(ums)*F_23p+ ups**2*conj(F_23m))
    F_63_3m = A*fft( 2*ums*conj(ups)*F_23m+ ums**2*conj(F_23p))
    F_63_4p = A*fft( 2*ups*conj(ums)*F_24p+ ups**2*conj(F_24m))
    F_63_4m = A*fft( 2*ums*conj(ups)*F_24m+ ums**2*conj(F_24p))
    F_63_5p = A*fft( 2*ups*conj(ums)*F_25p+ ups**2*conj(F_25m))
    F_63_5m = A*fft( 2*ums*conj(ups)*F_25m+ ums**2*conj(F_25p))
    F_63_6p = A*fft( 2*ups*conj(ums)*(F_26p if FIX309 else F_26m)+ ups**2*conj(F_26m))
    F_63_6m = A*fft( 2*ums*conj(ups)*F_26m+ ums**2*conj(F_26p))
    H_1ppp = A*fft( -2*ups*F_1p*conj(F_1m) + conj(ums)*F_1p*F_1p)
    H_1ppm = A*fft( -2*ups*F_1p*conj(F_1p) + conj(ums)*F_1p*F_1m)
    H_1pmp = A*fft( -2*ups*F_1m*conj(F_1m) + conj(ums)*F_1m*F_1p)
    H_1pmm = A*fft( -2*ups*F_1m*conj(F_1p) + conj(ums)*F_1m*F_1m)
    H_1mpp = A*fft( -2*ums*F_1p*conj(F_1m) + conj(ups)*F_1p*F_1p)
    H_1mpm = A*fft( -2*ums*F_1p*conj(F_1p) + conj(ups)*F_1p*F_1m)
    H_1mmp = A*fft( -2*ums*F_1m*conj(F_1m) + conj(ups)*F_1m*F_1p)
    H_1mmm = A*fft( -2*ums*F_1m*conj(F_1p) + conj(ups)*F_1m*F_1m)
    H_2ppp = A*fft( -2*ups*F_1p*conj(F_2m) + conj(ums)*F_1p*F_2p)
    H_2ppm = A*fft( -2*ups*F_1p*conj(F_2p) + conj(ums)*F_1p*F_2m)
    H_2pmp = A*fft( -2*ups*F_1m*conj(F_2m) + conj(ums)*F_1m*F_2p)
    H_2pmm = A*fft( -2*ups*F_1m*conj(F_2p) + conj(ums)*F_1m*F_2m)
    H_2mpp = A*fft( -2*ums*F_1p*conj(F_2m) + conj(ups)*F_1p*F_2p)
    H_2mpm = A*fft( -2*ums*F_1p*conj(F_2p) + conj(ups)*F_1p*F_2m)
    H_2mmp = A*fft( -2*ums*F_1m*conj(F_2m) + conj(ups)*F_1m*F_2p)
    H_2mmm = A*fft( -2*ums*F_1m*conj(F_2p) + conj(ups)*F_1m*F_2m)
    H_3ppp = A*fft( -2*ups*F_2p*conj(F_1m) + conj(ums)*F_2p*F_1p)
    H_3ppm = A*fft( -2*ups*F_2p*conj(F_1p) + conj(ums)*F_2p*F_1m)
    H_3pmp = A*fft( -2*ups*F_2m*conj(F_1m) + conj(ums)*F_2m*F_1p)
    H_3pmm = A*fft( -2*ups*F_2m*conj(F_1p) + conj(ums)*F_2m*F_1m)
    H_3mpp = A*fft( -2*ums*F_2p*conj(F_1m) + conj(ups)*F_2p*F_1p)
    H_3mpm = A*fft( -2*ums*F_2p*conj(F_1p) + conj(ups)*F_2p*F_1m)
    H_3mmp = A*fft( -2*ums*F_2m*conj(F_1m) + conj(ups)*F_2m*F_1p)
    H_3mmm = A*fft( -2*ums*F_2m*conj(F_1p) + conj(ups)*F_2m*F_1m)
    H_4ppp = A*fft( -2*ups*F_2p*conj(F_2m) + conj(ums)*F_2p*F_2p)
    H_4ppm = A*fft( -2*ups*F_2p*conj(F_2p) + conj(ums)*F_2p*F_2m)
    H_4pmp = A*fft( -2*ups*F_2m*conj(F_2m) + conj(ums)*F_2m*F_2p)
    H_4pmm = A*fft( -2*ups*F_2m*conj(F_2p) + conj(ums)*F_2m*F_2m)
    H_4mpp = A*fft( -2*ums*F_2p*conj(F_2m) + conj(ups)*F_2p*F_2p)
    H_4mpm = A*fft( -2*ums*F_2p*conj(F_2p) + conj(ups)*F_2p*F_2m)
    H_4mmp = A*fft( -2*ums*F_2m*conj(F_2m) + conj(ups)*F_2m*F_2p)
    H_4mmm = A*fft( -2*ums*F_2m*conj(F_2p) + conj(ups)*F_2m*F_2m)
    delta_n3p = (
        tau**2*1/2*B**2*( ps[0]*fft(F_2p) + ps[1]*fft(F_2m)+ ps[2]*fft(F_1p) + ps[3]*fft(F_1m) )
        +1/2*B**2*( p2s[0]*fft(F_2p) + p2s[1]*fft(F_2m)+ p2s[2]*fft(F_1p) + p2s[3]*fft(F_1m) )
        -tau*B**2*( p1s[0]*fft(F_2p) + p1s[1]*fft(F_2m)+ p1s[2]*fft(F_1p) + p1s[3]*fft(F_1m) ) -tau*B*(
        p1s[0]*fft(G_4p) + p1s[1]*fft(G_4m)+ p1s[2]*fft(+ G_3p) + p1s[3]*fft(G_3m) ) +B*(
        p2s[0]*fft(G_4p) + p2s[1]*fft(G_4m)+ p2s[2]*fft(+ G_3p) + p2s[3]*fft(G_3m) ) +( p2s[0]*E_2p +
        p2s[1]*E_2m+ p2s[2]*E_1p + p2s[3]*E_1m ) + p2s[0]*G_23p + p2s[1]*G_23m+ p2s[2]*G_13p +
        p2s[3]*G_13m -tau*B*( qs[0,0]*fft(F_21p)+ qs[0,1]*fft(F_21m) +qs[1,0]*fft(F_22p)+
        qs[1,1]*fft(F_22m) +qs[2,0]*fft(F_23p)+ qs[2,1]*fft(F_23m)+ qs[3,0]*fft(F_24p)+
        qs[3,1]*fft(F_24m) +qs[4,0]*fft(F_25p)+ qs[4,1]*fft(F_25m) +qs[5,0]*fft(F_26p)+
        qs[5,1]*fft(F_26m) ) +B* ( q1s[0,0]*fft(F_21p)+ q1s[0,1]*fft(F_21m) +q1s[1,0]*fft(F_22p)+
        q1s[1,1]*fft(F_22m) +q1s[2,0]*fft(F_23p)+ q1s[2,1]*fft(F_23m)+ q1s[3,0]*fft(F_24p)+
        q1s[3,1]*fft(F_24m) +q1s[4,0]*fft(F_25p)+ q1s[4,1]*fft(F_25m) +q1s[5,0]*fft(F_26p)+
        q1s[5,1]*fft(F_26m)) +( q1s[0,0]*F_31p+ q1s[0,1]*F_31m +q1s[1,0]*F_32p+ q1s[1,1]*F_32m
        +q1s[2,0]*F_33p+ q1s[2,1]*F_33m+ q1s[3,0]*F_34p+ q1s[3,1]*F_34m +q1s[4,0]*F_35p+ q1s[4,1]*F_35m
        +q1s[5,0]*F_36p+ q1s[5,1]*F_36m ) +rs[0,0]*H_1ppp +rs[0,1]*H_1ppm+ rs[0,2]*H_1pmp+
        rs[0,3]*H_1pmm+ rs[1,0]*H_2ppp +rs[1,1]*H_2ppm+ rs[1,2]*H_2pmp+ rs[1,3]*H_2pmm +rs[2,0]*H_3ppp
        +rs[2,1]*H_3ppm+ rs[2,2]*H_3pmp+ rs[2,3]*H_3pmm+ rs[3,0]*H_4ppp +rs[3,1]*H_4ppm+ rs[3,2]*H_4pmp+
        rs[3,3]*H_4pmm +rs[4,0]*H_1mpp+rs[4,1]*H_1mpm+ rs[4,2]*H_1mmp+ rs[4,3]*H_1mmm+ rs[5,0]*H_2mpp
        +rs[5,1]*H_2mpm+ rs[5,2]*H_2mmp+ rs[5,3]*H_2mmm +rs[6,0]*H_3mpp+rs[6,1]*H_3mpm+ rs[6,2]*H_3mmp+
        rs[6,3]*H_3mmm+ rs[7,0]*H_4mpp +rs[7,1]*H_4mpm+ rs[7,2]*H_4mmp+ rs[7,3]*H_4mmm
        +m1s[0,0]*F_61_1p+ m1s[1,0]*F_61_2p+ m1s[2,0]*F_61_3p+ m1s[3,0]*F_61_4p+ m1s[4,0]*F_61_5p+
        m1s[5,0]*F_61_6p+ +m2s[0,0]*F_62_1p+ m2s[1,0]*F_62_2p+ m2s[2,0]*F_62_3p+ m2s[3,0]*F_62_4p+
        m2s[4,0]*F_62_5p+ m2s[5,0]*F_62_6p+ +m3s[0,0]*F_63_1p+ m3s[1,0]*F_63_2p+ m3s[2,0]*F_63_3p+
        m3s[3,0]*F_63_4p+ m3s[4,0]*F_63_5p+ m3s[5,0]*F_63_6p+ +m1s[0,1]*F_61_1m+ m1s[1,1]*F_61_2m+
        m1s[2,1]*F_61_3m+ m1s[3,1]*F_61_4m+ m1s[4,1]*F_61_5m+ m1s[5,1]*F_61_6m+ +m2s[0,1]*F_62_1m+
        m2s[1,1]*F_62_2m+ m2s[2,1]*F_62_3m+ m2s[3,1]*F_62_4m+ m2s[4,1]*F_62_5m+ m2s[5,1]*F_62_6m+
        +m3s[0,1]*F_63_1m+ m3s[1,1]*F_63_2m+ m3s[2,1]*F_63_3m+ m3s[3,1]*F_63_4m+ m3s[4,1]*F_63_5m+
        m3s[5,1]*F_63_6m +q2s[0,0]*F_41p+ q2s[0,1]*F_41m +q2s[1,0]*F_42p+ q2s[1,1]*F_42m
        +q2s[2,0]*F_43p+ q2s[2,1]*F_43m+ q2s[3,0]*F_44p+ q2s[3,1]*F_44m +q2s[4,0]*F_45p+ q2s[4,1]*F_45m
        +q2s[5,0]*F_46p+ q2s[5,1]*F_46m +q3s[0,0]*F_51p+ q3s[0,1]*F_51m +q3s[1,0]*F_52p+ q3s[1,1]*F_52m
        +q3s[2,0]*F_53p+ q3s[2,1]*F_53m+ q3s[3,0]*F_54p+ q3s[3,1]*F_54m +q3s[4,0]*F_55p+q3s[4,1]*F_55m
        +q3s[5,0]*F_56p+ q3s[5,1]*F_56m +q4s[0,0]*F_47p+ q4s[0,1]*F_47m +q4s[1,0]*F_48p+ q4s[1,1]*F_48m
        +q4s[2,0]*F_49p+ q4s[2,1]*F_49m+ +q4s[3,0]*F_410p+ q4s[3,1]*F_410m +q4s[4,0]*F_411p+
        q4s[4,1]*F_411m +q4s[5,0]*F_412p+ q4s[5,1]*F_412m
    )
    delta_n3m = (
        tau**2*1/2*B**2*( -conj(ps[0])*fft(F_2m) + -conj(ps[1])*fft(F_2p)+ -conj(ps[2])*fft(F_1m) +
        -conj(ps[3])*fft(F_1p) )+ -1/2*B**2*( conj(p2s[0])*fft(F_2m) + conj(p2s[1])*fft(F_2p)+
        conj(p2s[2])*fft(F_1m) + conj(p2s[3])*fft(F_1p) ) +tau*B**2*( conj(p1s[0])*fft(F_2m) +
        conj(p1s[1])*fft(F_2p)+ conj(p1s[2])*fft(F_1m) + conj(p1s[3])*fft(F_1p) ) -tau*B*(
        conj(p1s[0])*fft(G_4m) + conj(p1s[1])*fft(G_4p)+ conj(p1s[2])*fft(+ G_3m) +
        conj(p1s[3])*fft(G_3p) ) +B*( conj(p2s[0])*fft(G_4m) + conj(p2s[1])*fft(G_4p)+
        conj(p2s[2])*fft(+ G_3m) + conj(p2s[3])*fft(G_3p) ) -( conj(p2s[0])*E_2m + conj(p2s[1])*E_2p+
        conj(p2s[2])*E_1m + conj(p2s[3])*E_1p ) -( conj(p2s[0])*G_23m + conj(p2s[1])*G_23p+
        conj(p2s[2])*G_13m + conj(p2s[3])*G_13p ) +tau*B* ( conj(qs[0,0])*fft(F_21m)+
        conj(qs[0,1])*fft(F_21p) + conj(qs[1,0])*fft(F_22m)+ conj(qs[1,1])*fft(F_22p) +
        conj(qs[2,0])*fft(F_23m)+ conj(qs[2,1])*fft(F_23p)+ conj(qs[3,0])*fft(F_24m)+
        conj(qs[3,1])*fft(F_24p) + conj(qs[4,0])*fft(F_25m)+ conj(qs[4,1])*fft(F_25p)
        +conj(qs[5,0])*fft(F_26m)+ conj(qs[5,1])*fft(F_26p) ) -B*( conj(q1s[0,0])*fft(F_21m)+
        conj(q1s[0,1])*fft(F_21p) + conj(q1s[1,0])*fft(F_22m)+ conj(q1s[1,1])*fft(F_22p) +
        conj(q1s[2,0])*fft(F_23m)+ conj(q1s[2,1])*fft(F_23p)+ conj(q1s[3,0])*fft(F_24m)+
        conj(q1s[3,1])*fft(F_24p) + conj(q1s[4,0])*fft(F_25m)+ conj(q1s[4,1])*fft(F_25p) +
        conj(q1s[5,0])*fft(F_26m)+ conj(q1s[5,1])*fft(F_26p) ) +( conj(q1s[0,0])*F_31m+
        conj(q1s[0,1])*F_31p + conj(q1s[1,0])*F_32m+ conj(q1s[1,1])*F_32p + conj(q1s[2,0])*F_33m+
        conj(q1s[2,1])*F_33p+ conj(q1s[3,0])*F_34m+ conj(q1s[3,1])*F_34p + conj(q1s[4,0])*F_35m+
        conj(q1s[4,1])*F_35p + conj(q1s[5,0])*F_36m+ conj(q1s[5,1])*F_36p ) -( conj(rs[0,0])*H_1mmm +
        conj(rs[0,1])*H_1mmp+ conj(rs[0,2])*H_1mpm+ conj(rs[0,3])*H_1mpp+ conj(rs[1,0])*H_2mmm +
        conj(rs[1,1])*H_2mmp+ conj(rs[1,2])*H_2mpm+ conj(rs[1,3])*H_2mpp +conj(rs[2,0])*H_3mmm
        +conj(rs[2,1])*H_3mmp+ conj(rs[2,2])*H_3mpm+ conj(rs[2,3])*H_3mpp+ conj(rs[3,0])*H_4mmm
        +conj(rs[3,1])*H_4mmp+ conj( rs[3,2])*H_4mpm+ conj(rs[3,3])*H_4mpp
        +conj(rs[4,0])*H_1pmm+conj(rs[4,1])*H_1pmp+ conj(rs[4,2])*H_1ppm+ conj(rs[4,3])*H_1ppp+
        conj(rs[5,0])*H_2pmm +conj(rs[5,1])*H_2pmp+ conj(rs[5,2])*H_2ppm+ conj(rs[5,3])*H_2ppp
        +conj(rs[6,0])*H_3pmm+conj(rs[6,1])*H_3pmp+ conj(rs[6,2])*H_3ppm+ conj(rs[6,3])*H_3ppp+
        conj(rs[7,0])*H_4pmm +conj(rs[7,1])*H_4pmp+ conj(rs[7,2])*H_4ppm+ conj(rs[7,3])*H_4ppp )
        -(+conj(q2s[0,0])*F_41m+ conj(q2s[0,1])*F_41p + conj(q2s[1,0])*F_42m+ conj(q2s[1,1])*F_42p +
        conj(q2s[2,0])*F_43m+ conj(q2s[2,1])*F_43p+ conj(q2s[3,0])*F_44m+ conj(q2s[3,1])*F_44p +
        conj(q2s[4,0])*F_45m+ conj(q2s[4,1])*F_45p + conj(q2s[5,0])*F_46m+ conj(q2s[5,1])*F_46p ) +(
        conj(q4s[0,0])*F_47m+ conj(q4s[0,1])*F_47p +conj(q4s[1,0])*F_48m+ conj(q4s[1,1])*F_48p
        +conj(q4s[2,0])*F_49m+ conj(q4s[2,1])*F_49p+ conj(q4s[3,0])*F_410m+ conj(q4s[3,1])*F_410p
        +conj(q4s[4,0])*F_411m+ conj(q4s[4,1])*F_411p +conj(q4s[5,0])*F_412m+ conj(q4s[5,1])*F_412p ) -(
        conj(q3s[0,0])*F_51m+ conj(q3s[0,1])*F_51p + conj(q3s[1,0])*F_52m+ conj(q3s[1,1])*F_52p +
        conj(q3s[2,0])*F_53m+ conj(q3s[2,1])*F_53p+ conj(q3s[3,0])*F_54m+ conj(q3s[3,1])*F_54p +
        conj(q3s[4,0])*F_55m+ conj(q3s[4,1])*F_55p + conj(q3s[5,0])*F_56m+ conj(q3s[5,1])*F_56p ) -(
        conj(m1s[0,0])*F_61_1m+ conj(m1s[1,0])*F_61_2m+ conj(m1s[2,0])*F_61_3m+ conj(m1s[3,0])*F_61_4m+
        conj(m1s[4,0])*F_61_5m+ conj(m1s[5,0])*F_61_6m+ +conj(m2s[0,0])*F_62_1m+ conj(m2s[1,0])*F_62_2m+
        conj(m2s[2,0])*F_62_3m+ conj(m2s[3,0])*F_62_4m+ conj(m2s[4,0])*F_62_5m+ conj(m2s[5,0])*F_62_6m+
        +conj(m3s[0,0])*F_63_1m+ conj(m3s[1,0])*F_63_2m+ conj(m3s[2,0])*F_63_3m+ conj(m3s[3,0])*F_63_4m+
        conj(m3s[4,0])*F_63_5m+ conj(m3s[5,0])*F_63_6m+ +conj(m1s[0,1])*F_61_1p+ conj(m1s[1,1])*F_61_2p+
        conj(m1s[2,1])*F_61_3p+ conj(m1s[3,1])*F_61_4p+ conj(m1s[4,1])*F_61_5p+ conj(m1s[5,1])*F_61_6p+
        +conj(m2s[0,1])*F_62_1p+ conj(m2s[1,1])*F_62_2p+ conj(m2s[2,1])*F_62_3p+ conj(m2s[3,1])*F_62_4p+
        conj(m2s[4,1])*F_62_5p+ conj(m2s[5,1])*F_62_6p+ +conj(m3s[0,1])*F_63_1p+ conj(m3s[1,1])*F_63_2p+
        conj(m3s[2,1])*F_63_3p+ conj(m3s[3,1])*F_63_4p+ conj(m3s[4,1])*F_63_5p+ conj(m3s[5,1])*F_63_6p )
    )
    ups = exp(-1j*tau*betal)*up+ delta_n1p+ delta_n2p+ delta_n3p
    ums = exp(1j*tau*betal)*um+ delta_n1m+ delta_n2m+ delta_n3m
    return ups, ums


# ----------------------------------------------------------------------------------------------
# drivers and checks
# ----------------------------------------------------------------------------------------------
EPS = [1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-6]
NS = [4, 8, 16, 32, 64]  # tau = T/n


def initial(E):
    u, v = kg_data(E)
    return np.fft.fft(np.conj(v)) / 2, np.fft.fft(u) / 2  # psi_+ = conj(v)/2, psi_- = u/2 (Fourier)


def to_uv(up, um):
    return 2 * np.fft.ifft(um), 2 * np.conj(np.fft.ifft(up))


def run_generic(E, tau, order):
    up, um = initial(E)
    S = NPI(E, tau, XK, LAM, order)
    for _ in range(int(round(TF / tau))):
        up, um = S.step(up, um)
    return to_uv(up, um)


def run_port(E, tau, order, fix309=True):
    up, um = initial(E)
    S = NPI(E, tau, XK, LAM, 1)  # only for A, B, D_E
    C = coeff_tables(E, tau)
    for _ in range(int(round(TF / tau))):
        if order == 2:
            up, um = newnpi2_step(up, um, S.A, S.B, tau, S.De, C)
        else:
            up, um = newnpi3_step(up, um, S.A, S.B, tau, S.De, C, FIX309=fix309)
    return to_uv(up, um)


def cquad(f, a, b):
    from scipy.integrate import quad

    kw = dict(epsabs=1e-14, epsrel=1e-12, limit=200)
    return quad(lambda x: f(x).real, a, b, **kw)[0] + 1j * quad(lambda x: f(x).imag, a, b, **kw)[0]


def check_coeffs():
    E, s = 0.3, 0.2
    C = code_coeffs(FloatField(E))
    ex = lambda x: np.exp(1j * x / E)
    pk = lambda k: (lambda t: ex(-t) * (t if k == 0 else cquad(lambda v: ex(k * v), 0, t)))
    p1k = lambda k: (lambda t: ex(-t) * cquad(lambda v: v * ex(k * v), 0, t))
    P = [pk(k) for k in (0, 2, -2, 4)]
    P1 = [p1k(k) for k in (0, 2, -2, 4)]
    conv = lambda g, ph=0: cquad(lambda t: ex(-(s - t)) * ex(ph * t) * g(t), 0, s)
    cj = np.conj
    rows = [
        ("p_-2 = p{3}", C["p"][2](s), P[2](s)),
        ("p_{4,1} = p1{4}", C["p1"][3](s), P1[3](s)),
        ("p_{2,2} = p2{2}", C["p2"][1](s), ex(-s) * cquad(lambda v: v * v * ex(2 * v), 0, s)),
        ("q{3,1}", C["q"][2][0](s), conv(lambda t: -cj(P[2](t)) + P[3](t), 2)),
        ("q{6,2}", C["q"][5][1](s), conv(lambda t: -cj(P[1](t)) + P[0](t), 2)),
        ("q1{4,2}", C["q1"][3][1](s), conv(lambda t: (-cj(P[1](t)) + P[0](t)) * t, -2)),
        ("q2{2,2}", C["q2"][1][1](s), conv(lambda t: cj(P1[1](t)) + P1[0](t))),
        ("q3{5,1}", C["q3"][4][0](s), conv(lambda t: (-cj(P[2](t)) - P[3](t)) * t, -2)),
        ("q4{1,2}", C["q4"][0][1](s), conv(lambda t: -cj(P1[3](t)) + P1[2](t))),
        ("r{6,3}", C["r"][5][2](s),
         ex(-s) * cquad(lambda t: ex(2 * t) * (-cj(P[2](t)) + P[3](t)) * (P[0](t) - cj(P[1](t))), 0, s)),
        ("m3{4,2}", C["m3"][3][1](s),
         conv(lambda t: cj(C["q"][3][0](t)) + C["q"][3][1](t), 2)),
        ("m1{2,1}", C["m1"][1][0](s),
         conv(lambda t: C["q"][1][0](t) + cj(C["q"][1][1](t)))),
        ("m2{5,2}", C["m2"][4][1](s),
         conv(lambda t: cj(C["q"][4][0](t)) + C["q"][4][1](t), -2)),
    ]
    print(f"Check 1: closed forms (PP) vs scipy quadrature of the symbolNPI_complex.m definitions, E = {E}, s = {s}")
    for name, a, b in rows:
        print(f"    {name:<16s} {a.real:+.15e} {a.imag:+.15e}i   |diff| {abs(a - b):.1e}")


def check_ports():
    print("Check 2: one step of the newnpi2.m / newnpi3.m ports vs the generic recipe (CosSin data, N_x = 128);")
    print("         |difference| / |delta^k(tau)|  (k = 2 for newnpi2, 3 for newnpi3)")
    for E, tau in [(1.0, 0.05), (0.1, 0.02), (1e-3, 0.01), (1e-6, 0.01)]:
        up, um = initial(E)
        S2, S3 = NPI(E, tau, XK, LAM, 2), NPI(E, tau, XK, LAM, 3)
        ds = S3.deltas(up, um)
        d2 = np.linalg.norm(S3.evald(ds[1][0], tau)) + np.linalg.norm(S3.evald(ds[1][1], tau))
        d3 = np.linalg.norm(S3.evald(ds[2][0], tau)) + np.linalg.norm(S3.evald(ds[2][1], tau))
        C = coeff_tables(E, tau)
        g2, g3 = S2.step(up, um), S3.step(up, um)
        diff = lambda a, b: np.linalg.norm(a[0] - b[0]) + np.linalg.norm(a[1] - b[1])
        c2 = newnpi2_step(up, um, S2.A, S2.B, tau, S2.De, C)
        c3 = newnpi3_step(up, um, S3.A, S3.B, tau, S3.De, C, FIX309=True)
        c3o = newnpi3_step(up, um, S3.A, S3.B, tau, S3.De, C, FIX309=False)
        print(f"    E={E:<6g} tau={tau:<5g} newnpi2: {diff(c2, g2) / d2:.1e}   newnpi3 (line 309 fixed): "
              f"{diff(c3, g3) / d3:.1e}   newnpi3 as published: {diff(c3o, g3) / d3:.1e}")


def table(title, fn, eps=EPS, ns=NS):
    print(title)
    t0 = time.process_time()
    print("    eps      " + "".join(f"  tau=T/{n:<3d}" for n in ns) + "  orders")
    worst = np.zeros(len(ns))
    for e in eps:
        ur, vr = kg_ref(e)
        errs = [rel(*fn(e, TF / n), ur, vr) for n in ns]
        worst = np.maximum(worst, errs)
        o = [np.log2(errs[i] / errs[i + 1]) for i in range(len(ns) - 1)]
        print(f"    {e:<8g}" + "".join(f"  {x:9.2e}" for x in errs) + "  " + " ".join(f"{x:5.2f}" for x in o))
    o = [np.log2(worst[i] / worst[i + 1]) for i in range(len(ns) - 1)]
    print("    max_eps " + "".join(f"  {x:9.2e}" for x in worst) + "  " + " ".join(f"{x:5.2f}" for x in o))
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


def check_part_c():
    d = 0.0
    for e in EPS:
        for n in (16, 64):
            a, b = run_generic(e, TF / n, 1), npi1_kg(e, TF / n)
            d = max(d, np.max(abs(a[0] - b[0])), np.max(abs(a[1] - b[1])))
    print(f"Check 3: generic order 1 vs micro_macro_prototype.npi1_kg (Part C), all eps, tau = T/16, T/64: "
          f"max |diff| = {d:.1e}")


def check_refs():
    print("Check 5: accuracy of the references: NPI3 (generic) at tau = T/128, T/256 vs micromacro-cos-sin/")
    t0 = time.process_time()
    for e in EPS:
        ur, vr = kg_ref(e)
        errs = [rel(*run_generic(e, TF / n, 3), ur, vr) for n in (128, 256)]
        print(f"    eps={e:<8g}  T/128: {errs[0]:.2e}  T/256: {errs[1]:.2e}  ratio {errs[0] / errs[1]:.2f}")
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


def closed_forms():
    """print every coefficient of symbolNPI_complex.m as sum_m e^{ims/E} (polynomial in s, E)"""
    F = SymField()
    sp = F.sp
    s = sp.Symbol("s")
    C = code_coeffs(F)
    names = {"p": ["p_0", "p_2", "p_-2", "p_4"], "p1": ["p_{0,1}", "p_{2,1}", "p_{-2,1}", "p_{4,1}"],
             "p2": ["p_{0,2}", "p_{2,2}", "p_{-2,2}", "p_{4,2}"]}

    def fmt(g):
        by_m = {}
        for (m, p), c in g.t.items():
            by_m[m] = by_m.get(m, 0) + sp.sympify(c) * s**p
        parts = []
        for m in sorted(by_m):
            poly = sp.expand(by_m[m])
            if poly != 0:
                parts.append(f"e^{{{m}is/E}} [{poly}]")
        return " + ".join(parts)

    for fam in ["p", "p1", "p2", "q", "q1", "q2", "q3", "q4", "r", "m1", "m2", "m3"]:
        v = C[fam]
        if not isinstance(v[0], list):
            for i, g in enumerate(v):
                print(f"{fam}{{{i + 1}}} = {names[fam][i]}(s) = {fmt(g)}")
        else:
            for j, row in enumerate(v):
                for k, g in enumerate(row):
                    print(f"{fam}{{{j + 1},{k + 1}}}(s) = {fmt(g)}")


if __name__ == "__main__":
    if "--closed-forms" in sys.argv:
        closed_forms()
        sys.exit(0)
    T0 = time.process_time()
    check_coeffs()
    check_ports()
    check_part_c()
    print("Check 4: error tables, KG CosSin, N_x = 128, T = 0.25, relative L2 of (u, v) vs micromacro-cos-sin/")
    for k in (1, 2, 3):
        table(f"  NPI{k} (generic recipe = newnpi{k}.m{' with line 309 fixed' if k == 3 else ''})",
              lambda e, tau, k=k: run_generic(e, tau, k))
    table("  port of newnpi3.m AS PUBLISHED (line 309 typo kept)",
          lambda e, tau: run_port(e, tau, 3, fix309=False), eps=[0.1, 0.01, 1e-3, 1e-4])
    check_refs()
    print(f"total {time.process_time() - T0:.1f} s CPU")
