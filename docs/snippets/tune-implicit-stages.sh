#!/usr/bin/env bash
# The fixed-point iteration of SE1's and SE2's implicit stages: Picard or Anderson, and what
# happens to a stage that does not converge.
set -euo pipefail

cp "$TSI_SOURCE_DIR/examples/hh-se1.json" .
tsi run hh-se1.json --set time.h=0.5 --set time.t_end=10 --out out/picard
tsi run hh-se1.json --set time.h=0.5 --set time.t_end=10 --set scheme.solver=anderson --out out/anderson
/usr/bin/python3 -c "
import json
for d in ('picard', 'anderson'):
    s = json.load(open(f'out/{d}/result.json'))['solver']
    print(d, s['iterations_mean'], s['iterations_max'], s['not_converged'], s['sweeps_histogram'])"

# A stage that misses tol within max_iter is counted and the run goes on (on_failure: warn) ...
tsi run hh-se1.json --set scheme.max_iter=5 --out out/warn
# ... or the run stops there as failed (exit code 1), its files written up to the stop.
tsi run hh-se1.json --set scheme.max_iter=5 --set scheme.on_failure=stop --out out/stop || echo "exit code $?"
