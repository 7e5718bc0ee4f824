#!/usr/bin/env bash
# Configures and builds tsi (Release, warnings as errors) in build/.
#   scripts/build.sh [TARGET...]     (no target: everything, the test suite included)
# The main job builds only `tsi tsi_plugins` (the runner and the shipped plugins). A compiler
# cache is used when ccache is on the PATH (never required; TSI_CCACHE=0 turns it off).
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=)
if [ "${TSI_CCACHE:-1}" != 0 ] && command -v ccache >/dev/null; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$root"  # hits across clones and build directories of the same sources
  export CCACHE_SLOPPINESS="pch_defines,time_macros,include_file_mtime,include_file_ctime"  # the test suites' PCH
fi
cmake -S "$root" -B "$root/build" -G Ninja -DCMAKE_BUILD_TYPE=Release "${launcher[@]}" >/dev/null
targets=()
for t in "$@"; do targets+=(--target "$t"); done
cmake --build "$root/build" -j "$(nproc)" "${targets[@]}" >&2
