#!/usr/bin/env bash
# Where results go: the default out/<config name>, --out DIR, one study per directory, --force.
set -euo pipefail

cp "$TSI_SOURCE_DIR/examples/hh-se1.json" .
tsi run hh-se1.json --quiet > /dev/null           # into out/hh-se1/, beside the working directory
tsi run hh-se1.json --out "$PWD/results/hh" --quiet > /dev/null
ls out/hh-se1 results/hh

# One --out holds one study: the same study again replaces its runs, another is refused...
cat > a.json <<'JSON'
{"kind": "convergence", "base": {"model": {"name": "henon-heiles"}, "reference": {}},
 "vary": {"time.h": [0.25, 0.125]}}
JSON
cat > b.json <<'JSON'
{"kind": "convergence", "base": {"model": {"name": "cpd"}, "reference": {}},
 "vary": {"time.h": [0.25, 0.125]}}
JSON
tsi study a.json --out results/study --no-plots --quiet > /dev/null
tsi study a.json --out results/study --no-plots --quiet > /dev/null
tsi study b.json --out results/study --no-plots --quiet || echo "exit code $?"
# ... unless --force replaces it.
tsi study b.json --out results/study --no-plots --quiet --force > /dev/null
head -n 2 results/study/table.csv | cut -d, -f1-6

# A directory that cannot be written is refused before anything is computed (exit code 2).
touch not-a-directory
tsi run hh-se1.json --out not-a-directory/run || echo "exit code $?"

# Large states go as .npy files both ways: u0 from a file, u_final.npy written beside result.json
# (result.json names the file when the state has more than 4096 values).
/usr/bin/python3 -c "
import numpy as np
x = 2 * np.pi * np.arange(8192) / 8192
np.save('u0.npy', (np.exp(1j * x) / (1 + np.sin(x) ** 2)).astype(np.complex128))"
cat > nls-big.json <<'JSON'
{"model": {"name": "nls", "n_x": 8192, "u0": "u0.npy"},
 "reformulation": {"name": "two-scale", "n_tau": 16},
 "time": {"h": 0.125, "t_end": 0.25}}
JSON
tsi run nls-big.json --out results/nls-big --quiet > /dev/null
/usr/bin/python3 -c "
import json, numpy as np
print(json.load(open('results/nls-big/result.json'))['u_final'])
print(np.load('results/nls-big/u_final.npy').shape)"
