#!/usr/bin/env bash
# A first run of examples/hh-se1.json and the files it writes (docs/reference/outputs.md).
set -euo pipefail
cp "$TSI_SOURCE_DIR/examples/hh-se1.json" .
tsi run hh-se1.json --out out/hh-se1 --quiet
ls out/hh-se1
head -n 3 out/hh-se1/invariants.csv
/usr/bin/python3 -c 'import json; r = json.load(open("out/hh-se1/result.json")); print(r["status"], r["steps"], r["error"]["relative"])'
