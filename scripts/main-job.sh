#!/usr/bin/env bash
# The main job: builds tsi and runs the paper's Henon-Heiles pair side by side for the four
# two-scale schemes: convergence (errors and observed orders per scheme and eps) and
# long-time conservation, with tables on the terminal and plots in out/.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out}"
"$root/scripts/build.sh"
"$root/build/bin/tsi" study "$root/examples/paper/hh-convergence.json" --out "$out/hh-convergence"
echo
"$root/build/bin/tsi" study "$root/examples/paper/hh-conservation.json" --out "$out/hh-conservation"
