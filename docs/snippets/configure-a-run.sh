#!/usr/bin/env bash
# A run config: every section, its defaults, overrides from the command line, and bad input.
set -euo pipefail

# Only "model" is required; the rest takes its defaults. result.json records them all.
echo '{"model": {"name": "henon-heiles"}}' > minimal.json
tsi run minimal.json --out out/minimal --quiet
/usr/bin/python3 -c "import json; print(json.dumps(json.load(open('out/minimal/result.json'))['config'], indent=1))"

# Every section written out.
cat > full.json <<'JSON'
{"model": {"name": "henon-heiles", "eps": 0.01, "u0": [0.12, 0.12, 0.12, 0.12]},
 "reformulation": {"name": "two-scale", "n_tau": 64, "initial_data_order": 2},
 "scheme": {"name": "se1", "tol": 1e-10, "max_iter": 200},
 "time": {"h": 0.125, "t_end": 1.0},
 "reference": {"scheme": "rk78", "reformulation": "filtered", "tol": 1e-13},
 "output": {"every": 1},
 "monitor": {"max_err_H": 10},
 "plugins": []}
JSON
tsi run full.json --out out/full

# --set overrides any entry; the value is JSON, a bare word a string.
tsi run full.json --set scheme.name=se2 --set reformulation.n_tau=32 --set 'model.u0=[0.1, 0.1, 0.1, 0.1]' --out out/se2

# Check a config without running it: the resolved sections, steps, reference, memory.
tsi run full.json --set time.h=0.001 --dry-run

# Bad input is refused before anything runs, naming the field (exit code 2).
tsi run full.json --set model.eps=2 || echo "exit code $?"
tsi run full.json --set time.h=0.3 || echo "exit code $?"

# The parameters every model and scheme takes, with their defaults, as JSON.
tsi list schemes --json | /usr/bin/python3 -c "
import json, sys
for s in json.load(sys.stdin)['schemes']:
    print(s['name'], [p['name'] for p in s['params']])"
