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
code: bad input raises tsi.ConfigError, whose .field names the config path (a NaN in the
dict too) or the bad argument of run, study, solve, register_model or register_field, before
anything is computed. The computation runs with the GIL released; Ctrl-C stops it at its next step and raises
tsi.Interrupted (a KeyboardInterrupt) carrying what was computed.
"""
import builtins
import inspect
import itertools
import json
import math
import numbers
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


def _scalar(value):
    """A numpy scalar as Python's (a long double too, rounded to a double)."""
    if isinstance(value, np.complexfloating):
        return complex(value)
    return float(value) if isinstance(value, np.floating) else value.item()


def _json_default(value):
    if isinstance(value, np.generic):
        return _scalar(value)
    if isinstance(value, np.ndarray):
        return value.tolist()
    if isinstance(value, complex):
        return [value.real, value.imag]
    if isinstance(value, os.PathLike):
        return os.fspath(value)
    raise TypeError(f"{type(value).__name__} is not a JSON value")


# ---- Arguments: a bad one raises tsi.ConfigError naming it (and the value, and what was
# expected) before anything is computed, as the runner's config reader does for a config.

_MAX_THREADS = 1024  # as the runner's --threads
_MAX_N_TAU = 1 << 20  # as reformulation.n_tau
_MAX_DEGREE = 126  # se2 integrates a degree-d nonlinearity with (d + 2) / 2 <= 64 nodes
_JSON_DEPTH = 64  # as the config reader's
_MAX_MATRIX_DIM = _tsi.max_matrix_model_dim
_MAX_OUTPUT_TIMES = _tsi.max_output_times
_MAX_STEPS = _tsi.max_steps


def _refuse(field, message):
    """The tsi.ConfigError for argument or config path `field`, worded as the runner's."""
    error = ConfigError(f"{field}: {message}")
    error.field = field
    return error


def _show(value):
    """A value as a message quotes it: short, with its type."""
    if isinstance(value, np.ndarray):
        return f"an array of shape {value.shape} and dtype {value.dtype}"
    try:
        text = repr(value)
    except Exception:  # a broken __repr__ is the caller's: the type still says enough
        text = "?"
    if len(text) > 60:
        text = text[:57] + "..."
    return f"{text} ({type(value).__name__})"


def _is_bool(value):
    return isinstance(value, (bool, np.bool_))


def _integer(field, value, low, high, expected=None):
    """An int from an int, a numpy integer or a float with an integer value (as the config
    reader takes 32.0 for 32); bools, strings and fractions are refused."""
    expected = expected or f"an integer from {low} to {high}"
    n = None
    if isinstance(value, numbers.Integral) and not _is_bool(value):
        n = int(value)
    elif isinstance(value, numbers.Real) and not _is_bool(value):
        x = float(value)
        n = int(x) if math.isfinite(x) and x.is_integer() else None
    if n is None or not low <= n <= high:
        raise _refuse(field, f"got {_show(value)}, expected {expected}")
    return n


def _boolean(field, value):
    if not _is_bool(value):
        raise _refuse(field, f"got {_show(value)}, expected True or False")
    return bool(value)


def _real(field, value, expected="a finite real number"):
    x = None
    if isinstance(value, numbers.Real) and not _is_bool(value):
        try:
            x = float(value)
        except OverflowError:  # an int beyond a double
            x = None
    if x is None or not math.isfinite(x):
        raise _refuse(field, f"got {_show(value)}, expected {expected}")
    return x


def _is_text(value):
    """A str the native module can take: UTF-8 (a lone surrogate is not)."""
    if not isinstance(value, str):
        return False
    try:
        value.encode("utf-8")
    except UnicodeEncodeError:
        return False
    return True


def _text(field, value, expected="a string"):
    if not _is_text(value):
        raise _refuse(field, f"got {_show(value)}, expected {expected}")
    return str(value)


def _name(field, value, kind):
    """A registration name: a non-empty printable string without surrounding spaces."""
    expected = f"the {kind}'s name: a non-empty printable string without spaces around it"
    text = _text(field, value, expected)
    if not text or text != text.strip() or not text.isprintable():
        raise _refuse(field, f"got {text!r}, expected {expected}")
    return text


def _directory(field, value):
    """An output directory as the native module takes it ("" for none)."""
    if value is None:
        return ""
    if isinstance(value, (str, bytes, os.PathLike)):
        try:
            path = os.fsdecode(os.fspath(value))
        except TypeError:  # an __fspath__ that returns neither str nor bytes
            path = None
        if _is_text(path) and "\0" not in path:
            return path
    raise _refuse(field, f"got {_show(value)}, expected a directory (a str, bytes or os.PathLike) or None")


def _callback(field, function, call, arguments):
    """Refuses a non-callable, or one whose signature cannot take `arguments` positional values
    (a signature Python cannot tell, as a C function's, is taken on trust)."""
    if not callable(function):
        raise _refuse(field, f"got {_show(function)}, expected a function {call}")
    try:
        signature = inspect.signature(function)
    except (TypeError, ValueError):
        return
    try:
        signature.bind(*([None] * arguments))
    except TypeError as e:
        raise _refuse(field, f"{_callable_name(function)}{signature} cannot be called as {call}: {e}") from None


def _callable_name(function):
    return getattr(function, "__qualname__", None) or type(function).__name__


def _json_problem(value, path, depth, inside):
    """(path, message) of the first value in `value` that JSON cannot hold, or None."""
    if isinstance(value, np.generic):
        value = _scalar(value)
    if value is None or isinstance(value, (bool, int, str)):
        return None
    if isinstance(value, float):
        return None if math.isfinite(value) else (path, f"got {value}, expected a finite number (JSON has no "
                                                        "NaN or infinity)")
    if isinstance(value, complex):
        return None if math.isfinite(value.real) and math.isfinite(value.imag) else (
            path, f"got {value}, expected finite real and imaginary parts (JSON has no NaN or infinity)")
    if isinstance(value, os.PathLike):
        try:
            return None if isinstance(os.fspath(value), str) else (path, f"got {_show(value)}, expected a str path")
        except TypeError as e:  # an __fspath__ that returns neither str nor bytes
            return path, f"got {_show(value)}, expected a str path ({e})"
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc":
            bad = np.argwhere(~np.isfinite(value))
            if len(bad) == 0:
                return None
            index = tuple(int(i) for i in bad[0])
            where = path + "".join(f"[{i}]" for i in index)
            return where, f"got {value[index]}, expected a finite number (JSON has no NaN or infinity)"
        if value.dtype.kind in "biuU":
            return None
        value = value.tolist()
    if isinstance(value, (dict, builtins.list, tuple)):
        if depth >= _JSON_DEPTH:
            return path, f"nested deeper than {_JSON_DEPTH} levels; no config needs that"
        if id(value) in inside:
            return path, "contains itself"
        inside.add(id(value))
        try:
            if isinstance(value, dict):
                for key, item in value.items():
                    if not (key is None or isinstance(key, (str, int, float))):  # JSON writes these as strings
                        return path, f"has the key {_show(key)}, expected string keys"
                    found = _json_problem(item, f"{path}.{key}" if path else str(key), depth + 1, inside)
                    if found:
                        return found
            else:
                for k, item in enumerate(value):
                    found = _json_problem(item, f"{path}[{k}]", depth + 1, inside)
                    if found:
                        return found
        finally:
            inside.discard(id(value))
        return None
    return path, f"got {_show(value)}, expected a JSON value: a number, string, boolean, None, list or dict"


def _dumps(value, what="config", prefix=""):
    """JSON text of a config, study or parameters; a value JSON cannot hold (NaN, infinity, a
    set, an object) is a ConfigError naming its path (`prefix` + the path inside, or `what`)."""
    try:
        return json.dumps(value, default=_json_default, allow_nan=False)
    except (TypeError, ValueError, RecursionError) as failure:
        found = _json_problem(value, prefix.rstrip("."), 0, set()) or ("", f"cannot be written as JSON: {failure}")
        raise _refuse(found[0] or what, found[1]) from None


def _name_is_free(field, name, kind, provider):
    """Refuses a name or alias another provider holds (the core, a plugin, another name
    registered from Python); the same name registered from Python is replaced."""
    for entry in json.loads(_tsi.list(kind))[kind]:
        if entry.get("provider") == provider or name not in [entry["name"], *entry.get("aliases", [])]:
            continue
        how = "" if name == entry["name"] else f" as an alias of \"{entry['name']}\""
        raise _refuse(field, f"\"{name}\" is already registered by {entry.get('provider')}{how}; expected a name "
                             f"of its own (registering the same name from Python again replaces it)")


def _numbers(field, value, expected):
    """A numpy array of numbers (integers, reals or complex, all finite) from an array-like."""
    if value is None or isinstance(value, (str, bytes, dict)):
        raise _refuse(field, f"got {_show(value)}, expected {expected}")
    try:
        a = np.asarray(value)
    except (TypeError, ValueError) as e:  # rows of different lengths
        raise _refuse(field, f"got {_show(value)}, expected {expected} ({e})") from None
    if a.dtype.kind not in "iufc":
        raise _refuse(field, f"got {_show(value)}, expected {expected} of numbers")
    bad = np.argwhere(~np.isfinite(a))
    if len(bad):
        index = tuple(int(i) for i in bad[0])
        raise _refuse(field + "".join(f"[{i}]" for i in index), f"got {a[index]}, expected a finite number")
    return a


def _real_or_zero_imaginary(field, a, what):
    """Refuses complex entries with an imaginary part where the problem is real (it would be dropped)."""
    if np.iscomplexobj(a) and np.any(a.imag != 0):
        index = tuple(int(i) for i in np.argwhere(a.imag != 0)[0])
        raise _refuse(field + "".join(f"[{i}]" for i in index),
                      f"got {a[index]}, expected a real number: {what} would drop the imaginary part")
    return a.real if np.iscomplexobj(a) else a


def _threads(threads):
    if threads is None:
        return 0
    return _integer("threads", threads, 1, _MAX_THREADS, f"an integer from 1 to {_MAX_THREADS} (or None: all cores)")


def _jobs(jobs):
    if jobs is None:
        return 0
    return _integer("jobs", jobs, 0, _MAX_THREADS, f"an integer from 1 to {_MAX_THREADS} (0 or None: all cores)")


# What a model class provides (register_model's docstring): the methods and their arguments
# after self, those of a Hamiltonian model (hamiltonian = True, the default), and the optional ones.
_MODEL_METHODS = {"linear_flow": "taus, U", "nonlinear_field": "U", "initial_value": ""}
_HAMILTONIAN_METHODS = {"apply_M": "u", "apply_J": "u", "H1": "u"}
_OPTIONAL_METHODS = {"filtered_field": "taus, U", "nonlinear_field_derivative": "U, V", "apply_A": "u"}
_COMMON_PARAMS = ("name", "eps", "u0")  # the model section's own keys


def _model_params(params):
    if params is None:
        return {}
    if not isinstance(params, dict):
        raise _refuse("params", f"got {_show(params)}, expected a dict {{\"parameter\": default}}")
    for key in params:
        if not isinstance(key, str) or not key.isidentifier():
            raise _refuse("params", f"has the key {_show(key)}, expected parameter names that are Python "
                                    "identifiers (the class is built as cls(eps, **params))")
        if key in _COMMON_PARAMS:
            raise _refuse(f"params.{key}", f"is the model section's own (model.{key}), common to every model; "
                                           "params holds the model's own parameters")
    return params


def _class_value(cls, attribute):
    """A class attribute as a plain value (None when absent or computed: a property)."""
    value = inspect.getattr_static(cls, attribute, None)
    return None if hasattr(type(value), "__get__") else value


def _model_class(cls, params):
    """Refuses what cannot be a model: a non-callable, a class that cannot be built as
    cls(eps, **params), a class without a method a model needs or with one that takes the
    wrong arguments, and class-level dim, is_complex or hamiltonian of the wrong type."""
    if not callable(cls):
        raise _refuse("cls", f"got {_show(cls)}, expected a class, built as cls(eps, **params)")
    try:
        signature = inspect.signature(cls)
    except (TypeError, ValueError):
        signature = None
    if signature is not None:
        try:
            signature.bind(None, **params)
        except TypeError as e:
            raise _refuse("cls", f"{_callable_name(cls)}{signature} cannot be built as cls(eps, **params) with "
                                 f"params {builtins.list(params)}: {e}") from None
    if not isinstance(cls, type):
        return
    dim = _class_value(cls, "dim")
    if dim is not None and not (isinstance(dim, numbers.Integral) and not _is_bool(dim) and dim > 0):
        raise _refuse("cls.dim", f"got {_show(dim)}, expected a positive integer")
    for flag in ("is_complex", "hamiltonian"):
        value = _class_value(cls, flag)
        if value is not None and not _is_bool(value):
            raise _refuse(f"cls.{flag}", f"got {_show(value)}, expected True or False")
    hamiltonian = _class_value(cls, "hamiltonian")
    required = dict(_MODEL_METHODS, **(_HAMILTONIAN_METHODS if hamiltonian in (None, True) else {}))
    for method, arguments in dict(required, **_OPTIONAL_METHODS).items():
        member = inspect.getattr_static(cls, method, None)
        if member is None:
            if method in required:
                raise _refuse(f"cls.{method}", f"{cls.__name__} has no method {method}({arguments}); a model "
                                               f"provides {', '.join(required)}")
            continue
        call = f"{method}({arguments})"
        if isinstance(member, staticmethod):
            function, bound = member.__func__, 0
        elif isinstance(member, classmethod):
            function, bound = member.__func__, 1
        elif inspect.isfunction(member):
            function, bound = member, 1
        elif callable(member):
            continue
        else:
            raise _refuse(f"cls.{method}", f"got {_show(member)}, expected a method {call}")
        try:
            signature = inspect.signature(function)
        except (TypeError, ValueError):
            continue
        count = bound + (len(arguments.split(",")) if arguments else 0)
        try:
            signature.bind(*([None] * count))
        except TypeError as e:
            raise _refuse(f"cls.{method}", f"{cls.__name__}.{method}{signature} cannot be called as {call}: "
                                           f"{e}") from None


def _span(t_span):
    expected = "(t0, t1): two finite numbers, t0 < t1"
    items = None
    if not isinstance(t_span, (str, bytes, dict)):
        try:
            items = builtins.list(t_span)
        except TypeError:
            items = None
    if items is None or len(items) != 2:
        raise _refuse("t_span", f"got {_show(t_span)}, expected {expected}")
    t0, t1 = (_real(f"t_span[{k}]", x) for k, x in enumerate(items))
    if not t0 < t1:
        raise _refuse("t_span", f"got ({t0}, {t1}), expected t0 < t1")
    if not math.isfinite(t1 - t0):
        raise _refuse("t_span", f"got ({t0}, {t1}), whose length t1 - t0 is beyond a double")
    return t0, t1


def _times(times, t0, t1):
    expected = f"a 1-d list of 1 to {_MAX_OUTPUT_TIMES} times in t_span ({t0}, {t1}) (or None: the steps)"
    a = _numbers("times", times, expected)
    if a.dtype.kind == "c" or a.ndim != 1 or not 1 <= a.size <= _MAX_OUTPUT_TIMES:
        raise _refuse("times", f"got {_show(times)}, expected {expected}")
    slack = 4 * np.finfo(float).eps * max(abs(t0), abs(t1))  # the rounding of t0 + k dt
    outside = np.flatnonzero((a < t0 - slack) | (a > t1 + slack))
    if outside.size:
        k = int(outside[0])
        raise _refuse(f"times[{k}]", f"got {a[k]}, outside t_span ({t0}, {t1}): u is computed only there")
    return a.astype(float)


def _step_count(h, t0, t1, dim, is_complex, error_estimate, every_step):
    """The number of steps, refused before anything of that size is made: counted as a double
    (a tiny h gives more steps than an int array can hold)."""
    count = (t1 - t0) / h
    if every_step and count + 1 > _MAX_OUTPUT_TIMES:
        states = (count + 1) * dim * (16 if is_complex else 8)
        raise _refuse("h", f"got {h} for t_span ({t0}, {t1}): u at every step would be {count + 1:.6g} states of "
                           f"{dim} {'complex128' if is_complex else 'float64'}, {states:.3g} bytes, more than the "
                           f"{_MAX_OUTPUT_TIMES} times a run returns; pass times= (u there only) or a larger h")
    if count > _MAX_STEPS:
        raise _refuse("h", f"got {h} for t_span ({t0}, {t1}): {count:.3g} steps, more than a run takes "
                           f"({_MAX_STEPS:.0e}, the runner's --max-steps)")
    steps = max(1, int(round(count)))
    return steps + 1 if error_estimate and steps % 2 else steps  # the estimate reruns at 2 h


def _probe_field(f, t0, u0, is_complex):
    """f once at (t0, u0), as the run first calls it: what it cannot be (an exception, the
    wrong shape or type, a NaN, complex values for a real problem) is refused before the run."""
    dim = u0.size
    u = u0.astype(complex if is_complex else float).reshape(dim, 1)
    where = f"f(t, u) at t = t0 = {t0}, u = u0 (a {dim} x 1 column)"
    try:
        value = f(np.array([t0]), u)
    except Exception as e:
        raise _refuse("f", f"{where} raised {type(e).__name__}: {e}") from e
    try:
        a = np.asarray(value)
    except (TypeError, ValueError):
        a = np.asarray(None)
    if a.dtype.kind not in "iufc":
        raise _refuse("f", f"{where} returned {_show(value)}, expected an array of u's shape ({dim}, 1) of numbers")
    if a.shape != (dim, 1):
        raise _refuse("f", f"{where} returned shape {a.shape}, expected ({dim}, 1): u's shape, one column per state")
    if not np.all(np.isfinite(a)):
        raise _refuse("f", f"{where} returned {a[~np.isfinite(a)][0]}, expected finite values")
    if not is_complex and np.iscomplexobj(a) and np.any(a.imag != 0):
        raise _refuse("f", f"{where} returned complex values for a real problem (A and u0 real), whose imaginary "
                           "parts would be dropped: return real values, or pass a complex u0")


# The config paths of tsi.solve's run, by the argument each comes from (the runner names the path).
_SOLVE_ARGUMENTS = (("model.eps", "eps"), ("model.A", "A"), ("model.u0", "u0"), ("model.f", "f"),
                    ("reformulation.n_tau", "n_tau"), ("time.h", "h"), ("time.t_end", "t_span"),
                    ("output.times", "times"))


def _as_solve_argument(error):
    """A ConfigError of solve's run, renamed after the argument it comes from."""
    field = getattr(error, "field", "")
    for path, argument in _SOLVE_ARGUMENTS:
        if field == path or field.startswith((path + "[", path + ".")):
            renamed = argument + field[len(path):]
            message = str(error)
            return _refuse(renamed, message[len(field) + 2:] if message.startswith(field + ": ") else message)
    return error


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
    [...], "schemes": [...], "fields": [...]}, or one of those lists when `what` names it;
    `what="config"` gives the run config's sections and their keys (`tsi list config`)."""
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
    return "ipykernel" in sys.modules if progress is None else _boolean("progress", progress)


def run(config, *, out=None, threads=None, progress=None):
    """Runs one config (a dict, as the JSON of `tsi run`) and returns a RunResult. With `out`,
    also writes result.json and invariants.csv there. A run that fails or blows up part-way
    is returned with its status and message; bad input raises tsi.ConfigError. `threads`:
    threads for a large two-scale tau grid, as `tsi --threads` (default: all cores).
    `progress`: a line on sys.stderr (step, t, simulated time per second, time left),
    rewritten at most once a second and erased at the end; default on in a Jupyter notebook,
    off elsewhere."""
    threads, out, progress = _threads(threads), _directory("out", out), _progress(progress)
    native = _tsi.run(_dumps(config, "config"), out, threads, progress)
    result = RunResult(native)
    if native["interrupted"]:
        raise Interrupted(result)
    return result


def _overrides(overrides):
    if overrides is None:
        return []
    if isinstance(overrides, dict):
        for path in overrides:
            if not _is_text(path) or not path:
                raise _refuse("overrides", f"has the key {_show(path)}, expected config paths such as \"model.eps\"")
        return [f"{path}={_dumps(value, '--set ' + path, '--set ' + path)}" for path, value in overrides.items()]
    if isinstance(overrides, (builtins.list, tuple)):
        for k, item in enumerate(overrides):
            if not _is_text(item):
                raise _refuse(f"overrides[{k}]", f"got {_show(item)}, expected a \"path=value\" string")
        return [str(item) for item in overrides]
    raise _refuse("overrides", f"got {_show(overrides)}, expected a dict {{\"path\": value}} or a list of "
                               "\"path=value\" strings")


def study(spec, jobs=None, *, overrides=None, out=None, progress=None):
    """Runs a study (a dict, as the JSON of `tsi study`) on `jobs` threads (default: all
    cores) and returns a StudyResult. `overrides` are --set assignments on the base, a dict
    {"path": value} or a list of "path=value"; with `out`, the study's files are written there
    (table.csv, study.json, runs/). `progress`: a line on sys.stderr (runs done of all, the
    current run, time left), as tsi.run's; default on in a Jupyter notebook, off elsewhere."""
    jobs, overrides, out, progress = _jobs(jobs), _overrides(overrides), _directory("out", out), _progress(progress)
    native = _tsi.study(_dumps(spec, "spec"), jobs, overrides, out, progress)
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
    Registering a name again replaces the earlier Python class; a name or alias another model
    holds (a C++ one, or another Python one) is refused, as is every bad argument
    (tsi.ConfigError naming it), before anything is registered.
    """
    name = _name("name", name, "model")
    params = _model_params(params)
    params_text = _dumps(params, "params", "params")
    if isinstance(aliases, (str, bytes, dict)) or not isinstance(aliases, (builtins.list, tuple, set, frozenset)):
        raise _refuse("aliases", f"got {_show(aliases)}, expected a list of names")
    aliases = [_name(f"aliases[{k}]", alias, "model") for k, alias in enumerate(aliases)]
    for k, alias in enumerate(aliases):
        if alias == name or alias in aliases[:k]:
            raise _refuse(f"aliases[{k}]", f"got \"{alias}\", {'the name itself' if alias == name else 'twice'}; "
                                           "expected other names")
    n_tau = _integer("n_tau", n_tau, 2, _MAX_N_TAU, f"an even integer from 2 to {_MAX_N_TAU}")
    if n_tau % 2:
        raise _refuse("n_tau", f"got {n_tau}, expected an even integer from 2 to {_MAX_N_TAU}")
    degree = _integer("nonlinearity_degree", nonlinearity_degree, 0, _MAX_DEGREE,
                      f"0 (not polynomial) or the degree, from 1 to {_MAX_DEGREE}")
    summary = _text("summary", summary)
    for field, taken in [("name", name)] + [(f"aliases[{k}]", alias) for k, alias in enumerate(aliases)]:
        _name_is_free(field, taken, "models", "python:" + name)

    def register(c):
        _model_class(c, params)
        _tsi.register_model(name, c, params_text, aliases, n_tau, degree, summary)
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
    value. Registering a name again replaces the earlier function; a name the core, a plugin or
    another Python field holds is refused, as is every bad argument (tsi.ConfigError naming it).
    """
    name = _name("name", name, "field")
    dim = _integer("dim", dim, 0, _MAX_MATRIX_DIM, f"0 (any) or a size from 1 to {_MAX_MATRIX_DIM}")
    time_dependent, is_complex = _boolean("time_dependent", time_dependent), _boolean("is_complex", is_complex)
    summary = _text("summary", summary)
    if u0 is not None:
        u0 = _numbers("u0", u0, "a 1-d array of numbers")
        if u0.ndim != 1 or not 1 <= u0.size <= _MAX_MATRIX_DIM or (dim and u0.size != dim):
            size = f"dim = {dim}" if dim else f"1 to {_MAX_MATRIX_DIM}"
            raise _refuse("u0", f"got {_show(u0)}, expected a 1-d array of {size} numbers")
        if not is_complex:
            _real_or_zero_imaginary("u0", u0, "the real field (is_complex=False)")
        u0 = u0.astype(complex)
    _name_is_free("name", name, "fields", "python-field:" + name)

    def register(func):
        _callback("f", func, "f(t, u)", 2)
        _tsi.register_field(name, func, dim, time_dependent, is_complex, u0, summary)
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

    Every argument is checked before anything is computed, f too (called once at t0 with u0):
    a bad one raises tsi.ConfigError naming it (h outside (0, t1 - t0], a time outside t_span,
    an f that returns the wrong shape, NaN, or complex values for a real A and u0, ...). A run
    that fails or blows up raises tsi.Error with its message.
    """
    A = _numbers("A", A, "a square matrix")
    if A.ndim != 2 or A.shape[0] != A.shape[1] or not 1 <= A.shape[0] <= _MAX_MATRIX_DIM:
        raise _refuse("A", f"got {_show(A)}, expected a square matrix, 1 x 1 to {_MAX_MATRIX_DIM} x {_MAX_MATRIX_DIM}")
    dim = A.shape[0]
    u0 = _numbers("u0", u0, f"a 1-d array of {dim} numbers (A is {dim} x {dim})")
    if u0.shape != (dim,):
        raise _refuse("u0", f"got {_show(u0)}, expected a 1-d array of {dim} numbers (A is {dim} x {dim})")
    _callback("f", f, "f(t, u)", 2)
    eps = _real("eps", eps, "a number in (0, 1]")
    t0, t1 = _span(t_span)
    length = t1 - t0
    h = length / 100 if h is None else _real("h", h, "a step in (0, t1 - t0]")
    if not 0 < h <= length:
        raise _refuse("h", f"got {h}, expected a step in (0, {length}] (t1 - t0 of t_span ({t0}, {t1}))")
    if isinstance(scheme, str) and scheme:
        scheme = {"name": scheme}
    elif isinstance(scheme, dict):
        scheme = dict(scheme)
    else:
        raise _refuse("scheme", f"got {_show(scheme)}, expected a scheme's name (\"eab\") or its config section "
                                "({\"name\": \"eab\", \"order\": 6})")
    n_tau = _integer("n_tau", n_tau, 2, _MAX_N_TAU, f"an even integer from 2 to {_MAX_N_TAU}")
    time_dependent = _boolean("time_dependent", time_dependent)
    error_estimate = _boolean("error_estimate", error_estimate)
    out, threads = _directory("out", out) or None, _threads(threads) or None
    wanted = None if times is None else _times(times, t0, t1)
    is_complex = bool(np.iscomplexobj(A) or np.iscomplexobj(u0))
    steps = _step_count(h, t0, t1, dim, is_complex, error_estimate, wanted is None)
    _probe_field(f, t0, u0, is_complex)
    step = length / steps
    if wanted is None:
        wanted = t0 + step * np.arange(steps + 1)
    # The field runs from t = 0: f at t0 + t (the equation is otherwise invariant under a shift in t).
    name = f"tsi-solve-{next(_solve_fields)}"
    _tsi.register_field(name, lambda t, u: f(t + t0, u), dim, time_dependent, is_complex, None, "")

    def entry(x):  # a number of the config: [re, im] for a complex model
        z = complex(x)
        return [z.real, z.imag] if is_complex else z.real

    config = {"model": {"name": "matrix", "eps": eps, "f": name,
                        "A": [[entry(a) for a in row] for row in A.tolist()],
                        "u0": [entry(x) for x in u0.tolist()]},
              "reformulation": {"name": "two-scale", "n_tau": n_tau},
              "scheme": scheme,
              "time": {"h": step, "t_end": length},
              "output": {"times": [min(max(t - t0, 0.0), length) for t in wanted.tolist()]}}
    if error_estimate:
        config["output"]["error_estimate"] = "richardson"
    try:
        result = run(config, out=out, threads=threads)
    except ConfigError as e:
        raise _as_solve_argument(e) from None
    if not result.ok:
        raise Error(f"tsi.solve: the run {result.status}: {result.message}")
    return wanted, result.u_times, result

def __getattr__(name):
    # tsi.plot (matplotlib) and tsi.models are imported on first use.
    if name in ("plot", "models"):
        import importlib

        return importlib.import_module(f"{__name__}.{name}")
    raise AttributeError(f"module 'tsi' has no attribute {name!r}")
