"""Run resting-dove/gautschiIntegrators (exported to /tmp/gautschi-src, never copied into tsi) on SPEC.md's FPUT
data and compare with the independent implementation trig_onestep.py.  Writes gautschi-fput-reference.json.
Run:  PYTHONPATH=/tmp/gautschi-src:/tmp/gautschi-shim OPENBLAS_NUM_THREADS=1 nice -n 19 /usr/bin/python3 run_gautschi_pkg.py
(/tmp/gautschi-shim/pywkm.py: a copy of pywkm_standin.py, a stand-in for the private PyWKM; imported by the
package but not used by the runs below.)"""
import json, math, os, sys, time
import numpy as np
import scipy, scipy.sparse, scipy.linalg
if not hasattr(scipy.sparse, "sparray"):   # Debian scipy 1.10: the package's type hints name scipy.sparse.sparray
    scipy.sparse.sparray = scipy.sparse.csr_array
from gautschiIntegrators import one_step, two_step
from gautschiIntegrators.integrate import solve_ivp
from gautschiIntegrators.matrix_functions import SymDiagonalizationEvaluator, TridiagDiagonalizationEvaluator
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from trig_onestep import FILTERS, make_stepper, fput, sinc

m, omega = 3, 50.0
w, g, H, I, x0, v0 = fput(m, omega)
Omega2 = scipy.sparse.csr_array(np.diag(w ** 2))
HS = {"0.03": 0.03, "pi/omega": math.pi / omega, "0.1": 0.1, "2pi/omega": 2 * math.pi / omega}
PKG = {"OneStepF": one_step.OneStepF, "OneStepGS99": one_step.OneStepGS99, "OneStep217": one_step.OneStep217}
MINE_OF = {"OneStepF": "E_hairerlubich2000", "OneStepGS99": "C_gss1999", "OneStep217": "own_217"}

def pkg_run(cls, h, N, evaluator=SymDiagonalizationEvaluator, record=None):
    s = cls(h, np.inf, x0.copy(), v0.copy(), g, evaluator=evaluator())   # t_end = inf: exactly N steps of size h
    out = {}
    for n in range(1, N + 1):
        s.step(Omega2)
        if record and n in record: out[n] = (s.x.copy(), s.v.copy())
    return s, out

def own_217(h):   # independent reading of the package's OneStep217 (HL2000 eq. (2.17)), see gautschi.md
    z = h * w; c, sn, ws = np.cos(z), sinc(z), w * np.sin(z)
    gt = lambda x: g(x) + sn * g(x) - g(sn * x)
    def step(x, v, gn=None):
        gn = gt(x) if gn is None else gn
        x1 = c * x + h * sn * v + 0.5 * h * h * sn * gn; g1 = gt(x1)
        return x1, -ws * x + c * v + 0.5 * h * (c * gn + g1), g1
    return step

def own_run(name, h, N, record=()):
    step = own_217(h) if name == "own_217" else make_stepper(w, h, g, name)
    x, v, gn, out, dH, dI = x0, v0, None, {}, 0.0, 0.0
    H0, I0 = H(x0, v0), I(x0, v0)
    with np.errstate(all="ignore"):
        for n in range(1, N + 1):
            x, v, gn = step(x, v, gn)
            if n in record: out[n] = (x, v)
            dH, dI = max(dH, abs(H(x, v) - H0)), max(dI, abs(I(x, v) - I0))
    return out, dH, dI

def fin(a): return [float(t) if np.isfinite(t) else None for t in np.atleast_1d(a)]
def entry(x, v):
    with np.errstate(all="ignore"): hh, ii = H(x, v), I(x, v)
    return {"x": fin(x), "v": fin(v), "H": fin(hh)[0], "I": fin(ii)[0]}

ref = {"_meta": {"package": "resting-dove/gautschiIntegrators", "commit": "8320204bd515eb73c0f2455555a1be939f6f06f0",
                 "problem": "SPEC.md 8 FPUT, m=3, omega=50, x=[x1..x6] slow then stiff, v=x'",
                 "h": {k: repr(v) for k, v in HS.items()}, "H0": float(H(x0, v0)), "I0": float(I(x0, v0)),
                 "evaluator": "SymDiagonalizationEvaluator", "steps": [1, 1000]}}
cmp_lines = []
for name, cls in PKG.items():
    ref[name] = {}
    for hk, h in HS.items():
        _, out = pkg_run(cls, h, 1000, record={1, 1000})
        ref[name][hk] = {str(n): entry(*out[n]) for n in (1, 1000)}
        mine, _, _ = own_run(MINE_OF[name], h, 1000, record={1, 1000})
        for n in (1, 1000):
            dx = np.max(np.abs(out[n][0] - mine[n][0])); dv = np.max(np.abs(out[n][1] - mine[n][1]))
            cmp_lines.append(f"{name:12s} vs {MINE_OF[name]:20s} h={hk:9s} n={n:4d}  max|dx|={dx:.3e} max|dv|={dv:.3e}")
for name in FILTERS:
    ref[name] = {}
    for hk, h in HS.items():
        mine, _, _ = own_run(name, h, 1000, record={1, 1000})
        ref[name][hk] = {str(n): entry(*mine[n]) for n in (1, 1000)}
print("H(0) = %.17g  I(0) = %.17g" % (H(x0, v0), I(x0, v0)))
print("\n".join(cmp_lines))

# Tridiagonal evaluator gives the same numbers?
_, a = pkg_run(one_step.OneStepF, 0.03, 1000, record={1000})
_, b = pkg_run(one_step.OneStepF, 0.03, 1000, evaluator=TridiagDiagonalizationEvaluator, record={1000})
print("OneStepF Sym vs Tridiag evaluator, h=0.03 n=1000: max|dx| = %.3e" % np.max(np.abs(a[1000][0] - b[1000][0])))

# the package's own driver solve_ivp with t_end = 1000 h
for hk in ("0.03", "0.1"):
    h = HS[hk]
    r = solve_ivp(Omega2, g, h, 1000 * h, x0.copy(), v0.copy(), "OneStepF", evaluator=SymDiagonalizationEvaluator())
    d = np.max(np.abs(r["x"] - np.array(ref["OneStepF"][hk]["1000"]["x"])))
    print(f"solve_ivp OneStepF h={hk}: t={r['t']!r} steps={r['iterations']} last ts={r['ts'][-2:]} max|dx| vs exact 1000 steps={d:.3e}")

# two-step forms, seeded with the exact one-step start (x1, v1), vs the one-step forms after 1000 steps
for two, one in ((two_step.TwoStepIntegratorF, one_step.OneStepF), (two_step.TwoStepIntegrator2_16, one_step.OneStep217)):
    h = 0.03
    s1, out = pkg_run(one, h, 1000, record={1, 1000})
    t = two(h, np.inf, out[1][0], out[1][1], g, evaluator=SymDiagonalizationEvaluator())
    t.prev_x, t.prev_v, t.t = x0.copy(), v0.copy(), h
    t.prev_g_x, t.curr_g_x = g(x0), g(out[1][0])
    for n in range(2, 1001): t.step(Omega2)
    print(f"{two.__name__} seeded by {one.__name__}(1 step), h=0.03 n=1000: max|dx|={np.max(np.abs(t.x - out[1000][0])):.3e}"
          f" max|dv|={np.max(np.abs(t.v - out[1000][1])):.3e}")
    t2, _ = pkg_run(two, h, 1000)   # as shipped: first step by scipy RK45 (rtol 1e-3)
    print(f"{two.__name__} as shipped (RK45 first step), h=0.03 n=1000: max|dx| vs one-step = {np.max(np.abs(t2.x - out[1000][0])):.3e}")

# long time T = 1000: max |H - H0|, |I - I0|
long = {}
for hk, N in (("0.03", round(1000 / 0.03)), ("2pi/omega", round(1000 / HS["2pi/omega"])), ("pi/omega", round(1000 / HS["pi/omega"]))):
    for name in list(FILTERS) + ["own_217"]:
        t0 = time.time(); _, dH, dI = own_run(name, HS[hk], N)
        long.setdefault(name, {})[hk] = {"N": N, "T": N * HS[hk], "maxdH": fin(dH)[0], "maxdI": fin(dI)[0]}
        print(f"long  {name:24s} h={hk:9s} N={N:6d} T={N*HS[hk]:.4f}  max|H-H0|={dH:.3e}  max|I-I0|={dI:.3e}  ({time.time()-t0:.1f}s)")
# one package long run to confirm the own runs stand for it
t0 = time.time(); s = one_step.OneStepF(0.03, np.inf, x0.copy(), v0.copy(), g, evaluator=SymDiagonalizationEvaluator())
dH = dI = 0.0
for n in range(round(1000 / 0.03)):
    s.step(Omega2); dH, dI = max(dH, abs(H(s.x, s.v) - H(x0, v0))), max(dI, abs(I(s.x, s.v) - 1.0))
print(f"long  package OneStepF h=0.03 N=33333: max|H-H0|={dH:.3e} max|I-I0|={dI:.3e} ({time.time()-t0:.1f}s)")
ref["_long_T1000_own"] = long
with open(os.path.join(os.path.dirname(os.path.abspath(__file__)), "gautschi-fput-reference.json"), "w") as f:
    json.dump(ref, f, indent=1)
