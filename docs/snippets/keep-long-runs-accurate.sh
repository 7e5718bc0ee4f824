#!/usr/bin/env bash
# Long runs at moderate eps: watch the tau monitors, and re-prepare the two-scale data.
set -euo pipefail

# The charged particle at eps = 1 with SE2, h = 1/5, up to t = 200: the tau characteristics
# of U come apart, the monitor warns, and the run blows up.
cat > cpd-long.json <<'JSON'
{"model": {"name": "cpd", "eps": 1},
 "reformulation": {"name": "two-scale", "n_tau": 64},
 "scheme": {"name": "se2"},
 "time": {"h": 0.2, "t_end": 200},
 "output": {"every": 5}}
JSON
tsi run cpd-long.json --out out/never || echo "exit code $?"

# Re-prepared when U drifts from its prepared data (reformulation.reprepare = auto, data of order 4):
# H is kept to 1e-3.
tsi run cpd-long.json --set reformulation.reprepare=auto --out out/auto
/usr/bin/python3 -c "
import json
r = json.load(open('out/auto/result.json'))
print(r['status'], r['repreparations']['count'], 're-preparations, max err_H', r['invariants']['H']['max_rel_error'])"

# Or every K steps.
tsi run cpd-long.json --set reformulation.reprepare=50 --out out/every-50 --quiet | grep 'change of H'
