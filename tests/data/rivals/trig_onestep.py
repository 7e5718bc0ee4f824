"""Independent numpy implementation of SPEC.md section 8's one-step trigonometric (Gautschi-type) form
(GNI XIII.2.2) for x'' = -Omega^2 x + g(x), Omega diagonal (given as the vector w of its diagonal):
  x1 = cos(hW) x + h sinc(hW) v + h^2/2 Psi g(Phi x)
  v1 = -W sin(hW) x + cos(hW) v + h/2 (Psi0 g(Phi x) + Psi1 g(Phi x1))
psi = sinc*psi1, psi0 = cos*psi1, sinc(z) = sin(z)/z (NOT numpy's normalized sinc).  Written from SPEC.md only.
Also the FPUT model of SPEC.md (GNI I.5.1 / XIII.2.1) in the variables x (slow x_1..x_m, stiff x_{m+1}..x_{2m})."""
import numpy as np

def sinc(z): return np.sinc(np.asarray(z) / np.pi)          # sin(z)/z, = 1 at 0
def tanc_half(z):                                              # tan(z/2)/(z/2) = sinc^2(z/2)/sinc(z), = 1 at 0
    z = np.asarray(z, float); zs = np.where(z == 0, 1.0, z)
    return np.where(z == 0, 1.0, np.tan(zs / 2) / (zs / 2))

# name: (psi, phi, psi1); psi0 = cos * psi1.  psi1 = psi / sinc written in closed form (A, D: singular at z = pi, 3pi, ...)
FILTERS = {
    "A_gautschi1961":     (lambda z: sinc(z / 2) ** 2, lambda z: np.ones_like(z), tanc_half),
    "B_deuflhard1979":    (sinc,                       lambda z: np.ones_like(z), lambda z: np.ones_like(z)),
    "C_gss1999":          (lambda z: sinc(z) ** 2,     sinc,                      sinc),
    "D_hochbrucklubich1999": (lambda z: sinc(z / 2) ** 2, lambda z: sinc(z) * (1 + np.sin(z / 2) ** 2 / 3), tanc_half),
    "E_hairerlubich2000": (lambda z: sinc(z) ** 2,     lambda z: np.ones_like(z), sinc),
}

def make_stepper(w, h, g, name):
    psi, phi, psi1 = FILTERS[name]; z = h * np.asarray(w, float)
    c, s, Psi, Phi, P1 = np.cos(z), sinc(z), psi(z), phi(z), psi1(z)
    P0, wsin = c * P1, np.asarray(w, float) * np.sin(z)
    def step(x, v, gn=None):          # gn = g(Phi x) may be passed from the previous step (FSAL)
        gn = g(Phi * x) if gn is None else gn
        x1 = c * x + h * s * v + 0.5 * h * h * Psi * gn
        g1 = g(Phi * x1)
        v1 = -wsin * x + c * v + 0.5 * h * (P0 * gn + P1 * g1)
        return x1, v1, g1
    return step

def fput(m=3, omega=50.0):
    """Omega diagonal, g = -grad U, H, I, x0, v0 of SPEC.md section 8 (FPUT)."""
    w = np.r_[np.zeros(m), omega * np.ones(m)]
    def terms(x):                     # t_0 = x_1 - x_{m+1}; t_i = x_{i+1}-x_{m+i+1}-x_i-x_{m+i}; t_m = -(x_m + x_2m)
        a, b = np.r_[0.0, x[:m], 0.0], np.r_[0.0, x[m:], 0.0]
        return a[1:] - a[:-1] - b[1:] - b[:-1]
    def U(x): return 0.25 * np.sum(terms(x) ** 4)
    def g(x):
        t3 = terms(x) ** 3
        return -np.r_[t3[:-1] - t3[1:], -t3[:-1] - t3[1:]]
    def H(x, v): return 0.5 * v @ v + 0.5 * omega ** 2 * x[m:] @ x[m:] + U(x)
    def I(x, v): return 0.5 * np.sum(v[m:] ** 2 + omega ** 2 * x[m:] ** 2)
    x0 = np.zeros(2 * m); v0 = np.zeros(2 * m)
    x0[0], v0[0], x0[m], v0[m] = 1.0, 1.0, 1.0 / omega, 1.0
    return w, g, H, I, x0, v0

if __name__ == "__main__":
    w, g, H, I, x0, v0 = fput()
    print("H(0) = %.17g  I(0) = %.17g" % (H(x0, v0), I(x0, v0)))
    for name in FILTERS:
        step = make_stepper(w, 0.03, g, name); x, v, gn = x0, v0, None
        for n in range(1000): x, v, gn = step(x, v, gn)
        print("%-24s h=0.03 n=1000  H=%.17g  I=%.17g" % (name, H(x, v), I(x, v)))
