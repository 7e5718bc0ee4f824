#!/usr/bin/env bash
# An error estimate without a reference: Richardson's, from the same run at h/2 and 2h.
set -euo pipefail

cat > linear-test.json <<'JSON'
{"model": {"name": "matrix", "f": "linear", "eps": 0.0015},
 "reformulation": {"name": "two-scale", "n_tau": 32},
 "scheme": {"name": "eab", "order": 4},
 "time": {"h": 0.0625, "t_end": 1},
 "output": {"error_estimate": "richardson"}}
JSON
tsi run linear-test.json --out out/estimate

# With the model's exact solution as reference as well, the estimate is compared with the error.
tsi run linear-test.json --set reference.scheme=exact --out out/estimate-and-error
/usr/bin/python3 -c "
import json
e = json.load(open('out/estimate-and-error/result.json'))['error_estimate']
print({k: e[k] for k in ('relative', 'observed_order', 'asymptotic', 'ratio_to_error')})"
