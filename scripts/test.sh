#!/usr/bin/env bash
# The test command: installs what is missing, builds, and runs the whole suite with ctest:
# the double build's (build/), then the extended-precision suite (tests/extended) in quad
# (build-quad/) and in long double (build-long-double/). Extra arguments go to the first ctest.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/build.sh"
ctest --test-dir "$root/build" -j "$(nproc)" --output-on-failure "$@"
for precision in quad long-double; do
  "$root/scripts/build-extended.sh" "$precision" >/dev/null
  ctest --test-dir "$root/build-$precision" -j "$(nproc)" --output-on-failure
done
