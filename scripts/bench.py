#!/usr/bin/python3
"""tsi's speed in one run: the cost of a step against its FFTs, and the eps-independent
advantage over classical solvers, measured side by side on this machine.

    python3 scripts/bench.py [--build build] [--out out/bench] [--quick]

1. Google Benchmark (build/bin/tsi_bench): per model, the nonlinearity over the whole tau
   grid against the FFTs it must do (the bound), and per scheme ns per step, sweeps per
   step and a sweep's cost over its FFT bound; the same SE1 step at eps = 1 and 1e-6.
2. Work-precision studies (tsi study) at eps = 1, 1e-2, 1e-4, 1e-6 and T = 1: wall time to
   reach relative errors 1e-4 and 1e-6 for the best two-scale scheme, rk78 on the direct
   problem, and Strang splitting where the model has an exact nonlinear flow, with the
   speed-up of the best two-scale scheme.
Writes bench.json and the tables (bench.txt) to --out.
"""
import argparse
import json
import os
import platform
import subprocess
import sys

EPSILONS = [1.0, 1e-2, 1e-4, 1e-6]
H_LIST = [0.25, 0.125, 0.0625, 0.03125, 0.015625, 0.0078125, 0.00390625, 0.001953125, 0.0009765625]
TOLS = [1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8, 1e-10, 1e-12]
MODELS = ["henon-heiles", "cpd", "nls"]
# rk78 on the direct NLS problem must resolve its fastest mode, (n_x/2)^2 / eps: below this
# eps a run takes hours, so the classical baseline for NLS there is Strang splitting alone.
RK78_MIN_EPS = {"nls": 1e-2}
# The reference itself (rk78 on the filtered problem, 8 substeps per fastest period) costs
# about (n_x/2)^2 / eps substeps for NLS: eps = 1e-6 would take hours.
MIN_EPS = {"nls": 1e-4}


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def google_benchmark(build, min_time):
    out = subprocess.run([os.path.join(build, "bin", "tsi_bench"), "--benchmark_format=json",
                          f"--benchmark_min_time={min_time}"], check=True, capture_output=True, text=True)
    return {b["name"]: b for b in json.loads(out.stdout)["benchmarks"]}


def step_table(bench):
    lines = ["step cost (ns) at h = 1/8, eps = 0.01; a sweep's cost over its FFT bound",
             f"  {'model':<16}{'scheme':<8}{'ns/step':>12}{'sweeps':>8}{'ns/sweep':>11}{'FFT bound':>11}{'ratio':>8}"]
    rows = []
    for name, b in bench.items():
        if not name.startswith("step/"):
            continue
        _, model, scheme = name.split("/")
        fft = bench[f"fft_bound/{model}"]["real_time"]
        evaluation = bench[f"nonlinearity/{model}"]["real_time"]
        sweeps = b.get("sweeps", 0.0)
        per_sweep = b["real_time"] / sweeps if sweeps else evaluation
        rows.append({"model": model, "scheme": scheme, "ns_per_step": b["real_time"], "sweeps": sweeps,
                     "ns_per_sweep": per_sweep, "fft_bound_ns": fft, "sweep_over_fft": per_sweep / fft})
        lines.append(f"  {model:<16}{scheme:<8}{b['real_time']:>12.0f}{sweeps:>8.2f}{per_sweep:>11.0f}{fft:>11.0f}"
                     f"{per_sweep / fft:>8.2f}")
    lines.append("  nonlinearity over the whole tau grid against its FFT bound:")
    for name, b in bench.items():
        if name.startswith("nonlinearity/"):
            model = name.split("/")[1]
            fft = bench[f"fft_bound/{model}"]["real_time"]
            lines.append(f"    {model:<20}{b['real_time']:>10.0f} ns  bound {fft:>8.0f} ns  ratio {b['real_time'] / fft:.2f}")
    lines.append("  SE1 step at eps = 1 and eps = 1e-6 (cost independent of eps):")
    for name, b in bench.items():
        if name.startswith("step_eps/") and name.endswith("/1"):
            other = bench.get(name[:-1] + "1e-6")
            if other:
                lines.append(f"    {name.split('/')[1]:<20}{b['real_time']:>10.0f} ns  {other['real_time']:>10.0f} ns"
                             f"  ratio {other['real_time'] / b['real_time']:.2f}")
    return rows, lines


def study_for(model, eps, with_strang, quick):
    hs = H_LIST[:6] if quick else H_LIST
    cases = [{"label": s, "set": {"scheme": {"name": s}, "reformulation": {"name": "two-scale"}}, "vary": {"time.h": hs}}
             for s in ("se1", "se2", "fd", "me")]
    if eps >= RK78_MIN_EPS.get(model, 0.0):
        cases.append({"label": "rk78", "set": {"scheme": {"name": "rk78"}, "reformulation": {"name": "direct"},
                                               "time.h": 1.0}, "vary": {"scheme.tol": TOLS}})
    if with_strang:
        cases.append({"label": "strang", "set": {"scheme": {"name": "strang"}, "reformulation": {"name": "direct"}},
                      "vary": {"time.h": [h / 8 for h in hs]}})
    return {"kind": "work-precision", "title": f"{model}: time to accuracy at T = 1",
            "base": {"model": {"name": model}, "time": {"t_end": 1.0},
                     "reference": {"scheme": "rk78", "reformulation": "filtered", "tol": 1e-13}},
            "cases": cases}


def eps_table(build, out, models, quick):
    tsi = os.path.join(build, "bin", "tsi")
    listing = json.loads(subprocess.run([tsi, "list", "--json"], check=True, capture_output=True, text=True).stdout)
    known = {m["name"] for m in listing["models"]}
    schemes = {s["name"] for s in listing["schemes"]}
    lines, rows = [], []
    for model in (m for m in models if m in known):
        for eps in (e for e in EPSILONS if e >= MIN_EPS.get(model, 0.0)):
            study = study_for(model, eps, model == "nls" and "strang" in schemes, quick)
            study["base"]["model"]["eps"] = eps
            path = os.path.join(out, f"study-{model}-{eps:g}.json")
            json.dump(study, open(path, "w"), indent=1)
            run_dir = os.path.join(out, f"{model}-{eps:g}")
            subprocess.run([tsi, "study", path, "--out", run_dir, "--jobs", "1", "--no-plots"],
                           check=False, capture_output=True, text=True)
            work = json.load(open(os.path.join(run_dir, "study.json"))).get("work_at_error", [])
            by_name = {w["name"]: w["seconds"] for w in work}
            for k, target in enumerate((1e-4, 1e-6)):
                two_scale = {s: by_name[s][k] for s in ("se1", "se2", "fd", "me") if by_name.get(s, [None, None])[k]}
                best = min(two_scale, key=two_scale.get) if two_scale else None
                row = {"model": model, "eps": eps, "target": target, "best": best,
                       "best_seconds": two_scale.get(best), "rk78_seconds": by_name.get("rk78", [None, None])[k],
                       "strang_seconds": by_name.get("strang", [None, None])[k]}
                rows.append(row)
    lines.append("wall time to reach a relative error at T = 1 (one thread; '-' = not reached by the runs;")
    lines.append(f"  rk78 is not run on NLS below eps = {RK78_MIN_EPS['nls']:g}: it must resolve (n_x/2)^2/eps)")
    lines.append(f"  {'model':<14}{'eps':>8}{'error':>8}{'best two-scale':>18}{'rk78':>12}{'speed-up':>10}"
                 f"{'strang':>12}{'speed-up':>10}")
    fmt = lambda x: f"{x:.2e}" if x else "-"
    for r in rows:
        up = lambda other: f"{other / r['best_seconds']:.2g}x" if other and r["best_seconds"] else "-"
        best = f"{r['best']} {fmt(r['best_seconds'])}" if r["best"] else "-"
        lines.append(f"  {r['model']:<14}{r['eps']:>8g}{r['target']:>8g}{best:>18}{fmt(r['rk78_seconds']):>12}"
                     f"{up(r['rk78_seconds']):>10}{fmt(r['strang_seconds']):>12}{up(r['strang_seconds']):>10}")
    return rows, lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--quick", action="store_true", help="shorter benchmarks and fewer step sizes")
    ap.add_argument("--models", nargs="*", default=list(MODELS))
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    header = [f"tsi bench on {cpu_name()}, {os.cpu_count()} cores, {platform.platform()}"]
    bench = google_benchmark(args.build, 0.05 if args.quick else 0.3)
    step_rows, step_lines = step_table(bench)
    eps_rows, eps_lines = eps_table(args.build, args.out, args.models, args.quick)
    text = "\n".join(header + [""] + step_lines + [""] + eps_lines) + "\n"
    print(text, end="")
    open(os.path.join(args.out, "bench.txt"), "w").write(text)
    json.dump({"machine": header[0], "google_benchmark": bench, "steps": step_rows, "time_to_accuracy": eps_rows},
              open(os.path.join(args.out, "bench.json"), "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
