#!/usr/bin/env bash
# The C++ suite under AddressSanitizer + UndefinedBehaviorSanitizer: a Debug build (assertions
# on, -O1 with line tables only so that the build and the numerical tests fit CI's time) in
# build-sanitize/, then ctest, less the long tests listed in tests/sanitizer-exclusions.txt
# (each runs in the Release suite of scripts/test.sh; lighter tests run its code here).
# Any ASan or UBSan report (leaks included) aborts the process that made it, so its test fails.
#   scripts/sanitize.sh [--all] [ctest arguments...]      (--all: no exclusions)
# The Python tests run the instrumented extension in the system interpreter, with the
# sanitizer runtimes preloaded and leak checks off there (tests/CMakeLists.txt). Not built:
# the benchmarks.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
all=0
if [ "${1:-}" = --all ]; then all=1; shift; fi
"$root/scripts/install-deps.sh"
build="$root/build-sanitize"
launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=)
if command -v ccache >/dev/null && [ "${TSI_CCACHE:-1}" != 0 ]; then
  launcher=(-DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR="$root" CCACHE_SLOPPINESS="pch_defines,time_macros,include_file_mtime,include_file_ctime"
fi
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g1 -O1" \
  -DTSI_SANITIZE=ON -DTSI_BUILD_PYTHON=ON -DTSI_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
cmake --build "$build" -j "$(nproc)" >&2
# Open MPI's own start-up allocations are never freed: scripts/lsan-suppressions.txt matches
# them by library. For that their stacks must have names: Open MPI keeps its components
# loaded until exit, and the MPI tests walk allocation stacks without frame pointers
# (tests/runner/run_command.hpp, mpirun_env; everywhere else that would be far too slow).
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan-suppressions.txt:print_suppressions=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1
exclude=()
if [ "$all" = 0 ]; then
  regex="$(/usr/bin/python3 "$root/scripts/ctest_exclusion_regex.py" "$root/tests/sanitizer-exclusions.txt" "$build")"
  [ -n "$regex" ] && exclude=(-E "$regex")
fi
ctest --test-dir "$build" -j "$(nproc)" --output-on-failure "${exclude[@]}" "$@"
