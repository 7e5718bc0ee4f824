#!/usr/bin/env bash
# Large runs: what they will need before they start, threads on the tau grid, and sparse records.
set -euo pipefail

# 3-D NLS on 256^3 points with n_tau = 64: the dry run gives the memory at the peak, and a
# run that does not fit the memory available is refused before anything is allocated.
cat > nls-3d.json <<'JSON'
{"model": {"name": "nls", "dims": 3, "n_x": 256},
 "reformulation": {"name": "two-scale", "n_tau": 64},
 "time": {"h": 0.125, "t_end": 1}}
JSON
tsi run nls-3d.json --dry-run || echo "exit code $?"

# 2-D NLS on 256 x 256 points, n_tau = 32: two steps on two threads, a record only at the end
# (output.every large: between records a step only checks the state is finite).
cat > nls-2d.json <<'JSON'
{"model": {"name": "nls", "dims": 2, "n_x": 256},
 "reformulation": {"name": "two-scale", "n_tau": 32},
 "scheme": {"name": "se1"},
 "time": {"h": 0.001, "t_end": 0.002},
 "output": {"every": 1000}}
JSON
tsi --threads 2 run nls-2d.json --out out/threads-2 --quiet > /dev/null
tsi --threads 1 run nls-2d.json --out out/threads-1 --quiet > /dev/null
cmp out/threads-1/u_final.npy out/threads-2/u_final.npy && echo "the same answer on 1 and 2 threads"
/usr/bin/python3 -c "
import json
r = json.load(open('out/threads-2/result.json'))
print('threads', r['threads'], 'memory', r['memory'], 'wall', r['wall_seconds'])"
