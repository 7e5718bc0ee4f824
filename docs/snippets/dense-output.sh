#!/usr/bin/env bash
# u at times between the steps (output.times), on the command line and from Python.
set -euo pipefail

# Steps of h = 0.25 (40 times the fast period 2 pi eps), u wanted at five times in between.
cat > hh-dense.json <<'JSON'
{"model": {"name": "henon-heiles", "eps": 0.001},
 "scheme": {"name": "se1"},
 "time": {"h": 0.25, "t_end": 2},
 "output": {"times": [0.1, 0.3, 0.7, 1.1, 1.9]}}
JSON
tsi run hh-dense.json --out out/dense
/usr/bin/python3 - <<'PY'
import json
d = json.load(open("out/dense/result.json"))["dense_output"]
print("degree", d["degree"])
for t, u in zip(d["times"], d["u"]):
    print(t, u)
PY

# From Python: times and u_times as numpy arrays (one row per time), checked here against
# runs that step exactly onto those times with a small h.
/usr/bin/python3 - <<'PY'
import numpy as np
import tsi
config = {"model": {"name": "henon-heiles", "eps": 0.001}, "scheme": {"name": "se1"},
          "time": {"h": 0.25, "t_end": 2}, "output": {"times": [0.1, 0.3, 0.7, 1.1, 1.9]}}
r = tsi.run(config)
for t, u in zip(r.times, r.u_times):
    fine = tsi.run({**config, "time": {"h": t / 64, "t_end": t}, "output": {}})
    print(f"t = {t}: u differs from a fine run by {np.linalg.norm(u - fine.u_final) / np.linalg.norm(fine.u_final):.1e}")
PY
