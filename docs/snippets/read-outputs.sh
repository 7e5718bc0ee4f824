#!/usr/bin/env bash
# Writes a run and a study, then reads them in Python (docs/snippets/read-outputs.py).
set -euo pipefail
tsi run "$TSI_SOURCE_DIR/examples/hh-se1.json" --out out/run --quiet > /dev/null
cat > study.json <<'JSON'
{"kind": "convergence",
 "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
 "vary": {"scheme.name": ["se1", "fd"], "model.eps": [1, 0.001], "time.h": [0.25, 0.125, 0.0625]}}
JSON
tsi study study.json --out out/study --no-plots --quiet > /dev/null
ls out/run out/study
/usr/bin/python3 "$TSI_SOURCE_DIR/docs/snippets/read-outputs.py"
