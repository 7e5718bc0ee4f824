#!/usr/bin/python3
"""The total energy W of a `vlasov-poisson-2d` conservation study, one row per run, as a
Markdown table, from the study's files only (table.csv, runs/*/invariants.csv):

    python3 examples/pic/energy_table.py OUT_DIR

Columns: the largest relative change max |W(t) - W(0)| / W(0) (table.csv's err_W); the drift,
the least-squares slope of (W(t) - W(0)) / W(0) over the last 90% of the run (as the study's
drift columns); the signed change at t_end; and the largest distance from the rk78 run of the
same eps, max |W(t) - W_rk78(t)| / W(0), over the times both have (rk78 on the filtered
problem at a tight tolerance: the energy of the PIC model itself, grid heating included).
"""
import csv
import os
import sys

import numpy as np


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "table.csv")) as f:
        rows = list(csv.DictReader(f))
    runs = {r["id"]: np.genfromtxt(os.path.join(out, "runs", r["id"], "invariants.csv"), delimiter=",", names=True)
            for r in rows if r["status"] in ("completed", "blow-up")}
    ref = {r["eps"]: r["id"] for r in rows if r["scheme"] == "rk78" and r["id"] in runs}
    print("| run | eps | max rel. change of W | drift per unit time | change at t_end | max distance from rk78 |")
    print("|---|---|---|---|---|---|")
    for r in rows:
        if r["id"] not in runs:
            print(f"| {r['label'] or r['scheme']} | {r['eps']} | {r['status']} | | | |")
            continue
        d = runs[r["id"]]
        t, w = d["t"], d["W"]
        rel = (w - w[0]) / w[0]
        late = t >= 0.1 * t[-1]
        drift = np.polyfit(t[late], rel[late], 1)[0]
        dist = ""
        if r["eps"] in ref and ref[r["eps"]] != r["id"]:
            wr = runs[ref[r["eps"]]]
            n = min(len(t), len(wr))
            if np.allclose(t[:n], wr["t"][:n]):
                dist = f"{np.max(np.abs(w[:n] - wr['W'][:n])) / w[0]:.2e} (t <= {t[n - 1]:g})"
        print(f"| {r['label'] or r['scheme']} | {float(r['eps']):g} | {np.max(np.abs(rel)):.2e} | {drift:+.2e} "
              f"| {rel[-1]:+.2e} (t = {t[-1]:g}) | {dist} |")


if __name__ == "__main__":
    main()
