#!/usr/bin/env bash
# Configures and builds tsi in extended precision: TSI_PRECISION=quad (default; tsi::Real is
# IEEE quadruple precision, Boost.Multiprecision's float128 over libquadmath) or long-double
# (x87, 64-bit significand), in build-quad/ or build-long-double/. Builds the runner, the
# plugins the extended suite needs (tests/extended) and the suite; `cmake --build DIR` builds
# every plugin. Prints the runner's path.
#   scripts/build-extended.sh [quad|long-double]
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
precision="${1:-quad}"
case "$precision" in
  quad|long-double) ;;
  *) echo "build-extended.sh: precision '$precision', expected quad or long-double" >&2; exit 2 ;;
esac
dir="$root/build-$precision"
"$root/scripts/install-deps.sh"
cmake -S "$root" -B "$dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTSI_PRECISION="$precision" \
      -DTSI_BUILD_PYTHON=OFF -DTSI_BUILD_BENCH=OFF >/dev/null
cmake --build "$dir" -j "$(nproc)" --target tsi tsi_extended_tests >&2
echo "$dir/bin/tsi"
