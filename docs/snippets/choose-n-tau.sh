#!/usr/bin/env bash
# Choose n_tau: double it until the error stops changing, and read the run's tau monitors.
set -euo pipefail

# NLS at eps = 1 (n_x = 16): the cubic term has tau frequencies up to 2 (n_x/2)^2 = 128,
# so n_tau = 4 (n_x/2)^2 = 256 resolves it exactly. A small h isolates the tau error.
cat > n-tau.json <<'JSON'
{"kind": "convergence",
 "base": {"model": {"name": "nls", "eps": 1}, "scheme": {"name": "se1"},
          "time": {"h": 0.015625, "t_end": 1}, "reference": {}},
 "vary": {"reformulation.n_tau": [32, 64, 128, 256, 512]}}
JSON
tsi study n-tau.json --out out/n-tau --no-plots --quiet > /dev/null

# The error falls to the step's own once n_tau resolves f_tau; the largest fraction of U's
# energy in the top quarter of its tau spectrum (tau_roughness_max) says the same per run.
/usr/bin/python3 - <<'PY'
import csv, json
for row in csv.DictReader(open("out/n-tau/table.csv")):
    r = json.load(open(f"out/n-tau/runs/{row['id']}/result.json"))
    print(f"n_tau {row['n_tau']:>4}: error {float(row['error']):.2e}, tau_roughness_max {r['tau_roughness_max']:.1e}")
PY

# A run whose U roughens in tau warns while it runs (monitor.tau_roughness_warn, default 1e-10).
tsi run "$TSI_SOURCE_DIR/examples/hh-se1.json" --set model.eps=1 --set time.t_end=100 --set time.h=0.25 \
  --set reformulation.n_tau=16 --out out/rough
