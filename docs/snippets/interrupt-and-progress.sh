#!/usr/bin/env bash
# Before a long run: a dry run. During it: progress and checkpoints. Stopping it: Ctrl-C (SIGINT).
set -euo pipefail

cat > long.json <<'JSON'
{"model": {"name": "henon-heiles", "eps": 0.01},
 "scheme": {"name": "se1"},
 "time": {"h": 0.001, "t_end": 10000},
 "output": {"every": 100, "checkpoint_seconds": 1}}
JSON

# What it would cost, checked as the run would be, nothing written.
tsi run long.json --dry-run

# Too many steps for the default limit of 1e9? Here the limit is lowered to show the refusal.
tsi run long.json --max-steps 1e6 || echo "exit code $?"

# Start it (off a terminal the progress line is a plain line every 30 s; --quiet for none),
# and interrupt it after two seconds as Ctrl-C would.
tsi run long.json --out out/long --quiet &
pid=$!
sleep 2
kill -INT "$pid"
status=0
wait "$pid" || status=$?
echo "exit code $status"                       # 130 = 128 + SIGINT

# What was computed up to the stop is written: result.json says how far it got.
/usr/bin/python3 - <<'PY'
import json
r = json.load(open("out/long/result.json"))
print(r["status"], r["t_reached"], r["steps"], r["message"])
PY
tail -n 2 out/long/invariants.csv
