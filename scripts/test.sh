#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs the whole suite with ctest:
# the double build's (build/), then the extended-precision build's (build-extended/,
# tests/extended). Extra arguments go to the first ctest.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
ctest --test-dir "$root/build" -j "$(nproc)" --output-on-failure "$@"
"$root/scripts/build-extended.sh" >/dev/null
ctest --test-dir "$root/build-extended" -j "$(nproc)" --output-on-failure
