#!/usr/bin/python3
"""An integrating-factor pseudo-spectral solve of Klein-Gordon with complex z (SPEC.md section 8),
independent of tsi: the (u, v) form

    u_t = (i/eps) <D> u + i lambda <D>^{-1} (|z|^2 z),   v_t = (i/eps) <D> v + i lambda <D>^{-1} conj(|z|^2 z),
    z = (u + conj v) / 2,   <D> = (1 - eps d_xx)^{1/2},

on 128 points of [0, 2 pi), CosSin data (z = (1+i) cos x, eps z_t = (1-i) sin x, lambda = 1), to
T = 0.25 with DOP853 at rtol = atol = 1e-12 on e^{-i t <D>/eps} (u, v) in Fourier. Compared with
MicroMacro.jl's published reference solutions (micromacro-cos-sin/, from the repository
JuliaVlasov/MicroMacro.jl, test/donnees_data3_128_micmac/ at commit a9397f7, MIT licence):

    /usr/bin/python3 tests/data/rivals/kg_complex_if_solve.py 1 0.1 0.01 0.001
    /usr/bin/python3 tests/data/rivals/kg_complex_if_solve.py --bao-dong 1 0.1

(the second writes kg-complex-bao-dong/, Bao and Dong's data on a box of length 16, lambda = 4,
for tsi's test of the model's `length` and `bao-dong` data)

prints, per eps, the relative discrete L2 difference of (u, v) from the reference (1.7e-14,
1.4e-14, 3.0e-14, 2.2e-14 on the development machine) and from the same solve at 1e-10 (1.6e-12
to 3.1e-12). Smaller eps take this solver ever more steps (the phases e^{2 i t/eps} of the
nonlinearity)."""
import sys

import numpy as np
from scipy.integrate import solve_ivp

N = 128
x = np.arange(N) * 2 * np.pi / N
k = np.fft.fftfreq(N, 1.0 / N)
LAMBDA = 1.0
FILES = {1.0: "1", 0.1: "0_1", 0.01: "0_01", 0.001: "0_001"}


def solve(eps, t_end=0.25, tol=1e-12, data="cos-sin", length=2 * np.pi, lam=LAMBDA):
    """(u, v) at t_end on N points of [0, length); data "cos-sin" or "bao-dong" (z = sech(x^2)
    centred in the box, eps z_t = 0)."""
    xs = np.arange(N) * length / N
    ks = np.fft.fftfreq(N, 1.0 / N) * (2 * np.pi / length)
    d = np.sqrt(1 + eps * ks**2)  # the symbol of <D>
    omega = d / eps
    if data == "bao-dong":
        c = xs - length / 2
        z0, p0 = 2 / (np.exp(c**2) + np.exp(-c**2)) + 0j, np.zeros(N, complex)
    else:
        z0, p0 = (1 + 1j) * np.cos(xs), (1 - 1j) * np.sin(xs)  # z and eps z_t
    u0 = z0 - 1j * np.fft.ifft(np.fft.fft(p0) / d)
    v0 = np.conj(z0) - 1j * np.fft.ifft(np.fft.fft(np.conj(p0)) / d)

    def rhs(t, w):
        phase = np.exp(1j * omega * t)
        u, v = np.fft.ifft(w[:N] * phase), np.fft.ifft(w[N:] * phase)
        z = (u + np.conj(v)) / 2
        f = lam * np.abs(z) ** 2 * z
        return np.concatenate([1j * np.fft.fft(f) / d / phase, 1j * np.fft.fft(np.conj(f)) / d / phase])

    w0 = np.concatenate([np.fft.fft(u0), np.fft.fft(v0)])
    w = solve_ivp(rhs, (0, t_end), w0, method="DOP853", rtol=tol, atol=tol).y[:, -1]
    phase = np.exp(1j * omega * t_end)
    return np.fft.ifft(w[:N] * phase), np.fft.ifft(w[N:] * phase)


def main():
    here = __file__.rsplit("/", 1)[0]
    if sys.argv[1:2] == ["--bao-dong"]:
        # Bao and Dong's data on [-8, 8) (length 16), lambda = 4: (u, v) at T = 0.25 written as
        # the reference files' layout (Re u, Im u, Re v, Im v a line) for tsi's test.
        for eps in (float(a) for a in sys.argv[2:]):
            u, v = solve(eps, data="bao-dong", length=16.0, lam=4.0)
            u2, v2 = solve(eps, data="bao-dong", length=16.0, lam=4.0, tol=1e-10)
            norm = np.sqrt(np.sum(np.abs(u) ** 2 + np.abs(v) ** 2))
            self_diff = np.sqrt(np.sum(np.abs(u - u2) ** 2 + np.abs(v - v2) ** 2)) / norm
            name = f"{here}/kg-complex-bao-dong/eps_{eps:g}.txt".replace("eps_0.", "eps_0_")
            np.savetxt(name, np.column_stack([u.real, u.imag, v.real, v.imag]), fmt="%.17e")
            print(f"eps = {eps:g}: written {name}; against tol 1e-10 {self_diff:.2e}")
        return
    for eps in (float(a) for a in sys.argv[1:]):
        ref = np.loadtxt(f"{here}/micromacro-cos-sin/donnee_{FILES[eps]}.txt")
        u_ref, v_ref = ref[:, 0] + 1j * ref[:, 1], ref[:, 2] + 1j * ref[:, 3]
        norm = np.sqrt(np.sum(np.abs(u_ref) ** 2 + np.abs(v_ref) ** 2))
        u, v = solve(eps)
        u2, v2 = solve(eps, tol=1e-10)
        diff = np.sqrt(np.sum(np.abs(u - u_ref) ** 2 + np.abs(v - v_ref) ** 2)) / norm
        self_diff = np.sqrt(np.sum(np.abs(u - u2) ** 2 + np.abs(v - v2) ** 2)) / norm
        print(f"eps = {eps:g}: against MicroMacro.jl {diff:.2e}, against tol 1e-10 {self_diff:.2e}")


if __name__ == "__main__":
    main()
