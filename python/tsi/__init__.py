"""tsi from Python: runs, studies and models written in Python, through the runner's own code.

    import tsi
    r = tsi.run({"model": {"name": "henon-heiles", "eps": 0.01}, "scheme": {"name": "se1"},
                 "time": {"h": 0.125, "t_end": 1}, "reference": {}})
    print(r.error, r.u_final.shape, r.invariants["err_H"].max())

    s = tsi.study({"kind": "convergence", "base": {...}, "vary": {...}}, jobs=2)
    s.rows            # one dict per run, as table.csv
    s.to_pandas()     # the same as a DataFrame (pandas needed)
    s.plot()          # the figure `tsi study` draws

A config or study is the dict `tsi run` / `tsi study` read as JSON, resolved by the same
code: bad input raises tsi.ConfigError, whose .field names the config path. The
computation runs with the GIL released; Ctrl-C stops it at its next step and raises
tsi.Interrupted (a KeyboardInterrupt) carrying what was computed.
"""
import builtins
import itertools
import json
import math
import os
import sys
import warnings

import numpy as np

from . import _tsi
from ._tsi import ConfigError, Error, PluginError

__version__ = _tsi.version
__all__ = ["run", "study", "list", "load_plugin", "register_model", "register_field", "RunResult", "StudyResult", "Error",
           "ConfigError", "PluginError", "Interrupted", "plugin_directory"]

for _warning in _tsi.init():
    warnings.warn("tsi: plugin not loaded: " + _warning)


class Interrupted(KeyboardInterrupt):
    """Ctrl-C (SIGINT) stopped a run or study; .result holds what was computed up to then."""

    def __init__(self, result):
        super().__init__("tsi: interrupted; what was computed is in .result")
        self.result = result


def _json_default(value):
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, complex):
        return [value.real, value.imag]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"{type(value).__name__} is not a JSON value")


def _dumps(value):
    return json.dumps(value, default=_json_default, allow_nan=False)


def _state(values):
    """A state from result.json: numbers, or [re, im] pairs for a complex model (None for a
    state kept only in its .npy file: {"file": ..., "dtype": ..., "shape": ...})."""
    if values is None or isinstance(values, dict):
        return None
    a = np.asarray(values, dtype=float)
    return a[..., 0] + 1j * a[..., 1] if a.ndim == 2 else a


def _dense_output(native, result, u_final):
    """(times, u_times) of a run with output.times, from the run itself or its result.json."""
    entry = result.get("dense_output")
    if not entry:
        return None, None
    times = np.array(entry["times"], dtype=float)
    states = native.get("u_times")
    if states is None:  # read back: result.json holds small ones inline
        states = [_state(u) if u is not None else None for u in entry["u"]] if isinstance(entry["u"], list) else None
    if states is None or u_final is None:
        return times, None
    blank = np.full(np.shape(u_final), np.nan, dtype=np.asarray(u_final).dtype)
    return times, np.stack([np.asarray(u) if u is not None else blank for u in states])


def _columns(csv_text):
    """invariants.csv as a dict of numpy arrays, one per column (empty values are NaN)."""
    lines = csv_text.splitlines()
    if not lines:
        return {}
    header = lines[0].split(",")
    rows = [[float(x) if x else math.nan for x in line.split(",")] for line in lines[1:] if line]
    data = np.array(rows, dtype=float).reshape(len(rows), len(header))
    return {name: data[:, k].copy() for k, name in enumerate(header)}


def list(what=""):
    """What is registered, as `tsi list --json` prints it: {"models": [...], "reformulations":
    [...], "schemes": [...]}, or one of those lists when `what` names it."""
    listing = json.loads(_tsi.list(what))
    return listing[what] if what else listing


def load_plugin(path):
    """Loads a plugin library (as --plugin); its models and schemes are then usable by name."""
    _tsi.load_plugin(os.fspath(path))


def plugin_directory():
    """The shipped plugins' directory this package loaded."""
    return _tsi.plugin_directory()


class RunResult:
    """One run: what `tsi run` writes to result.json and invariants.csv, as Python objects.

    status       "completed", "blow-up", "failed" or "interrupted" (message says why)
    u_final      the final state in physical variables (numpy; complex for a complex model)
    times, u_times   output.times and u there (numpy, one row per time, NaN where the run did
                 not reach it); None without output.times
    error        the relative error against the reference (None without a reference)
    error_estimate   the estimated relative error without a reference (output.error_estimate;
                 None without one); result["error_estimate"] says how it was made
    reference    the reference's final state (numpy), reference_info its settings and cost
    invariants   invariants.csv by column: t, H, I, m, err_H, err_I, err_m, tau_roughness,
                 tau_spread and the model's own (numpy arrays; as in the file, the values carry
                 17 significant digits and the changes err_* 7)
    result       result.json as a dict, config the resolved config
    """

    def __init__(self, native, run_id="", label="", assignments=None):
        self.result = json.loads(native["result"])
        self.id, self.label = run_id, label
        self.assignments = assignments or {}
        self.ok = bool(native["ok"])
        self.status = self.result.get("status", "failed")
        self.message = native["message"]
        self.config = self.result.get("config", {})
        self.steps = self.result.get("steps")
        self.t_end = self.result.get("t_end")
        self.t_reached = self.result.get("t_reached")
        # The states come as numpy arrays from the run itself (result.json holds a large one
        # only as the name of its .npy file); from result.json when given only that.
        self.u_final = native.get("u_final")
        if self.u_final is None:
            self.u_final = _state(self.result.get("u_final"))
        self.times, self.u_times = _dense_output(native, self.result, self.u_final)
        err = self.result.get("error", {})
        self.error = err.get("relative")
        self.error_absolute = err.get("absolute")
        self.reference_info = err.get("reference")
        # The error estimate without a reference (output.error_estimate), None without one.
        self.error_estimate = self.result.get("error_estimate", {}).get("relative")
        self.reference = native.get("reference_u_final")
        if self.reference is None and self.reference_info:
            self.reference = _state(self.reference_info.get("u_final"))
        self.invariants = _columns(native["csv"])
        self.t = self.invariants.get("t")
        self.wall_seconds = self.result.get("wall_seconds")
        self.warnings = self.result.get("warnings", [])

    def __repr__(self):
        where = f"{self.id} " if self.id else ""
        error = f", error={self.error:.3e}" if self.error is not None else ""
        return f"<tsi.RunResult {where}{self.status}, steps={self.steps}{error}>"


class StudyResult:
    """A study: the table (one row per run, the columns of table.csv, each varied path a key
    of its own), the convergence or work-at-error summary of study.json, and every run."""

    def __init__(self, native):
        head = json.loads(native["study"])
        self.kind, self.title, self.spec = head["kind"], head["title"], head["study"]
        self.varied = head["varied"]
        # Base settings some runs do not take (path -> their ids); the other runs use them.
        self.not_used = head.get("not_used", {})
        self.wall_seconds, self.jobs = head["wall_seconds"], head["jobs"]
        self.convergence = head.get("convergence")
        self.work_at_error = head.get("work_at_error")
        self.runs = [RunResult(r, r["id"], r["label"], json.loads(r["assignments"])) for r in native["runs"]]
        self.rows = []
        for row, run in zip(head["table"], self.runs):
            for path in self.varied:
                row.setdefault(path, run.assignments.get(path))
            self.rows.append(row)

    def run(self, run_id):
        """The run with this id (r0001, ...)."""
        for r in self.runs:
            if r.id == run_id:
                return r
        raise KeyError(run_id)

    def to_pandas(self):
        """The table as a pandas DataFrame, indexed by run id."""
        import pandas as pd

        return pd.DataFrame(self.rows).set_index("id", drop=False)

    @property
    def table(self):
        """The table: a DataFrame when pandas imports, else the rows."""
        try:
            return self.to_pandas()
        except ImportError:
            return self.rows

    def plot(self, path=None):
        """The figure `tsi study` draws for this kind (tsi.plot); saved to `path` if given."""
        from . import plot

        return plot.figure(self, path)

    def __repr__(self):
        failed = sum(r["status"] != "completed" for r in self.rows)
        return f"<tsi.StudyResult {self.kind} {self.title!r}: {len(self.rows)} runs, {failed} not completed>"


def _progress(progress):
    # Default: on in a Jupyter notebook (its kernel is loaded), off in a script.
    return "ipykernel" in sys.modules if progress is None else bool(progress)


def run(config, *, out=None, threads=None, progress=None):
    """Runs one config (a dict, as the JSON of `tsi run`) and returns a RunResult. With `out`,
    also writes result.json and invariants.csv there. A run that fails or blows up part-way
    is returned with its status and message; bad input raises tsi.ConfigError. `threads`:
    threads for a large two-scale tau grid, as `tsi --threads` (default: all cores).
    `progress`: a line on sys.stderr (step, t, simulated time per second, time left),
    rewritten at most once a second and erased at the end; default on in a Jupyter notebook,
    off elsewhere."""
    native = _tsi.run(_dumps(config), os.fspath(out) if out else "", int(threads or 0), _progress(progress))
    result = RunResult(native)
    if native["interrupted"]:
        raise Interrupted(result)
    return result


def _overrides(overrides):
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        return [f"{path}={_dumps(value)}" for path, value in overrides.items()]
    return builtins.list(overrides)


def study(spec, jobs=None, *, overrides=None, out=None, progress=None):
    """Runs a study (a dict, as the JSON of `tsi study`) on `jobs` threads (default: all
    cores) and returns a StudyResult. `overrides` are --set assignments on the base, a dict
    {"path": value} or a list of "path=value"; with `out`, the study's files are written there
    (table.csv, study.json, runs/). `progress`: a line on sys.stderr (runs done of all, the
    current run, time left), as tsi.run's; default on in a Jupyter notebook, off elsewhere."""
    native = _tsi.study(_dumps(spec), int(jobs or 0), _overrides(overrides), os.fspath(out) if out else "",
                        _progress(progress))
    result = StudyResult(native)
    if native["interrupted"]:
        raise Interrupted(result)
    return result


def register_model(name, cls=None, *, params=None, aliases=(), n_tau=64, nonlinearity_degree=0, summary=""):
    """Registers a model written in Python under `name` (a decorator when `cls` is left out).

    The class is built as cls(eps, **params) for every run, and provides (tsi.models has a
    complete example, Henon-Heiles):
      dim                          the number of entries of u
      is_complex                   optional, False: real states are float64 arrays
      linear_flow(taus, U)         e^{JM tau_j} applied to column j of U (dim x n)
      nonlinear_field(U)           J grad H1 of every column
      filtered_field(taus, U)      optional: f_tau(u) = e^{-JM tau} J grad H1(e^{JM tau} u) per
                                   column, the two-scale hot path (otherwise composed of the two
                                   above, three calls)
      apply_M(u), apply_J(u), H1(u), initial_value()
    `params` maps the model's own parameters to their defaults (eps and u0 are common to all).
    Registering a name again replaces the earlier Python class; a C++ model's name is refused.
    """

    def register(c):
        _tsi.register_model(name, c, _dumps(params or {}), builtins.list(aliases), int(n_tau),
                            int(nonlinearity_degree), summary)
        return c

    return register if cls is None else register(cls)


def register_field(name, f=None, *, dim=0, time_dependent=False, is_complex=False, u0=None, summary=""):
    """Registers a Python function f(t, u) as the field `name` of the "matrix" model, whose A is
    a matrix in the run's config (a decorator when `f` is left out):

        @tsi.register_field("my-f", dim=4)
        def f(t, u):                  # t: n times, u: dim x n, one state per column
            return np.array([0 * u[0], u[3], 2 * u[0] * u[1], -u[1] - u[0] ** 2 + u[1] ** 2])

        tsi.run({"model": {"name": "matrix", "A": A, "f": "my-f", "eps": 1e-4, "u0": u0}, ...})

    f returns an array of u's shape (float64 states, complex128 with is_complex). `dim`: the
    number of entries it takes (0: any, A's size decides). `time_dependent`: f depends on t (the
    model then carries t as one more variable; runs start at t = 0). `u0`: the default initial
    value. Registering a name again replaces the earlier function; a plugin's name is refused.
    """

    def register(func):
        _tsi.register_field(name, func, int(dim), bool(time_dependent), bool(is_complex),
                            None if u0 is None else np.asarray(u0, dtype=complex), summary)
        return func

    return register if f is None else register(f)


_solve_fields = itertools.count()


def solve(A, f, eps, u0, t_span, *, scheme="eab", h=None, n_tau=32, times=None, time_dependent=True,
          error_estimate=False, out=None, threads=None):
    """u' = (1/eps) A u + f(t, u) from u(t0) = u0 over t_span = (t0, t1), as HOODESolver.jl's
    solve: returns (t, u, result), t the times (the steps t0 + k h, or `times`), u the states
    there (numpy, one row per time) and result the RunResult (its error, invariants, cost).

        t, u, r = tsi.solve(A, lambda t, u: ..., 1e-4, [0.55, 0.12, 0.03, 0.89], (0, 3), h=0.1)

    A: a matrix whose e^{2 pi A} is I (the "matrix" model; complex entries allowed). f(t, u): t an
    array of n times, u the dim x n states, one per column; it returns an array of u's shape.
    scheme: a scheme's name (default eab, order 4) or its config section ({"name": "eab",
    "order": 6}). h: the step (default (t1 - t0) / 100, as HOODESolver.jl; rounded to a whole
    number of steps). times: the times to return u at (any times in t_span: between the steps u
    comes from the two-scale solution interpolated in t). time_dependent=False when f does not
    use t (one variable fewer). error_estimate=True: the run also estimates its error without a
    reference (Richardson's, from the same run at h / 2 and 2 h, as HOODESolver.jl's
    getprecision; the number of steps is then made even): result.error_estimate, and the whole
    record in result.result["error_estimate"].
    """
    t0, t1 = float(t_span[0]), float(t_span[1])
    if not t1 > t0:
        raise ValueError(f"t_span: got ({t0}, {t1}), expected t0 < t1")
    length = t1 - t0
    steps = max(1, int(round(length / (length / 100 if h is None else float(h)))))
    if error_estimate and steps % 2:
        steps += 1  # the estimate reruns at 2 h
    step = length / steps
    A = np.asarray(A)
    u0 = np.asarray(u0)
    is_complex = bool(np.iscomplexobj(A) or np.iscomplexobj(u0))
    # The field runs from t = 0: f at t0 + t (the equation is otherwise invariant under a shift in t).
    name = f"tsi-solve-{next(_solve_fields)}"
    register_field(name, lambda t, u: f(t + t0, u), dim=u0.size, time_dependent=time_dependent,
                   is_complex=is_complex)
    def entry(x):  # a number of the config: [re, im] for a complex model
        z = complex(x)
        return [z.real, z.imag] if is_complex else z.real

    grid = t0 + step * np.arange(steps + 1)
    wanted = grid if times is None else np.asarray(times, dtype=float)
    config = {"model": {"name": "matrix", "eps": float(eps), "f": name,
                        "A": [[entry(a) for a in row] for row in A.tolist()],
                        "u0": [entry(x) for x in u0.ravel().tolist()]},
              "reformulation": {"name": "two-scale", "n_tau": int(n_tau)},
              "scheme": {"name": scheme} if isinstance(scheme, str) else dict(scheme),
              "time": {"h": step, "t_end": length},
              "output": {"times": [min(max(t - t0, 0.0), length) for t in wanted.tolist()]}}
    if error_estimate:
        config["output"]["error_estimate"] = "richardson"
    result = run(config, out=out, threads=threads)
    if not result.ok:
        raise RuntimeError(f"tsi.solve: the run {result.status}: {result.message}")
    return wanted, result.u_times, result


def __getattr__(name):
    # tsi.plot (matplotlib) and tsi.models are imported on first use.
    if name in ("plot", "models"):
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'tsi' has no attribute {name!r}")
