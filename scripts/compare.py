#!/usr/bin/python3
"""Side-by-side comparison of schemes: runs `tsi run` over the groups of a comparison file
(a base config, fixed settings per group, and lists of values whose cartesian product is
run), then writes table.csv, prints the convergence and cost tables, and plots.

Plots need python3-matplotlib; without it the tables are still written."""
import argparse
import concurrent.futures as futures
import csv
import itertools
import json
import math
import os
import subprocess
import sys


def run_one(tsi, base_file, out_dir, settings):
    cmd = [tsi, "run", base_file, "--out", out_dir]
    for key, value in settings.items():
        cmd += ["--set", f"{key}={json.dumps(value)}"]
    proc = subprocess.run(cmd, capture_output=True, text=True)
    result_file = os.path.join(out_dir, "result.json")
    result = json.load(open(result_file)) if os.path.exists(result_file) else {}
    if proc.returncode != 0:
        result.setdefault("status", "failed")
        result["message"] = (proc.stderr or proc.stdout).strip()
    return result


def expand(group):
    keys = list(group.get("vary", {}))
    for values in itertools.product(*(group["vary"][k] for k in keys)):
        settings = {f"{section}": value for section, value in group.get("set", {}).items()}
        settings.update(dict(zip(keys, values)))
        yield settings


def fraction(x):
    inv = 1.0 / x
    return f"1/{round(inv)}" if x < 1 and abs(inv - round(inv)) < 1e-9 else f"{x:g}"


def order(h, e):
    return math.log(e[0] / e[1]) / math.log(h[0] / h[1])


def main():
    ap = argparse.ArgumentParser(description=__doc__)
    ap.add_argument("--tsi", required=True, help="the tsi runner")
    ap.add_argument("--study", required=True, help="the comparison file (JSON)")
    ap.add_argument("--out", required=True, help="output directory")
    ap.add_argument("--jobs", type=int, default=os.cpu_count() or 1)
    args = ap.parse_args()

    study = json.load(open(args.study))
    os.makedirs(args.out, exist_ok=True)
    base_file = os.path.join(args.out, "base.json")
    json.dump(study["base"], open(base_file, "w"), indent=2)

    jobs = []
    for g, group in enumerate(study["groups"]):
        for i, settings in enumerate(expand(group)):
            jobs.append((group["label"], settings, os.path.join(args.out, "runs", f"g{g}-{i:03d}")))
    rows = []
    with futures.ThreadPoolExecutor(args.jobs) as pool:
        pending = {pool.submit(run_one, args.tsi, base_file, d, s): (label, d) for label, s, d in jobs}
        for done, fut in enumerate(futures.as_completed(pending), 1):
            label, run_dir = pending[fut]
            r = fut.result()
            c = r.get("config", {})
            rows.append({
                "group": label, "run": os.path.basename(run_dir),
                "scheme": c.get("scheme", {}).get("name"), "reformulation": c.get("reformulation", {}).get("name"),
                "eps": c.get("model", {}).get("eps"), "h": c.get("time", {}).get("h"),
                "tol": c.get("scheme", {}).get("tol"), "error": r.get("error", {}).get("relative"),
                "err_H": r.get("invariants", {}).get("H", {}).get("max_rel_error"),
                "rhs_evaluations": r.get("rhs_evaluations"), "wall_seconds": r.get("wall_seconds"),
                "sweeps_mean": r.get("solver", {}).get("iterations_mean"),
                "status": r.get("status", "failed"), "message": r.get("message", "")})
            if sys.stderr.isatty():
                print(f"\r  runs done: {done}/{len(jobs)}", end="", file=sys.stderr, flush=True)
    if sys.stderr.isatty():
        print(file=sys.stderr)
    rows.sort(key=lambda r: r["run"])
    with open(os.path.join(args.out, "table.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)

    print(study.get("title", ""))
    failed = [r for r in rows if r["status"] != "completed"]
    for r in failed:
        print(f"  FAILED {r['run']} ({r['scheme']}, eps={r['eps']}): {r['message']}")
    for group in study["groups"]:
        g_rows = [r for r in rows if r["group"] == group["label"] and r["status"] == "completed"]
        if "time.h" in group.get("vary", {}):
            print_convergence(group["label"], g_rows)
        else:
            print_cost(group["label"], g_rows)
    plot(study, rows, args.out)
    print(f"\n  table: {args.out}/table.csv   runs: {args.out}/runs/")
    return 1 if failed else 0


def print_convergence(label, rows):
    epss = sorted({r["eps"] for r in rows}, reverse=True)
    hs = sorted({r["h"] for r in rows}, reverse=True)
    err = {(r["eps"], r["h"]): r["error"] for r in rows}
    print(f"\n{label}: relative error at t_end (observed order in parentheses)")
    print("  " + f"{'h':>7}" + "".join(f"{'eps=' + fraction(e):>20}" for e in epss) + f"{'max over eps':>20}")
    for i, h in enumerate(hs):
        cells = []
        for e in epss:
            x = err.get((e, h))
            o = f" ({order([hs[i - 1], h], [err[(e, hs[i - 1])], x]):.2f})" if i and x else ""
            cells.append(f"{x:.3e}{o}" if x else "-")
        worst = max((err[(e, h)] for e in epss if (e, h) in err), default=float("nan"))
        print("  " + f"{fraction(h):>7}" + "".join(f"{c:>20}" for c in cells) + f"{worst:>20.3e}")


def print_cost(label, rows):
    print(f"\n{label}: error and cost at t_end")
    print(f"  {'eps':>10} {'tol':>8} {'error':>11} {'rhs evals':>12} {'wall s':>9}")
    for r in sorted(rows, key=lambda r: (-r["eps"], -r["tol"])):
        print(f"  {fraction(r['eps']):>10} {r['tol']:>8.0e} {r['error']:>11.3e} {r['rhs_evaluations']:>12d}"
              f" {r['wall_seconds']:>9.3f}")


def plot(study, rows, out):
    try:
        import matplotlib
        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        print(f"\n  (no plots: install python3-matplotlib and rerun {sys.argv[0]})")
        return
    ok = [r for r in rows if r["status"] == "completed" and r["error"]]
    conv_groups = [g for g in study["groups"] if "time.h" in g.get("vary", {})]
    ncols = min(2, len(conv_groups))
    nrows = (len(conv_groups) + ncols - 1) // ncols
    fig, axes = plt.subplots(nrows, ncols, figsize=(6.4 * ncols, 4.8 * nrows), squeeze=False)
    for ax in axes.flat[len(conv_groups):]:
        ax.set_visible(False)
    for ax, g in zip(axes.flat, conv_groups):
        g_rows = [r for r in ok if r["group"] == g["label"]]
        for e in sorted({r["eps"] for r in g_rows}, reverse=True):
            pts = sorted((r["h"], r["error"]) for r in g_rows if r["eps"] == e)
            ax.loglog(*zip(*pts), "o-", label=f"eps = {fraction(e)}")
        hs = sorted({r["h"] for r in g_rows})
        e0 = max(r["error"] for r in g_rows if r["h"] == hs[-1])
        ax.loglog(hs, [2 * e0 * (h / hs[-1]) ** 2 for h in hs], "k--", label="slope 2")
        ax.set_xlabel("time step h")
        ax.set_ylabel("relative error at t_end")
        ax.set_title(g["label"])
        ax.grid(True, which="both", alpha=0.3)
        ax.legend()
    fig.tight_layout()
    fig.savefig(os.path.join(out, "convergence.png"), dpi=120)

    fig, ax = plt.subplots(figsize=(11.5, 5.6))
    styles = itertools.cycle(["o-", "s--", "^:", "v-.", "D-"])
    all_eps = sorted({r["eps"] for r in ok}, reverse=True)
    colors = {e: f"C{i}" for i, e in enumerate(all_eps)}
    for g in study["groups"]:
        style = next(styles)
        g_rows = [r for r in ok if r["group"] == g["label"]]
        for e in sorted({r["eps"] for r in g_rows}, reverse=True):
            pts = sorted((r["rhs_evaluations"], r["error"]) for r in g_rows if r["eps"] == e)
            ax.loglog(*zip(*pts), style, color=colors[e], label=f"{g['label']}, eps = {fraction(e)}")
    ax.set_xlabel("nonlinearity evaluations (two-scale: one covers all n_tau points)")
    ax.set_ylabel("relative error at t_end")
    ax.set_title("Work against precision")
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=7, ncol=1, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.tight_layout()
    fig.savefig(os.path.join(out, "work_precision.png"), dpi=120)
    print(f"\n  plots: {out}/convergence.png, {out}/work_precision.png")


if __name__ == "__main__":
    sys.exit(main())
