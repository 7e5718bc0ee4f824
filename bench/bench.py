#!/usr/bin/python3
"""tsi's speed in one run: the cost of a step against its FFTs, and the eps-independent
advantage over classical solvers, measured side by side on this machine.

    python3 bench/bench.py [--build build] [--out out/bench] [--quick] [--models M ...] [--eps E ...]
                           [--benchmark-filter REGEX]

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
# rk78 integrates the charged particle in its physical variables (x, v), as a user would:
# in the canonical ones a tolerance on p = 2 eps v - B x is 1/(2 eps) times larger on v.
RK78_VARIABLES = {"cpd": "physical"}
# The default reference (rk78 on the filtered problem, 8 substeps per fast period) costs
# about (n_x/2)^2 / eps substeps for NLS: at eps = 1e-6, hours. Below REFERENCE_MIN_EPS the
# reference is SE2 on the two-scale problem with a step 1/4096 (error about 4e-9, uniform in
# eps); at eps = 1e-4 the two references are compared (printed with the table).
REFERENCE_MIN_EPS = {"nls": 1e-4}
FILTERED_REFERENCE = {"scheme": "rk78", "reformulation": "filtered", "tol": 1e-13}
TWO_SCALE_REFERENCE = {"scheme": "se2", "reformulation": "two-scale", "tol": 1e-13, "h": 1.0 / 4096}


def cpu_name():
    try:
        for line in open("/proc/cpuinfo"):
            if line.startswith("model name"):
                return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor()


def google_benchmark(build, min_time, benchmark_filter=None):
    command = [os.path.join(build, "bin", "tsi_bench"), "--benchmark_format=json", f"--benchmark_min_time={min_time}"]
    if benchmark_filter:
        command.append(f"--benchmark_filter={benchmark_filter}")
    out = subprocess.run(command, check=True, capture_output=True, text=True)
    return {b["name"]: b for b in json.loads(out.stdout)["benchmarks"]}


def step_table(bench):
    lines = ["step cost at h = 1/8, eps = 0.01: a sweep's cost over the FFTs it must do (its N evaluations'",
             "transforms; for explicit schemes, the cost per evaluation of N over one evaluation's transforms)",
             f"  {'model':<16}{'scheme':<8}{'ns/step':>12}{'sweeps':>8}{'N evals':>9}{'ns/sweep':>11}{'FFT bound':>11}{'ratio':>8}"]
    rows = []
    for name, b in bench.items():
        if not name.startswith("step/"):
            continue
        # step/<model>/<scheme>[/<variant>] (step/cpd/se2/2-nodes)
        _, model, scheme = name.split("/", 2)
        if f"fft_bound/{model}" not in bench:  # filtered out (--benchmark-filter)
            continue
        fft = bench[f"fft_bound/{model}"]["real_time"]
        sweeps, evaluations = b.get("sweeps", 0.0), b.get("evaluations", 0.0)
        units = sweeps if sweeps else evaluations  # sweeps of an implicit scheme, else evaluations
        per_unit = b["real_time"] / units
        bound = fft * evaluations / units  # the transforms one sweep (or evaluation) must do
        rows.append({"model": model, "scheme": scheme, "ns_per_step": b["real_time"], "sweeps": sweeps,
                     "evaluations": evaluations, "ns_per_sweep": per_unit, "fft_bound_ns": bound,
                     "sweep_over_fft": per_unit / bound})
        lines.append(f"  {model:<16}{scheme:<8}{b['real_time']:>12.0f}{sweeps:>8.2f}{evaluations:>9.2f}{per_unit:>11.0f}"
                     f"{bound:>11.0f}{per_unit / bound:>8.2f}")
    lines.append("  nonlinearity over the whole tau grid against its FFT bound:")
    for name, b in bench.items():
        if name.startswith("nonlinearity/") and f"fft_bound/{name.split('/')[1]}" in bench:
            model = name.split("/")[1]
            fft = bench[f"fft_bound/{model}"]["real_time"]
            lines.append(f"    {model:<20}{b['real_time']:>10.0f} ns  bound {fft:>8.0f} ns  ratio {b['real_time'] / fft:.2f}")
    lines.append("  at sizes where the state dominates (large/<case>): N and a step against the transforms:")
    for name, b in bench.items():
        if name.startswith("large/") and name.endswith("/fft_bound"):
            case = name.split("/")[1]
            fft = b["real_time"]
            n = bench.get(f"large/{case}/nonlinearity")
            if n:
                lines.append(f"    {case:<36} N {n['real_time']:>12.0f} ns  bound {fft:>12.0f} ns  ratio {n['real_time'] / fft:.2f}")
            for scheme in ("se1", "eab"):
                st = bench.get(f"large/{case}/{scheme}")
                if st and st.get("evaluations"):
                    ratio = st["real_time"] / (st["evaluations"] * fft)
                    lines.append(f"    {case:<36} {scheme} step {st['real_time']:>12.0f} ns  {st['evaluations']:.1f} evaluations"
                                 f"  step / (evaluations x bound) {ratio:.2f}")
    lines.append("  the same with FFTW on two threads (tsi --fft-threads 2; used from 65536 values per batch):")
    for name, b in bench.items():
        if name.startswith("nonlinearity_threads/") and f"nonlinearity/{name.split('/')[1]}" in bench:
            model = name.split("/")[1]
            one = bench[f"nonlinearity/{model}"]["real_time"]
            lines.append(f"    {model:<20}{b['real_time']:>10.0f} ns  one thread {one:>8.0f} ns  speed-up {one / b['real_time']:.2f}")
    lines.append("  SE1 step at eps = 1 and eps = 1e-6 (cost independent of eps):")
    for name, b in bench.items():
        if name.startswith("step_eps/") and name.endswith("/1"):
            other = bench.get(name[:-1] + "1e-6")
            if other:
                lines.append(f"    {name.split('/')[1]:<20}{b['real_time']:>10.0f} ns  {other['real_time']:>10.0f} ns"
                             f"  ratio {other['real_time'] / b['real_time']:.2f}")
    return rows, lines


def reference_for(model, eps):
    return FILTERED_REFERENCE if eps >= REFERENCE_MIN_EPS.get(model, 0.0) else TWO_SCALE_REFERENCE


def study_for(model, eps, with_strang, quick):
    hs = H_LIST[:6] if quick else H_LIST
    cases = [{"label": s, "set": {"scheme": {"name": s}, "reformulation": {"name": "two-scale"}}, "vary": {"time.h": hs}}
             for s in ("se1", "se2", "fd", "me")]
    if eps >= RK78_MIN_EPS.get(model, 0.0):
        direct = {"name": "direct", "variables": RK78_VARIABLES.get(model, "model")}
        cases.append({"label": "rk78", "set": {"scheme": {"name": "rk78"}, "reformulation": direct,
                                               "time.h": 1.0}, "vary": {"scheme.tol": TOLS}})
    if with_strang:
        cases.append({"label": "strang", "set": {"scheme": {"name": "strang"}, "reformulation": {"name": "direct"}},
                      "vary": {"time.h": [h / 8 for h in hs]}})
    return {"kind": "work-precision", "title": f"{model}: time to accuracy at T = 1",
            "base": {"model": {"name": model, "eps": eps}, "time": {"t_end": 1.0},
                     "reference": reference_for(model, eps)},
            "cases": cases}


def references_agree(tsi, out, model, eps):
    """The two-scale reference measured against the filtered one, where both are affordable."""
    study = {"kind": "work-precision", "title": f"{model}: the two-scale reference against rk78 (filtered)",
             "base": {"model": {"name": model, "eps": eps}, "time": {"t_end": 1.0, "h": TWO_SCALE_REFERENCE["h"]},
                      "scheme": {"name": TWO_SCALE_REFERENCE["scheme"], "tol": TWO_SCALE_REFERENCE["tol"]},
                      "reformulation": {"name": "two-scale"}, "reference": FILTERED_REFERENCE}}
    path = os.path.join(out, f"references-{model}-{eps:g}.json")
    json.dump(study, open(path, "w"), indent=1)
    run_dir = os.path.join(out, f"references-{model}-{eps:g}")
    subprocess.run([tsi, "study", path, "--out", run_dir, "--jobs", "1", "--no-plots"], check=False,
                   capture_output=True, text=True)
    table = json.load(open(os.path.join(run_dir, "study.json")))["table"]
    return table[0].get("error") if table else None


def eps_table(build, out, models, quick, epsilons=EPSILONS):
    tsi = os.path.join(build, "bin", "tsi")
    listing = json.loads(subprocess.run([tsi, "list", "--json"], check=True, capture_output=True, text=True).stdout)
    known = {m["name"] for m in listing["models"]}
    schemes = {s["name"] for s in listing["schemes"]}
    lines, rows, notes = [], [], []
    for model in (m for m in models if m in known):
        if model in REFERENCE_MIN_EPS:
            eps = REFERENCE_MIN_EPS[model]
            agreement = references_agree(tsi, out, model, eps)
            notes.append(f"  {model}: below eps = {eps:g} the reference is {TWO_SCALE_REFERENCE['scheme']} on the two-scale "
                         f"problem, h = 1/{1 / TWO_SCALE_REFERENCE['h']:.0f}; at eps = {eps:g} it differs from rk78 on "
                         f"the filtered problem by {agreement:.2e}" if agreement is not None else
                         f"  {model}: the two references could not be compared")
        for eps in epsilons:
            study = study_for(model, eps, model == "nls" and "strang" in schemes, quick)
            path = os.path.join(out, f"study-{model}-{eps:g}.json")
            json.dump(study, open(path, "w"), indent=1)
            run_dir = os.path.join(out, f"{model}-{eps:g}")
            subprocess.run([tsi, "study", path, "--out", run_dir, "--jobs", "1", "--no-plots"],
                           check=False, capture_output=True, text=True)
            work = json.load(open(os.path.join(run_dir, "study.json"))).get("work_at_error", [])
            by_name = {w["name"]: w for w in work}
            seconds = lambda name, k: by_name[name]["seconds"][k] if name in by_name else None
            bound = lambda name, k: name in by_name and by_name[name].get("how", [None, None])[k] == "at_most"
            for k, target in enumerate((1e-4, 1e-6)):
                two_scale = {s: seconds(s, k) for s in ("se1", "se2", "fd", "me") if seconds(s, k)}
                best = min(two_scale, key=two_scale.get) if two_scale else None
                row = {"model": model, "eps": eps, "target": target, "best": best,
                       "best_seconds": two_scale.get(best), "best_is_bound": bool(best and bound(best, k)),
                       "rk78_seconds": seconds("rk78", k), "rk78_is_bound": bound("rk78", k),
                       "strang_seconds": seconds("strang", k), "strang_is_bound": bound("strang", k)}
                rows.append(row)
    lines.append("wall time to reach a relative error at T = 1 (one thread; '-' = not reached by the runs;")
    lines.append(f"  '<=': every run was below the error, the cheapest one's time; rk78 is not run on NLS below")
    lines.append(f"  eps = {RK78_MIN_EPS['nls']:g}: it must resolve (n_x/2)^2/eps)")
    lines.append(f"  {'model':<14}{'eps':>8}{'error':>8}{'best two-scale':>20}{'rk78':>12}{'speed-up':>12}"
                 f"{'strang':>12}{'speed-up':>12}")
    fmt = lambda x, is_bound=False: ("<=" if is_bound else "") + f"{x:.2e}" if x else "-"
    for r in rows:
        # A bound on the two-scale time is a lower bound on the speed-up, and vice versa.
        def up(name):
            other = r[f"{name}_seconds"]
            if not other or not r["best_seconds"]:
                return "-"
            mark = ">=" if r["best_is_bound"] and not r[f"{name}_is_bound"] else ""
            mark = "<=" if r[f"{name}_is_bound"] and not r["best_is_bound"] else mark
            mark = "~" if r[f"{name}_is_bound"] and r["best_is_bound"] else mark
            return f"{mark}{other / r['best_seconds']:.2g}x"
        best = f"{r['best']} {fmt(r['best_seconds'], r['best_is_bound'])}" if r["best"] else "-"
        lines.append(f"  {r['model']:<14}{r['eps']:>8g}{r['target']:>8g}{best:>20}"
                     f"{fmt(r['rk78_seconds'], r['rk78_is_bound']):>12}{up('rk78'):>12}"
                     f"{fmt(r['strang_seconds'], r['strang_is_bound']):>12}{up('strang'):>12}")
    lines.extend(notes)
    return rows, lines


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--build", default="build")
    ap.add_argument("--out", default="out/bench")
    ap.add_argument("--quick", action="store_true", help="shorter benchmarks and fewer step sizes")
    ap.add_argument("--models", nargs="*", default=list(MODELS))
    ap.add_argument("--eps", nargs="*", type=float, default=list(EPSILONS), help="eps of the time-to-accuracy studies")
    ap.add_argument("--benchmark-filter", default=None, help="a regex of the Google benchmarks to run (default: all)")
    args = ap.parse_args()
    os.makedirs(args.out, exist_ok=True)
    header = [f"tsi bench on {cpu_name()}, {os.cpu_count()} cores, {platform.platform()}"]
    bench = google_benchmark(args.build, 0.05 if args.quick else 0.3, args.benchmark_filter)
    step_rows, step_lines = step_table(bench)
    eps_rows, eps_lines = eps_table(args.build, args.out, args.models, args.quick, args.eps)
    text = "\n".join(header + [""] + step_lines + [""] + eps_lines) + "\n"
    print(text, end="")
    open(os.path.join(args.out, "bench.txt"), "w").write(text)
    json.dump({"machine": header[0], "google_benchmark": bench, "steps": step_rows, "time_to_accuracy": eps_rows},
              open(os.path.join(args.out, "bench.json"), "w"), indent=1)


if __name__ == "__main__":
    sys.exit(main())
