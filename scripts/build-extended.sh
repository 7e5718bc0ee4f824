#!/usr/bin/env bash
# Configures and builds tsi in extended precision (TSI_PRECISION=long-double: tsi::Real is x87
# long double) in build-extended/: the core, every plugin, the runner and the extended suite
# (tests/extended). Prints the runner's path.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
cmake -S "$root" -B "$root/build-extended" -G Ninja -DCMAKE_BUILD_TYPE=Release -DTSI_PRECISION=long-double \
      -DTSI_BUILD_PYTHON=OFF -DTSI_BUILD_BENCH=OFF >/dev/null
cmake --build "$root/build-extended" -j "$(nproc)" >&2
echo "$root/build-extended/bin/tsi"
