#!/usr/bin/env bash
# The whole suite under AddressSanitizer + UndefinedBehaviorSanitizer: a Debug build (assertions
# on, -O1 so that the numerical tests finish in CI's time) in build-sanitize/, then ctest.
# Any ASan or UBSan report (leaks included) aborts the process that made it, so its test fails.
#   scripts/sanitize.sh [ctest arguments...]
# The Python tests run the instrumented extension in the system interpreter, with the
# sanitizer runtimes preloaded and leak checks off there (tests/CMakeLists.txt). Not built:
# the benchmarks.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"
"$root/scripts/install-deps.sh"
build="$root/build-sanitize"
cmake -S "$root" -B "$build" -G Ninja -DCMAKE_BUILD_TYPE=Debug -DCMAKE_CXX_FLAGS_DEBUG="-g -O1" \
  -DTSI_SANITIZE=ON -DTSI_BUILD_PYTHON=ON -DTSI_BUILD_BENCH=OFF >/dev/null
cmake --build "$build" -j "$(nproc)" >&2
# Open MPI's own start-up allocations are never freed: scripts/lsan-suppressions.txt matches
# them by library. For that their stacks must have names: Open MPI keeps its components
# loaded until exit, and the MPI tests walk allocation stacks without frame pointers
# (tests/runner/run_command.hpp, mpirun_env; everywhere else that would be far too slow).
export ASAN_OPTIONS="abort_on_error=1:detect_leaks=1:strict_string_checks=1:detect_stack_use_after_return=1:check_initialization_order=1"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export LSAN_OPTIONS="suppressions=$root/scripts/lsan-suppressions.txt:print_suppressions=0"
export OMPI_MCA_mca_base_component_disable_dlclose=1
ctest --test-dir "$build" -j "$(nproc)" --output-on-failure "$@"
