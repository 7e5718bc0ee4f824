#!/usr/bin/env bash
# A real model with 10^7 unknowns on one machine: the synthetic Henon-Heiles ensemble
# (bench/plugins/henon_heiles_ensemble.cpp; COPIES systems, dim 4 COPIES) on its two-scale
# problem with SE1 and eab, STEPS steps, no reference; peak memory and wall time per step from
# each run's result.json. Numbers for the README and docs/benchmarks/memory.md.
#   bench/large_real.sh [COPIES] [N_TAU] [STEPS] [OUT]
# SCHEMES (default "se1 eab") and LAYOUTS (default "true false": reformulation.real_layout)
# select the runs.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
copies="${1:-2500000}"
n_tau="${2:-16}"
steps="${3:-2}"
out="${4:-$root/out/large-real}"
tsi="$root/build/bin/tsi"
plugin="$root/build/lib/tsi/bench-plugins/tsi_henon_heiles_ensemble.so"
mkdir -p "$out"
for scheme in ${SCHEMES:-se1 eab}; do
  for layout in ${LAYOUTS:-true false}; do
    name="$scheme-real_layout-$layout"
    cat >"$out/$name.json" <<JSON
{
  "plugins": ["$plugin"],
  "model": {"name": "henon-heiles-ensemble", "eps": 0.01, "copies": $copies},
  "reformulation": {"name": "two-scale", "n_tau": $n_tau, "real_layout": $layout},
  "scheme": {"name": "$scheme"},
  "time": {"h": 0.1, "t_end": $(/usr/bin/python3 -c "print(0.1 * $steps)")},
  "output": {"every": 1000000}
}
JSON
    rm -rf "${out:?}/$name"
    if ! /usr/bin/time -o "$out/$name.time" -f "%e s, %M kB" "$tsi" run "$out/$name.json" --out "$out/$name" >"$out/$name.log" 2>&1; then
      echo "$name: failed (see $out/$name.log)"; continue
    fi
    /usr/bin/python3 - "$out/$name/result.json" "$name" "$steps" "$(cat "$out/$name.time")" <<'PY'
import json, sys
r = json.load(open(sys.argv[1]))
m = r.get("memory", {})
state = m.get("state_bytes", 0)
peak = m.get("process_peak_rss_bytes", 0)
wall = r.get("wall_seconds") or r.get("timing", {}).get("wall_seconds")
print(f"{sys.argv[2]}: state {state/1e9:.2f} GB, peak RSS {peak/1e9:.2f} GB ({peak/max(state,1):.1f} states), "
      f"stepper vectors {m.get('stepper_state_vectors')}, run {sys.argv[4]}")
PY
  done
done
