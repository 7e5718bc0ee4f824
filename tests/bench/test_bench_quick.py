#!/usr/bin/python3
"""bench/bench.py --quick on one model and one eps: it runs (Google Benchmark, then the
work-precision studies) and writes tables whose numbers are measured, not placeholders.

    test_bench_quick.py BENCH_PY BUILD_DIR OUT_DIR
"""
import json
import math
import os
import subprocess
import sys


def main():
    bench_py, build, out = sys.argv[1:4]
    r = subprocess.run([sys.executable, bench_py, "--build", build, "--out", out, "--quick",
                        "--models", "henon-heiles", "--eps", "0.01",
                        "--benchmark-filter", "^(nonlinearity|fft_bound|step)/henon-heiles"],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    bench = json.load(open(os.path.join(out, "bench.json")))
    steps = bench["steps"]
    schemes = {row["scheme"] for row in steps}
    # Every two-scale scheme of the shipped plugins has a step row with a measured cost.
    assert {"se1", "se2", "fd", "me", "eab", "collocation", "composition"} <= schemes, schemes
    for row in steps:
        assert row["ns_per_step"] > 0 and math.isfinite(row["sweep_over_fft"]) and row["sweep_over_fft"] > 0, row
    # The time-to-accuracy table: both targets at eps = 0.01, rk78 on the direct problem reaching
    # 1e-4 (its tolerances go to 1e-12), and the best two-scale scheme named where one reached it.
    table = bench["time_to_accuracy"]
    assert [(row["eps"], row["target"]) for row in table] == [(0.01, 1e-4), (0.01, 1e-6)], table
    assert table[0]["rk78_seconds"] and table[0]["rk78_seconds"] > 0, table[0]
    assert table[0]["best"] in {"se1", "se2", "fd", "me"}, table[0]
    text = open(os.path.join(out, "bench.txt")).read()
    assert "wall time to reach a relative error" in text and "henon-heiles" in text, text
    print("bench.py --quick: ok,", len(steps), "step rows")


if __name__ == "__main__":
    main()
