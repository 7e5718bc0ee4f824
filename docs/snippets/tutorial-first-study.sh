#!/usr/bin/env bash
# First study: two schemes over eps and h side by side, with observed orders.
set -euo pipefail

cat > hh-uniform.json <<'JSON'
{
  "kind": "convergence",
  "title": "Henon-Heiles: error at t = 1",
  "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
  "vary": {
    "scheme.name": ["se1", "fd"],
    "model.eps": [1, 0.015625, 0.000244140625],
    "time.h": [0.5, 0.25, 0.125, 0.0625, 0.03125]
  }
}
JSON

# Every run is checked before any starts; then they run on two threads.
tsi study hh-uniform.json --out out/hh-uniform --jobs 2

# One row per run, a column per varied path; each run's files under runs/.
head -n 3 out/hh-uniform/table.csv
ls out/hh-uniform out/hh-uniform/runs | sed -n 1,8p
