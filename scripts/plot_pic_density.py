#!/usr/bin/python3
"""Plots the particle density of a `vlasov-poisson-2d` run from its files only (result.json and
u_final.npy), so a run can be looked at without rerunning it:

    python3 scripts/plot_pic_density.py RUN_DIR [--out FILE.png]

The particles' positions (columns x1, x2 of the N x 4 state, possibly outside the box) are
wrapped into the periodic box [0, 2 pi / k_x) x [0, 2 pi / k_y) and counted on the run's own
n_x x n_y cells (nearest cell, not the model's shape function), scaled so that a uniform
density is 1 (each particle carries |box| / N, as in the model). The box and the grid come from
the resolved config in result.json (`config.model.k_x`, `k_y`, `n_x`, `n_y`).

A second panel shows the density at t = 0 where the run's files hold the initial particles:
- the dense output at t = 0 (a run with `"output": {"times": [0]}`: u_times.npy, or the values
  in result.json for a small run), or
- `model.particles` naming a particle file (`.npy`, N x 4, or the UA-PIC peer's raw layout of 4
  float64 per particle) that still exists.
Sampled particles (`model.particles` a count) are not written by a run: without the dense
output at t = 0 only the final density is drawn. `--initial FILE.npy` names an N x 4 file to
draw as the initial density instead.

Default output: RUN_DIR/density.png. Exit code 2, with a message naming the file and what was
expected, for a missing or unexpected file; 3 when the figure cannot be written.
"""
import argparse
import json
import math
import os
import sys

import numpy as np

import matplotlib

if __name__ == "__main__":
    matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

MODEL = "vlasov-poisson-2d"


class BadInput(Exception):
    """A file that is missing or not what a vlasov-poisson-2d run writes."""


def fraction(x):
    inv = 1.0 / x
    return f"1/{round(inv)}" if x < 1 and abs(inv - round(inv)) < 1e-9 * inv else f"{x:g}"


def read_result(run_dir):
    path = os.path.join(run_dir, "result.json")
    if not os.path.isfile(path):
        raise BadInput(f"{path}: not found (expected the result.json a `tsi run ... --out {run_dir}` writes)")
    try:
        with open(path) as f:
            result = json.load(f)
    except (OSError, ValueError) as e:
        raise BadInput(f"{path}: not readable as JSON ({e})")
    model = result.get("config", {}).get("model") if isinstance(result, dict) else None
    if not isinstance(model, dict):
        raise BadInput(f"{path}: no config.model (expected the resolved config of a tsi run)")
    if model.get("name") != MODEL:
        raise BadInput(f"{path}: config.model.name is {model.get('name')!r}, expected {MODEL!r}")
    for key, kind in (("k_x", float), ("k_y", float), ("n_x", int), ("n_y", int), ("eps", float)):
        value = model.get(key)
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not value > 0 \
                or (kind is int and value != int(value)):
            raise BadInput(f"{path}: config.model.{key} is {value!r}, expected a positive "
                           + ("integer" if kind is int else "number"))
    return path, result


def as_particles(values, name):
    """An N x 4 array of finite float64 from an N x 4 array or a flat one of 4 N values."""
    try:
        u = np.asarray(values, dtype=np.float64)
    except (TypeError, ValueError):
        raise BadInput(f"{name}: expected real numbers (x1 x2 v1 v2 per particle)")
    if u.ndim == 1 and u.size % 4 == 0 and u.size > 0:
        u = u.reshape(-1, 4)
    if u.ndim != 2 or u.shape[1] != 4 or u.shape[0] == 0:
        raise BadInput(f"{name}: shape {u.shape}, expected N x 4 (x1 x2 v1 v2 per particle)")
    if not np.all(np.isfinite(u[:, :2])):
        raise BadInput(f"{name}: {int(np.sum(~np.isfinite(u[:, :2])))} non-finite positions")
    return u


def load_npy(path):
    try:
        with open(path, "rb") as f:
            if f.read(6) != b"\x93NUMPY":
                raise BadInput(f"{path}: not a .npy file (no NumPy header; expected an N x 4 float64 array)")
        return np.load(path, allow_pickle=False)
    except (OSError, ValueError) as e:
        raise BadInput(f"{path}: not a readable .npy file ({e}; expected an N x 4 float64 array)")


def final_particles(run_dir, result):
    path = os.path.join(run_dir, "u_final.npy")
    if os.path.isfile(path):
        return as_particles(load_npy(path), path)
    inline = result.get("u_final")
    if isinstance(inline, list) and inline:  # a small run's state, also in result.json
        return as_particles(inline, os.path.join(run_dir, "result.json") + ": u_final")
    raise BadInput(f"{path}: not found (expected the N x 4 final state a vlasov-poisson-2d run writes)")


def initial_particles(run_dir, result):
    """(particles at t = 0, where they came from), or (None, why not)."""
    dense = result.get("dense_output")
    if isinstance(dense, dict) and 0 in (dense.get("times") or []):
        i = dense["times"].index(0)
        u = dense.get("u")
        if isinstance(u, dict):  # above 4096 values: in u_times.npy, shape (times, N, 4)
            path = os.path.join(run_dir, u.get("file", "u_times.npy"))
            if os.path.isfile(path):
                arr = load_npy(path)
                if arr.ndim >= 2 and arr.shape[0] == len(dense["times"]):
                    return as_particles(arr[i], path + f"[{i}]"), "dense output at t = 0"
        elif isinstance(u, list) and i < len(u) and u[i] is not None:
            return as_particles(u[i], "result.json: dense_output.u"), "dense output at t = 0"
    particles = result["config"]["model"].get("particles")
    if isinstance(particles, str):
        path = particles if os.path.isabs(particles) else os.path.join(run_dir, particles)
        if not os.path.isfile(path):
            return None, f"the particle file {particles} is not there any more"
        if path.endswith(".npy"):
            return as_particles(load_npy(path), path), os.path.basename(path)
        raw = np.fromfile(path, dtype="<f8")  # the UA-PIC peer's layout
        return as_particles(raw, path), os.path.basename(path)
    return None, ("sampled particles are not written by a run "
                  "(add \"output\": {\"times\": [0]} to the config to keep them)")


def density(u, model):
    """Particles per cell scaled to a mean of 1 (the model's weights |box| / N), on n_x x n_y cells."""
    lx, ly = 2 * math.pi / model["k_x"], 2 * math.pi / model["k_y"]
    nx, ny = int(model["n_x"]), int(model["n_y"])
    x1, x2 = np.mod(u[:, 0], lx), np.mod(u[:, 1], ly)
    counts, ex, ey = np.histogram2d(x1, x2, bins=[nx, ny], range=[[0, lx], [0, ly]])
    return counts * (nx * ny) / len(u), ex, ey


def density_figure(result, final, initial=None, initial_source=""):
    model = result["config"]["model"]
    panels = [(initial, f"t = 0 ({initial_source})")] if initial is not None else []
    t = result.get("t_reached", result.get("t_end"))
    status = result.get("status", "completed")
    panels.append((final, f"t = {t:g}" + ("" if status == "completed" else f" ({status})")))
    grids = [density(u, model) for u, _ in panels]
    vmax = max(float(g[0].max()) for g in grids)
    lx, ly = 2 * math.pi / model["k_x"], 2 * math.pi / model["k_y"]
    # A panel 3.4 inches high and as wide as the box (plus its colour bar); panels side by side
    # for a box about square or tall, one above the other for a wide one.
    aspect = lx / ly
    pw, ph = 3.4 * aspect + 1.6, 3.4 + 0.9
    stacked = aspect > 1.3 and len(panels) > 1
    shape = (len(panels), 1) if stacked else (1, len(panels))
    fig, axes = plt.subplots(*shape, figsize=(pw * shape[1], ph * shape[0] + 0.4), squeeze=False,
                             constrained_layout=True)
    for ax, (rho, ex, ey), (_, label) in zip(axes.flat, grids, panels):
        mesh = ax.pcolormesh(ex, ey, rho.T, cmap="viridis", vmin=0.0, vmax=vmax, shading="flat")
        ax.set(xlabel="x1", ylabel="x2", xlim=(0, lx), ylim=(0, ly), title=label)
        ax.set_aspect("equal")
        fig.colorbar(mesh, ax=ax, label="density (uniform = 1)", shrink=0.9)
    distribution = model.get("distribution", "") if not isinstance(model.get("particles"), str) else "from a file"
    fig.suptitle(f"{MODEL}: particle density on {model['n_x']} x {model['n_y']} cells\n"
                 f"eps = {model['eps']:g}, t_end = {result.get('t_end', t):g}, N = {len(final)} "
                 f"({distribution})", fontsize=10)
    return fig


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0],
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("run_dir", metavar="RUN_DIR", help="a vlasov-poisson-2d run's --out directory")
    parser.add_argument("--out", metavar="FILE.png", help="the figure (default RUN_DIR/density.png)")
    parser.add_argument("--initial", metavar="FILE.npy", help="an N x 4 file of particles to draw as t = 0")
    args = parser.parse_args(argv)
    prog = os.path.basename(sys.argv[0]) if argv is None else "plot_pic_density.py"
    try:
        if not os.path.isdir(args.run_dir):
            raise BadInput(f"{args.run_dir}: not a directory (expected a run's --out directory)")
        _, result = read_result(args.run_dir)
        final = final_particles(args.run_dir, result)
        if args.initial:
            if not os.path.isfile(args.initial):
                raise BadInput(f"{args.initial}: not found (expected an N x 4 .npy file of particles)")
            initial, source = as_particles(load_npy(args.initial), args.initial), args.initial
        else:
            initial, source = initial_particles(args.run_dir, result)
        if initial is None:
            print(f"  no initial density: {source}")
        elif len(initial) != len(final):
            raise BadInput(f"initial particles ({source}): {len(initial)}, expected as many as "
                           f"u_final.npy's {len(final)}")
    except BadInput as e:
        print(f"{prog}: error: {e}", file=sys.stderr)
        return 2
    out = args.out or os.path.join(args.run_dir, "density.png")
    fig = density_figure(result, final, initial, source if initial is not None else "")
    try:
        fig.savefig(out, dpi=110)
    except OSError as e:
        print(f"{prog}: error: {out}: could not be written ({e})", file=sys.stderr)
        return 3
    print(f"  plot: {out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
