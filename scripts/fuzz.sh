#!/usr/bin/env bash
# Fuzzes the config and study loaders: builds fuzz/fuzz_loaders.cpp with clang, libFuzzer,
# ASan and UBSan in build-fuzz/ (installing clang and its runtime when missing) and runs it.
#   scripts/fuzz.sh [SECONDS] [extra libFuzzer flags...]      (default 60 s, one process)
# The corpus grows in build-fuzz/fuzz-corpus/ (seeded from examples/*.json and
# examples/paper/*.json); a crash, sanitizer report or uncaught non-tsi exception leaves its
# input in build-fuzz/fuzz-findings/ and exits non-zero.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
seconds="${1:-60}"
shift || true
"$root/scripts/install-deps.sh"
missing=()
for p in clang libclang-rt-14-dev; do  # libclang-rt-14-dev: libclang_rt.fuzzer, asan, ubsan
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
build="$root/build-fuzz"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=RelWithDebInfo -DCMAKE_CXX_COMPILER=clang++ \
  -DTSI_BUILD_FUZZERS=ON -DTSI_BUILD_TESTS=OFF -DTSI_BUILD_BENCH=OFF -DTSI_BUILD_PYTHON=OFF -DTSI_WITH_MPI=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" --target tsi_fuzz_loaders tsi_plugins >&2
mkdir -p "$build/fuzz-corpus" "$build/fuzz-findings" "$build/fuzz-seeds"
cp "$root"/examples/*.json "$root"/examples/paper/*.json "$build/fuzz-seeds/"
export ASAN_OPTIONS="detect_leaks=0:abort_on_error=1:allocator_may_return_null=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
exec "$build/bin/tsi_fuzz_loaders" -max_total_time="$seconds" -timeout=30 -rss_limit_mb=4096 -max_len=16384 \
  -print_final_stats=1 -artifact_prefix="$build/fuzz-findings/" "$@" "$build/fuzz-corpus" "$build/fuzz-seeds"
