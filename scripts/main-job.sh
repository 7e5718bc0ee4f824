#!/usr/bin/env bash
# The main job: builds the runner and the shipped plugins (not the test suite) and runs the
# paper's Henon-Heiles pair side by side for the four two-scale schemes: convergence (errors
# and observed orders per scheme and eps) and long-time conservation, with tables on the
# terminal and plots in out/.
#   scripts/main-job.sh [OUT_DIR]      (default: out/)
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
out="${1:-$root/out}"
step() { printf '\n== %s\n' "$*" >&2; }
start=$SECONDS
step "main job: building the runner and the plugins (Release, build/; the test suite is built by scripts/test.sh)"
"$root/scripts/build.sh" tsi tsi_plugins
step "built in $((SECONDS - start)) s; convergence at t = 1, eps from 1 to 1e-6 (examples/paper/hh-convergence.json)"
"$root/build/bin/tsi" study "$root/examples/paper/hh-convergence.json" --out "$out/hh-convergence"
step "long-time conservation up to t = 200 (examples/paper/hh-conservation.json)"
"$root/build/bin/tsi" study "$root/examples/paper/hh-conservation.json" --out "$out/hh-conservation"
step "main job done in $((SECONDS - start)) s: tables above, plots and files in $out/"
