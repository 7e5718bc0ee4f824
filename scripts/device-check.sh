#!/usr/bin/env bash
# The device backend's check on a machine with a CUDA GPU (docs/how-to/gpu.md): the CUDA tests
# (the algebra, and the two-scale NLS and particle-in-cell steps of SE1 and eab against the
# CPU), then the step benchmark (2-D NLS 1024 x 1024, n_tau 32: a step against the cuFFT bound
# and the CPU, the device's memory; the particle-in-cell plasma of 2^20 particles). Prints a short table last; logs and JSON go to $OUT (or ./device-check).
#
#   scripts/device-check.sh            uses build-cuda/ (built here first where it is missing:
#                                      cmake -DTSI_WITH_CUDA=ON, needs nvcc and the project's deps)
#   TSI_DEVICE_LIBS=DIR scripts/...    shared libraries to put first on the library path (a
#                                      build tree carried from another machine with its deps)
#   TSI_BENCH_N=512 scripts/...        a smaller grid (default 1024)
#   TSI_BENCH_PARTICLES=N scripts/...  the particle-in-cell benchmark's particles (default 2^20; 0: none)
set -euo pipefail
cd "$(dirname "$0")/.."
root=$PWD
out=${OUT:-$root/device-check}
mkdir -p "$out"
build=${TSI_CUDA_BUILD:-build-cuda}

if [[ ! -x $build/bin/tsi_cuda_tests ]]; then
  cmake -S . -B "$build" -G Ninja -DTSI_WITH_CUDA=ON -DTSI_BUILD_PYTHON=OFF -DTSI_BUILD_BENCH=OFF
  cmake --build "$build" --target tsi tsi_plugins tsi_cuda_tests tsi_cuda_bench
fi
export LD_LIBRARY_PATH=$root/$build/lib${TSI_DEVICE_LIBS:+:$TSI_DEVICE_LIBS}:/usr/local/cuda/lib64${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}
export TSI_TEST_PLUGIN_DIR=$root/$build/lib/tsi/plugins TSI_PLUGIN_DIR=$root/$build/lib/tsi/plugins
export TSI_TEST_RUNNER=$root/$build/bin/tsi

{
  nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.sm,clocks.mem --format=csv || true
  nproc
} 2>&1 | tee "$out/device.txt"

status=0
echo "== tests"
(cd "$out" && "$root/$build/bin/tsi_cuda_tests" --success=false 2>&1) | tee "$out/tests.log" || status=1
if command -v compute-sanitizer > /dev/null; then
  echo "== compute-sanitizer memcheck (the algebra, the NLS and particle-in-cell steps)"
  (cd "$out" && compute-sanitizer --tool memcheck --error-exitcode 9 "$root/$build/bin/tsi_cuda_tests" \
     --test-case='device algebra*,device NLS*,device particle*' 2>&1 | tail -5) | tee "$out/memcheck.log" || status=1
fi
echo "== step benchmark"
"$root/$build/bin/tsi_cuda_bench" --n "${TSI_BENCH_N:-1024}" --n-tau 32 --steps 5 --cpu-steps 1 \
  --pic-particles "${TSI_BENCH_PARTICLES:-1048576}" --json "$out/bench.json" 2>&1 | tee "$out/bench.log" || status=1
exit $status
