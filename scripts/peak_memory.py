#!/usr/bin/env python3
"""Peak memory of `tsi run` with a row of invariants.csv at every step, for runs of growing
length: Henon-Heiles, eps = 0.01, SE1 (n_tau 16), h = 0.01, no reference.

    python3 scripts/peak_memory.py [--tsi build/bin/tsi] [STEPS ...]   (default 160000 1600000)

Prints, per run, its steps, wall time, the size of invariants.csv and the peak resident memory
of the `tsi` process (getrusage of the child: ru_maxrss)."""
import argparse
import json
import os
import subprocess
import sys
import tempfile
import time

root = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
parser = argparse.ArgumentParser()
parser.add_argument("--tsi", default=os.path.join(root, "build", "bin", "tsi"))
parser.add_argument("steps", nargs="*", type=int, default=[160000, 1600000])
args = parser.parse_args()

print(f"{'steps':>9} {'wall s':>7} {'csv MB':>8} {'peak RSS MB':>11}")
peaks = []
for steps in args.steps:
    with tempfile.TemporaryDirectory() as tmp:
        config = {"model": {"name": "henon-heiles", "eps": 0.01},
                  "reformulation": {"name": "two-scale", "n_tau": 16},
                  "scheme": {"name": "se1"},
                  "time": {"h": 0.01, "t_end": 0.01 * steps},
                  "output": {"every": 1}}
        path = os.path.join(tmp, "config.json")
        with open(path, "w") as f:
            json.dump(config, f)
        out = os.path.join(tmp, "out")
        start = time.monotonic()
        pid = os.fork()
        if pid == 0:
            os.dup2(os.open(os.devnull, os.O_WRONLY), 1)  # the run's summary
            os.execv(args.tsi, [args.tsi, "run", path, "--out", out])
        _, status, usage = os.wait4(pid, 0)
        wall = time.monotonic() - start
        if os.waitstatus_to_exitcode(status) != 0:
            sys.exit(f"tsi exited with {os.waitstatus_to_exitcode(status)}")
        csv_mb = os.path.getsize(os.path.join(out, "invariants.csv")) / 1e6
        peaks.append(usage.ru_maxrss / 1024)
        print(f"{steps:>9} {wall:>7.1f} {csv_mb:>8.1f} {peaks[-1]:>11.1f}", flush=True)
if len(peaks) > 1:
    print(f"peak RSS ratio, longest / shortest: {peaks[-1] / peaks[0]:.3f}")
