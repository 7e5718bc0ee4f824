#!/usr/bin/env bash
# eab of order 6 on HOODESolver.jl's linear test against its exact solution: the double build
# stops at its rounding floor; a long-double or quad build goes on with the same config.
set -euo pipefail

cat > linear-test.json <<'JSON'
{"model": {"name": "matrix", "f": "linear", "eps": 1.5e-5},
 "reformulation": {"name": "two-scale", "n_tau": 32},
 "scheme": {"name": "eab", "order": 6},
 "time": {"h": 0.001953125, "t_end": 1},
 "reference": {"scheme": "exact"}}
JSON
# Give h exactly: 1/512 is a double; 0.1 would be 0.1 + 5.6e-18 and so would t_end be off.
tsi run linear-test.json --out out/double

# The extended-precision runners, where scripts/build-extended.sh has built them in the source tree.
for precision in long-double quad; do
  runner="$TSI_SOURCE_DIR/build-$precision/bin/tsi"
  if [ -x "$runner" ]; then
    "$runner" run linear-test.json --out "out/$precision"
  else
    echo "no $precision build in $TSI_SOURCE_DIR/build-$precision: scripts/build-extended.sh $precision makes it"
  fi
done
