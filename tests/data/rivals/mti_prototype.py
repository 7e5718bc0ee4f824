#!/usr/bin/python3
"""MTI-FP (multiscale time integrator, Fourier pseudospectral) for the complex cubic Klein-Gordon
equation, RECONSTRUCTED (see mti.md: the paper's body was not accessible, so every formula below
is derived here from the structure the paper's abstract states, not transcribed), run against
MicroMacro.jl's CosSin references (micromacro-cos-sin/, N_x = 128 on [0, 2 pi), T = 0.25).

Equation (Bao's scaling, e^2 = MicroMacro.jl's eps, nonlinearity in the "+ f" form):
    e^2 psi_tt - psi_xx + psi / e^2 + f(psi) = 0,   f(psi) = lam |psi|^2 psi,  lam = +1
(= eps z_tt - z_xx + z/eps + |z|^2 z = 0 of micro-macro.md section 3.3; Cai-Zhou's lambda = -1).
MicroMacro.jl's (u, v):  psi = (u + conj v)/2,  psi_t = i D_e (u - conj v)/2,
    u = psi - i D_e^{-1} psi_t,  v = conj(psi) - i D_e^{-1} conj(psi_t),  D_e = sqrt(1 + e^2 k^2)/e^2
(psi_- = u/2, psi_+ = conj(v)/2, checked in micro_macro_prototype.py Part C).

One MTI step from (psi^n, psid^n) ~ (psi(t_n), psi_t(t_n)), s in [0, tau], th = s/e^2:
    psi(t_n + s) = e^{i th} z(s) + e^{-i th} conj(w(s)) + r(s)                            (MDF)
    e^2 z'' + 2i z' - z_xx + lam (|z|^2 + 2|w|^2) z = 0                                  (NLSW+)
    e^2 w'' + 2i w' - w_xx + lam (|w|^2 + 2|z|^2) w = 0                                  (NLSW-)
    e^2 r'' - r_xx + r/e^2 + f_r = 0,                                                     (KG-r)
    f_r = lam [e^{3i th} z^2 w + e^{-3i th} conj(z) conj(w)^2] + f(psi_0 + r) - f(psi_0),
    psi_0 = e^{i th} z + e^{-i th} conj(w)
    data: z(0) = (psi^n - i e^2 psid^n)/2,  w(0) = conj(psi^n + i e^2 psid^n)/2,  r(0) = 0,
          z'(0) = (i/2)(-z_xx + lam (|z|^2 + 2|w|^2) z)(0)   (the same for w: "well-prepared"),
          r'(0) = -z'(0) - conj(w'(0))                      (so that psi_t(t_n) is matched)
    z, w: exponential wave integrator (exact variation of constants of the linear part, mode by
          mode) with the nonlinearity linear in s, F(s) ~ F(0) + s F'(0), F'(0) by the chain rule;
    r:    Gautschi-type EWI with f_r(s) ~ lam e^{3is/e^2}(A0 + s A1) + lam e^{-3is/e^2}(B0 + s B1)
          + [coupling term], the phases integrated exactly; coupling f(psi_0 + r) - f(psi_0):
          variant A ("taylor"): s G1, G1 = Df(psi^n) r'(0) (r(0) = 0);
          variant B ("phase", not from any source): Df(psi_0(s)) applied to the free oscillation
          sin(om s)/om r'(0), z and w frozen, every phase e^{+-i s/e^2}, e^{+-3i s/e^2} exact.
    psi^{n+1}  = e^{i tau/e^2} z(tau) + e^{-i tau/e^2} conj(w(tau)) + r(tau)
    psid^{n+1} = e^{i tau/e^2}(i z/e^2 + z') + e^{-i tau/e^2}(-i conj(w)/e^2 + conj(w')) + r'
Whole run: about 0.5 s of CPU (numpy 1.24, one core).
"""
import sys
import time

import numpy as np

sys.path.insert(0, __file__.rsplit("/", 1)[0])
from micro_macro_prototype import XK, kg_data, kg_ref, rel  # noqa: E402

LAM = 1.0
K2 = XK**2


def phi1(x):
    """(e^x - 1)/x, x complex array, series near 0"""
    x = np.asarray(x, complex)
    out = np.empty_like(x)
    small = np.abs(x) < 1e-4
    xs = x[small]
    out[small] = 1 + xs / 2 + xs**2 / 6
    xl = x[~small]
    out[~small] = np.expm1(xl) / xl
    return out


def phi2(x):
    """(e^x - 1 - x)/x^2, series near 0"""
    x = np.asarray(x, complex)
    out = np.empty_like(x)
    small = np.abs(x) < 1e-3
    xs = x[small]
    out[small] = 0.5 + xs / 6 + xs**2 / 24 + xs**3 / 120
    xl = x[~small]
    out[~small] = (np.expm1(xl) - xl) / xl**2
    return out


def W(alpha, beta, m, tau):
    """int_0^tau e^{i alpha (tau - s)} e^{i beta s} s^m ds, m = 0, 1 (alpha, beta real arrays)"""
    c = 1j * (alpha - beta) * tau
    if m == 0:
        return np.exp(1j * beta * tau) * tau * phi1(c)
    return np.exp(1j * beta * tau) * tau**2 * phi2(c)


class MTI:
    def __init__(self, eps, tau, coupling="taylor"):
        self.e2 = e2 = eps  # Bao's eps^2 = MicroMacro.jl's eps
        self.tau = tau
        self.coupling = coupling  # "taylor" (variant A) or "phase" (variant B), see mti.md 4
        d = np.sqrt(1 + e2 * K2)
        self.delta = d
        self.De = d / e2  # D_e (mode-wise); also the KG frequency omega of r
        lp = K2 / (1 + d)  # slow root of e^2 l^2 + 2 l - k^2 = 0  (= (d - 1)/e2, stable form)
        lm = -(1 + d) / e2  # fast root
        self.lp, self.lm = lp, lm
        z0 = np.zeros_like(lp)
        # z-EWI coefficients (Fourier multipliers), see mti.md section 3
        self.Ep, self.Em = np.exp(1j * lp * tau), np.exp(1j * lm * tau)
        self.P0 = (W(lp, z0, 0, tau) - W(lm, z0, 0, tau)) / (2j * d)  # multiplies F(0)
        self.P1 = (W(lp, z0, 1, tau) - W(lm, z0, 1, tau)) / (2j * d)  # multiplies F'(0)
        self.Q0 = (1j * lp * W(lp, z0, 0, tau) - 1j * lm * W(lm, z0, 0, tau)) / (2j * d)
        self.Q1 = (1j * lp * W(lp, z0, 1, tau) - 1j * lm * W(lm, z0, 1, tau)) / (2j * d)
        # r-EWI coefficients: sin/cos kernels against e^{i beta s} s^m, beta in {+-3/e2, +-1/e2, 0}
        om = self.De
        self.rs, self.rc = {}, {}
        for beta in (3 / e2, -3 / e2, 1 / e2, -1 / e2, 0.0):
            b = np.full_like(om, beta)
            for m in (0, 1):
                wp, wm = W(om, b, m, tau), W(-om, b, m, tau)
                self.rs[beta, m] = (wp - wm) / (2j) / d  # (1/delta) int sin(om(tau-s)) ...
                self.rc[beta, m] = (wp + wm) / 2 / e2  # (1/e2) int cos(om(tau-s)) ...
        self.cc, self.sn = np.cos(om * tau), np.sin(om * tau)
        self.ph = np.exp(1j * tau / e2)

    def step(self, psi, psid):
        e2, F, iF = self.e2, np.fft.fft, np.fft.ifft
        d, lp, lm = self.delta, self.lp, self.lm
        z = (psi - 1j * e2 * psid) / 2
        w = np.conj(psi + 1j * e2 * psid) / 2
        Fz = LAM * (abs(z) ** 2 + 2 * abs(w) ** 2) * z
        Fw = LAM * (abs(w) ** 2 + 2 * abs(z) ** 2) * w
        zh, wh = F(z), F(w)
        zsh = 0.5j * (K2 * zh + F(Fz))  # well-prepared z'(0)
        wsh = 0.5j * (K2 * wh + F(Fw))
        zs, ws = iF(zsh), iF(wsh)
        # chain-rule s-derivatives of the NLSW nonlinearities at s = 0
        dzz = 2 * (z.conjugate() * zs).real  # d|z|^2/ds
        dww = 2 * (w.conjugate() * ws).real
        Fz1 = LAM * ((dzz + 2 * dww) * z + (abs(z) ** 2 + 2 * abs(w) ** 2) * zs)
        Fw1 = LAM * ((dww + 2 * dzz) * w + (abs(w) ** 2 + 2 * abs(z) ** 2) * ws)

        def ewi(yh, ysh, f0, f1):
            cp = (1 + d) * yh / (2 * d) + e2 * ysh / (2j * d)
            cm = e2 * lp * yh / (2 * d) - e2 * ysh / (2j * d)
            f0h, f1h = F(f0), F(f1)
            y = cp * self.Ep + cm * self.Em - self.P0 * f0h - self.P1 * f1h
            ys = 1j * lp * cp * self.Ep + 1j * lm * cm * self.Em - self.Q0 * f0h - self.Q1 * f1h
            return y, ys

        zt, zst = ewi(zh, zsh, Fz, Fz1)
        wt, wst = ewi(wh, wsh, Fw, Fw1)
        # remainder
        rs0 = -zs - np.conj(ws)
        A0, A1 = LAM * z**2 * w, LAM * (2 * z * zs * w + z**2 * ws)
        cz, cw, czs, cws = np.conj(z), np.conj(w), np.conj(zs), np.conj(ws)
        B0, B1 = LAM * cz * cw**2, LAM * (czs * cw**2 + 2 * cz * cw * cws)
        b3, b1 = 3 / e2, 1 / e2
        if self.coupling == "taylor":
            # variant A: f(psi_0 + r) - f(psi_0) ~ s Df(psi^n) r'(0)   (r(0) = 0)
            G1 = LAM * (2 * abs(psi) ** 2 * rs0 + psi**2 * np.conj(rs0))
            terms = [(b3, 0, A0), (b3, 1, A1), (-b3, 0, B0), (-b3, 1, B1), (0.0, 1, G1)]
        else:
            # variant B: f(psi_0 + r) - f(psi_0) ~ Df(psi_0(s)) r_lin(s), psi_0 with z, w frozen,
            # r_lin = sin(om s)/om r'(0) = e^{i th}(rho + s rho1) - e^{-i th}(rho - s rho1) + O(s^2),
            # rho = (2 i om)^{-1} r'(0), rho1 = i lp rho (mode-wise); phases e^{+-i th},
            # e^{+-3i th} integrated exactly
            rsh0 = F(rs0) / (2j * self.De)
            rho, rho1 = iF(rsh0), iF(1j * lp * rsh0)
            a2 = abs(z) ** 2 + abs(w) ** 2

            def coup(al, be):  # Df(psi_0) (e^{i th} al - e^{-i th} be) by phase e^{3i th}, e^{i th}, e^{-i th}, e^{-3i th}
                ca, cb = np.conj(al), np.conj(be)
                return (LAM * (2 * z * w * al - z**2 * cb),
                        LAM * (2 * a2 * al - 2 * z * w * be + z**2 * ca - 2 * z * cw * cb),
                        LAM * (-2 * a2 * be + 2 * cz * cw * al + 2 * z * cw * ca - cw**2 * cb),
                        LAM * (-2 * cz * cw * be + cw**2 * ca))

            c0, c1 = coup(rho, rho), coup(rho1, -rho1)
            terms = [(b3, 0, A0 + c0[0]), (b3, 1, A1 + c1[0]), (-b3, 0, B0 + c0[3]), (-b3, 1, B1 + c1[3]),
                     (b1, 0, c0[1]), (b1, 1, c1[1]), (-b1, 0, c0[2]), (-b1, 1, c1[2])]
        rsh = F(rs0)
        rt = self.sn / self.De * rsh
        rst = self.cc * rsh
        for beta, m, g in terms:
            gh = F(g)
            rt = rt - self.rs[beta, m] * gh
            rst = rst - self.rc[beta, m] * gh
        z1, zs1, w1, ws1 = iF(zt), iF(zst), iF(wt), iF(wst)
        r1, rs1 = iF(rt), iF(rst)
        ph = self.ph
        psi1 = ph * z1 + np.conj(ph * w1) + r1
        psid1 = ph * (1j * z1 / e2 + zs1) + np.conj(ph * (1j * w1 / e2 + ws1)) + rs1
        return psi1, psid1

    def solve(self, T=0.25):
        e2 = self.e2
        u, v = kg_data(e2)
        # psi = (u + conj v)/2, psi_t = i D_e (u - conj v)/2
        psi = (u + np.conj(v)) / 2
        psid = np.fft.ifft(1j * self.De * np.fft.fft((u - np.conj(v)) / 2))
        for _ in range(int(round(T / self.tau))):
            psi, psid = self.step(psi, psid)
        Dinv_psid = np.fft.ifft(np.fft.fft(psid) / self.De)
        Dinv_cpsid = np.fft.ifft(np.fft.fft(np.conj(psid)) / self.De)
        return psi - 1j * Dinv_psid, np.conj(psi) - 1j * Dinv_cpsid


def consistency(coupling):
    """the MDF reproduces the data exactly: at s = 0, psi_0 + r = psi^n and the reconstructed
    psi_t = psid^n to rounding (checked through a zero-length step)"""
    u, v = kg_data(0.01)
    m = MTI(0.01, 1e-300, coupling)  # tau -> 0: every coefficient -> its limit
    psi = (u + np.conj(v)) / 2
    psid = np.fft.ifft(1j * m.De * np.fft.fft((u - np.conj(v)) / 2))
    p1, d1 = m.step(psi, psid)
    return np.abs(p1 - psi).max() / np.abs(psi).max(), np.abs(d1 - psid).max() / np.abs(psid).max()


def table(coupling, T=0.25):
    taus = [T / 4, T / 8, T / 16, T / 32, T / 64]
    epss = [1.0, 0.1, 0.01, 1e-3, 1e-4, 1e-6]
    t0 = time.process_time()
    print("    eps     " + "".join(f"  tau=T/{int(round(T / d)):<3d}" for d in taus) + "  orders")
    tab = {}
    for e in epss:
        ur, vr = kg_ref(e)
        errs = [rel(*MTI(e, d, coupling).solve(T), ur, vr) for d in taus]
        tab[e] = errs
        o = [np.log2(errs[i] / errs[i + 1]) for i in range(len(taus) - 1)]
        print(f"    {e:<8g}" + "".join(f"  {x:9.2e}" for x in errs) + "  " + " ".join(f"{x:5.2f}" for x in o))
    mx = [max(tab[e][j] for e in epss) for j in range(len(taus))]
    o = [np.log2(mx[i] / mx[i + 1]) for i in range(len(taus) - 1)]
    print("    max     " + "".join(f"  {x:9.2e}" for x in mx) + "  " + " ".join(f"{x:5.2f}" for x in o)
          + f"   (T/4 -> T/64: {np.log2(mx[0] / mx[-1]) / 4:.2f})")
    print(f"    ({time.process_time() - t0:.1f} s CPU)")


def main():
    for c in ("taylor", "phase"):
        a, b = consistency(c)
        print(f"zero-length step ({c}): |psi^1 - psi^0| / |psi^0| = {a:.1e}, |psid^1 - psid^0| / |psid^0| = {b:.1e}")
    print("KG CosSin, N_x = 128, T = 0.25: relative discrete L2 error of (u, v) vs micromacro-cos-sin/"
          " (eps = MicroMacro.jl's eps = Bao's eps^2)")
    print("  variant A (reconstruction, r-coupling Taylor in s):")
    table("taylor")
    print("  variant B (own improvement, r-coupling with the phases e^{+-i s/eps}, e^{+-3i s/eps} resolved):")
    table("phase")


if __name__ == "__main__":
    main()
