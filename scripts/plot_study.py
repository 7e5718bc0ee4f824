#!/usr/bin/python3
"""Plots a tsi study from its files only (table.csv, study.json, runs/*/invariants.csv), so
the figures can be restyled without rerunning anything:

    python3 scripts/plot_study.py OUT_DIR

convergence:    convergence.png     error against h, one panel per scheme, one curve per eps
                side_by_side.png    (two schemes or more) error against h, one panel per eps,
                                    one colour and marker per scheme in every panel
conservation:   conservation.png    err_H, err_I, err_m against t, one row per scheme, and a
                                    panel more per invariant the models declare (err_P,
                                    abs_err_P, err_mu: the change columns of invariants.csv)
work-precision: work_precision.png  error against wall time and against evaluations

The Python package draws the same figures with these functions (tsi.plot, from a study's
objects): convergence_figure, conservation_figure and work_precision_figure take the rows of
table.csv (dicts) and return the matplotlib figure.
"""
import csv
import json
import math
import os
import sys

import matplotlib

if __name__ == "__main__":  # a script writes files; imported (tsi.plot), the caller's backend stays
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402


def fraction(x):
    inv = 1.0 / x
    return f"1/{round(inv)}" if x < 1 and abs(inv - round(inv)) < 1e-9 * inv else f"{x:g}"


def number(s):
    try:
        return float(s)
    except (TypeError, ValueError):
        return None


def series_name(row):
    return row["label"] or row["scheme"]


def panels(n, width=6.0, height=4.4):
    cols = min(2, n)
    rows = (n + cols - 1) // cols
    fig, axes = plt.subplots(rows, cols, figsize=(width * cols, height * rows), squeeze=False)
    for ax in axes.flat[n:]:
        ax.set_visible(False)
    return fig, list(axes.flat[:n])


def convergence_figure(rows, title):
    # Failed runs (blow-up, no error) are drawn as red crosses along the top of their panel:
    # a plot never hides them.
    failed = [r for r in rows if not number(r["error"])]
    rows = [r for r in rows if number(r["error"])]
    names = list(dict.fromkeys(series_name(r) for r in rows + failed))
    fig, axes = panels(len(names))
    for ax, name in zip(axes, names):
        mine = [r for r in rows if series_name(r) == name]
        lost = [r for r in failed if series_name(r) == name]
        for eps in sorted({number(r["eps"]) for r in mine}, reverse=True):
            pts = sorted((number(r["h"]), number(r["error"])) for r in mine if number(r["eps"]) == eps)
            ax.loglog(*zip(*pts), "o-", label=f"eps = {fraction(eps)}")
        if mine:
            hs = sorted({number(r["h"]) for r in mine})
            top = max(number(r["error"]) for r in mine if number(r["h"]) == hs[-1])
            ax.loglog(hs, [1.5 * top * (h / hs[-1]) ** 2 for h in hs], "k--", label="slope 2")
        if lost:
            ax.set_xscale("log")
            ax.set_yscale("log")
            y = ax.get_ylim()[1] if mine else 1.0
            ax.plot([number(r["h"]) for r in lost], [y] * len(lost), "rx", markersize=9, clip_on=False,
                    label=f"failed: {len(lost)} run(s) (" + ", ".join(sorted({r['status'] for r in lost})) + ")")
        ax.set(xlabel="time step h", ylabel="relative error at t_end",
               title=f"{name} ({(mine or lost)[0]['model']})")
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


# Twenty colours, the ten strong hues first, then their light ones, and a marker cycle of
# another length: twelve schemes or more stay apart in a plot and in its legend.
_ORDER = list(range(0, 20, 2)) + list(range(1, 20, 2))
_MARKERS = "osD^v<>pPXh*"


def series_style(k):
    """Colour and marker of the k-th series: the same for a scheme in every panel."""
    return {"color": plt.get_cmap("tab20")(_ORDER[k % 20]), "marker": _MARKERS[k % len(_MARKERS)]}


def side_by_side_figure(rows, title):
    """Every scheme in one panel per eps: error against h. Failed runs are crosses in the scheme's
    colour along the panel's top, and the legend counts them."""
    failed = [r for r in rows if not number(r["error"])]
    good = [r for r in rows if number(r["error"])]
    names = list(dict.fromkeys(series_name(r) for r in rows))
    eps_values = sorted({number(r["eps"]) for r in rows}, reverse=True)
    fig, axes = panels(len(eps_values), width=5.2, height=4.2)
    for ax, eps in zip(axes, eps_values):
        ax.set_xscale("log")
        ax.set_yscale("log")
        for k, name in enumerate(names):
            pts = sorted((number(r["h"]), number(r["error"])) for r in good
                         if series_name(r) == name and number(r["eps"]) == eps)
            if pts:
                ax.plot(*zip(*pts), "-", lw=1, markersize=4, **series_style(k))
        top = ax.get_ylim()[1] if ax.lines else 1.0
        for k, name in enumerate(names):
            lost = [number(r["h"]) for r in failed if series_name(r) == name and number(r["eps"]) == eps]
            if lost:
                ax.plot(lost, [top] * len(lost), "x", color=series_style(k)["color"], markersize=8, clip_on=False)
        ax.set(xlabel="time step h", ylabel="relative error at t_end", title=f"eps = {fraction(eps)}")
        ax.grid(True, which="both", alpha=0.3)
    handles = []
    for k, name in enumerate(names):
        lost = sum(1 for r in failed if series_name(r) == name)
        label = name + (f" ({lost} failed: x)" if lost else "")
        handles.append(plt.Line2D([], [], lw=1, markersize=5, label=label, **series_style(k)))
    fig.legend(handles=handles, loc="center left", bbox_to_anchor=(1.0, 0.5), fontsize=8)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


CHANGES = ("err_H", "err_I", "err_m")


def read_invariants(path):
    """Every column of a run's invariants.csv, by name."""
    with open(path) as f:
        data = list(csv.DictReader(f))
    keys = data[0].keys() if data else ()
    return {k: [number(d[k]) for d in data] for k in keys}


def declared_changes(inv):
    """The change columns of the invariants a model declares: err_<name> or abs_err_<name>."""
    return [k for k in inv if k.startswith(("err_", "abs_err_")) and k not in CHANGES]


def recorded_values(inv):
    """The values a model records without tracking a change (FPUT's stiff energies I_1 .. I_m, a
    plasma's electric energy): columns with no err_ or abs_err_ column of their own."""
    skip = {"t", "tau_roughness", "tau_spread", "H", "I", "m"}
    return [k for k in inv if k not in skip and not k.startswith(("err_", "abs_err_"))
            and f"err_{k}" not in inv and f"abs_err_{k}" not in inv]


def read_runs(rows, out):
    """Every run's invariants.csv under OUT/runs/, by run id (runs without one left out)."""
    runs = {}
    for r in rows:
        path = os.path.join(out, "runs", r["id"], "invariants.csv")
        if os.path.exists(path):
            runs[r["id"]] = read_invariants(path)
    return runs


def conservation_figure(rows, title, runs):
    """`runs`: each run's invariants.csv columns by run id (read_runs)."""
    names = list(dict.fromkeys(series_name(r) for r in rows))
    keys = list(CHANGES)
    values = []
    for inv in runs.values():
        keys += [k for k in declared_changes(inv) if k not in keys]
        values += [k for k in recorded_values(inv) if k not in values]
    # A last column draws the recorded values themselves (FPUT's exchange I_1 -> I_2 -> I_3).
    columns = len(keys) + (1 if values else 0)
    fig, axes = plt.subplots(len(names), columns, figsize=(5 * columns, 3.2 * len(names)), squeeze=False)
    several_models = len({r["model"] for r in rows}) > 1
    for i, name in enumerate(names):
        for k, r in enumerate(r for r in rows if series_name(r) == name and r["id"] in runs):
            inv = runs[r["id"]]
            label = f"eps = {fraction(number(r['eps']))}, h = {fraction(number(r['h']))}"
            if several_models:
                label = f"{r['model']}, {label}"
            if r["status"] != "completed":
                label += f" ({r['status']} at t = {number(r['t_reached']) or 0:g})"
            for j, key in enumerate(keys):
                pts = [(t, e) for t, e in zip(inv["t"], inv.get(key, ())) if t > 0 and e and e > 0]
                if pts:  # a run keeps its colour in every panel, also where other runs have no curve
                    axes[i][j].semilogy(*zip(*pts), lw=0.8, color=f"C{k % 10}", label=label)
            for v, key in enumerate(values):  # a colour per value, a line style per run
                pts = [(t, y) for t, y in zip(inv["t"], inv.get(key, ())) if y is not None]
                if pts:
                    axes[i][-1].plot(*zip(*pts), ["-", "--", ":", "-."][k % 4], lw=0.9, color=f"C{v % 10}",
                                     label=f"{key}, {label}")
        for j, key in enumerate(keys):
            ax = axes[i][j]
            ax.set(xlabel="t", ylabel=key, title=f"{name}: {key}")
            ax.grid(True, which="both", alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=7)
        if values:
            ax = axes[i][-1]
            ax.set(xlabel="t", ylabel="value", title=f"{name}: " + ", ".join(values))
            ax.grid(True, alpha=0.3)
            if ax.lines:
                ax.legend(fontsize=7)
    fig.suptitle(title, fontsize=10)
    fig.tight_layout(rect=(0, 0, 1, 1 - 0.4 / fig.get_figheight()))  # room for the title
    return fig


def work_precision_figure(rows, title):
    rows = [r for r in rows if number(r["error"]) and number(r["wall_seconds"])]
    fig, axes = plt.subplots(1, 2, figsize=(14, 5.2))
    eps_values = sorted({number(r["eps"]) for r in rows}, reverse=True)
    lines = ["-", "--", ":", "-."]
    # A colour and marker per scheme (series_style), a line style per eps.
    for k, name in enumerate(dict.fromkeys(series_name(r) for r in rows)):
        for i, eps in enumerate(eps_values):
            mine = [r for r in rows if series_name(r) == name and number(r["eps"]) == eps]
            if not mine:
                continue
            for ax, x in zip(axes, ("wall_seconds", "rhs_evals")):
                pts = sorted((number(r[x]), number(r["error"])) for r in mine)
                ax.loglog(*zip(*pts), lines[i % len(lines)], markersize=4, label=f"{name}, eps = {fraction(eps)}",
                          **series_style(k))
    axes[0].set(xlabel="wall time [s]", ylabel="relative error at t_end", title="error against time")
    axes[1].set(xlabel="nonlinearity evaluations (two-scale: one covers all tau points)",
                ylabel="relative error at t_end", title="error against evaluations")
    for ax in axes:
        ax.grid(True, which="both", alpha=0.3)
    axes[1].legend(fontsize=7, loc="upper left", bbox_to_anchor=(1.01, 1.0))
    fig.suptitle(title, fontsize=10)
    fig.tight_layout()
    return fig


# The file each kind's figure goes to, and its resolution.
FILES = {"convergence": ("convergence.png", 110), "conservation": ("conservation.png", 100),
         "work-precision": ("work_precision.png", 110)}


def main():
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    out = sys.argv[1]
    with open(os.path.join(out, "study.json")) as f:
        study = json.load(f)
    with open(os.path.join(out, "table.csv")) as f:
        rows = list(csv.DictReader(f))
    kind, title = study["kind"], study.get("title", "")
    if kind == "convergence":
        fig = convergence_figure(rows, title)
    elif kind == "conservation":
        fig = conservation_figure(rows, title, read_runs(rows, out))
    else:
        fig = work_precision_figure(rows, title)
    name, dpi = FILES[kind]
    fig.savefig(os.path.join(out, name), dpi=dpi)
    print(f"  plot: {os.path.join(out, name)}")
    if kind == "convergence" and len({series_name(r) for r in rows}) > 1:
        path = os.path.join(out, "side_by_side.png")
        side_by_side_figure(rows, title).savefig(path, dpi=110, bbox_inches="tight")
        print(f"  plot: {path}")


if __name__ == "__main__":
    main()
