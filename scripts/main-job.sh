#!/usr/bin/env bash
# The main job: builds tsi and compares schemes side by side on the paper's Henon-Heiles
# problem (errors and observed orders per eps, cost against a classical solver), with plots.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
/usr/bin/python3 "$root/scripts/compare.py" --tsi "$root/build/bin/tsi" \
  --study "$root/examples/hh-comparison.json" --out "${1:-$root/out/hh-comparison}"
