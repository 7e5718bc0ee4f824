#!/usr/bin/env bash
# A study: a base config, lists of values, cases with settings of their own; the three kinds.
set -euo pipefail

# Convergence: the two-scale schemes over h, and rk78 on the direct problem over its tolerance.
# The top-level lists apply to every case; a case adds lists and settings of its own.
cat > convergence.json <<'JSON'
{"kind": "convergence",
 "title": "Henon-Heiles at T = 1",
 "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
 "vary": {"model.eps": [0.01, 0.0001]},
 "cases": [{"vary": {"scheme.name": ["se1", "me"], "time.h": [0.25, 0.125, 0.0625]}},
           {"label": "rk78",
            "set": {"scheme": {"name": "rk78"}, "reformulation.name": "direct", "time.h": 1},
            "vary": {"scheme.tol": [1e-6, 1e-8]}}]}
JSON
tsi study convergence.json --dry-run | tail -n 4
tsi study convergence.json --out out/convergence --jobs 2 --no-plots

# --set changes the base; a path the study varies is refused, naming the list.
tsi study convergence.json --set model.eps=0.1 --out out/refused || echo "exit code $?"
tsi study convergence.json --set reformulation.n_tau=32 --out out/n-tau-32 --no-plots --quiet

# Conservation: the largest change of H, I, m (and each model's own invariants) and their drift.
cat > conservation.json <<'JSON'
{"kind": "conservation",
 "base": {"model": {"name": "henon-heiles", "eps": 0.01}, "time": {"h": 0.2, "t_end": 50}},
 "vary": {"scheme.name": ["se1", "se2", "fd", "me"]}}
JSON
tsi study conservation.json --out out/conservation --no-plots

# Work-precision: error against wall time and evaluations; the time to reach 1e-4 and 1e-6.
cat > work-precision.json <<'JSON'
{"kind": "work-precision",
 "base": {"model": {"name": "henon-heiles", "eps": 0.0001}, "time": {"t_end": 1}, "reference": {}},
 "vary": {"scheme.name": ["se1", "fd"], "time.h": [0.25, 0.125, 0.0625, 0.03125, 0.015625]}}
JSON
tsi study work-precision.json --out out/work-precision --jobs 1 --no-plots
