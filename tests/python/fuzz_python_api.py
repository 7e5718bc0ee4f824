"""A short fuzz run of the Python layer: random mutations, from a fixed seed, of valid configs
and study specs (tsi.run, tsi.study) and of the arguments of tsi.solve, tsi.register_model and
tsi.register_field. Every call must return or raise tsi.ConfigError (with a .field) or
tsi.Error; another exception is a finding, and so is a call that does not come back.

A call is given a few seconds (then SIGALRM stops it as Ctrl-C would: tsi.Interrupted, counted,
not a finding, since a mutated config may ask for a long run); one that ignores that is a hang:
faulthandler prints every thread's stack and exits 1. Run by ctest (python.fuzz_api):

    PYTHONPATH=<build>/python /usr/bin/python3 tests/python/fuzz_python_api.py [--seconds 40] [--seed 1]

Prints the number of calls by outcome and every finding (the call and its exception); exits 1
if there is one.
"""
import argparse
import collections
import copy
import faulthandler
import math
import os
import random
import signal
import sys
import tempfile
import time
import traceback

import numpy as np

import tsi
from tsi.models import HenonHeiles

CALL_SECONDS = 3.0  # a call's time before it is stopped as Ctrl-C would stop it
HANG_SECONDS = 30.0  # a call that has not come back by then is a hang

QUICKSTART_A = [[0, 0, 1, 0], [0, 0, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 0]]
QUICKSTART_U0 = [0.55, 0.12, 0.03, 0.89]


def quickstart_f(t, u):
    return np.array([np.zeros_like(u[0]), u[3], 2 * u[0] * u[1], -u[1] - u[0] ** 2 + u[1] ** 2])


def deep(levels):
    value = {}
    for _ in range(levels):
        value = {"a": value}
    return value


def looped():
    value = {"model": {"name": "hh"}}
    value["model"]["self"] = value
    return value


class Unprintable:
    def __repr__(self):
        raise RuntimeError("no repr")


class BadPath(os.PathLike):
    def __fspath__(self):
        return 5


# Values a careless or hostile caller passes: wrong types, non-finite and extreme numbers,
# numpy scalars and arrays, strings JSON or UTF-8 cannot hold, containers that loop.
HOSTILE = [math.nan, math.inf, -math.inf, None, True, False, 0, -1, 1, 3, 2 ** 31, 2 ** 63, -2 ** 63, 10 ** 30,
           1e300, -1e300, 1e-300, 5e-324, 0.5, -0.25, "", "x", "0.1", "\0", "\udcff", "hh", [], [math.nan],
           [[1, 2], [3]], [0.5, "a"], {}, {"a": 1}, (1, 2), {1, 2}, object(), b"bytes", 1j, complex(math.nan, 0),
           np.float32(math.nan), np.int64(7), np.float64(0.25), np.bool_(True), np.array([1.0, math.nan]),
           np.zeros((2, 2)), np.array(["a"]), np.longdouble(0.1), np.complex64(1 + 1j), range(3), lambda: 0,
           Unprintable(), BadPath(), deep(70), looped()]

HH = {"model": {"name": "henon-heiles", "eps": 0.01}, "scheme": {"name": "se1"},
      "time": {"h": 0.25, "t_end": 0.5}, "reference": {}}
CONFIGS = [
    HH,
    {"model": {"name": "hh", "eps": 0.1, "u0": [0.1, 0.2, 0.3, 0.4]}, "scheme": {"name": "se2", "tol": 1e-10},
     "time": {"h": 0.125, "t_end": 0.5}, "output": {"times": [0.1, 0.25]}},
    {"model": {"name": "nls", "eps": 0.1, "n_x": 8}, "reformulation": {"name": "two-scale", "n_tau": 16},
     "scheme": {"name": "fd"}, "time": {"h": 0.25, "t_end": 0.5}},
    {"model": {"name": "matrix", "A": QUICKSTART_A, "f": "fuzz-f", "eps": 1e-3, "u0": QUICKSTART_U0},
     "reformulation": {"name": "two-scale", "n_tau": 16}, "scheme": {"name": "eab", "order": 4},
     "time": {"h": 0.25, "t_end": 0.5}},
]
SPEC = {"kind": "convergence", "base": HH, "vary": {"time.h": [0.25, 0.125], "scheme.name": ["se1", "fd"]}}


# ---- Model classes and fields, good and bad, for the registrations ---------------------------

class ComplexReturns(HenonHeiles):
    def filtered_field(self, taus, u):
        return super().filtered_field(taus, u) * (1 + 1j)


class NanReturns(HenonHeiles):
    def nonlinear_field(self, u):
        return super().nonlinear_field(u) * math.nan


class WrongShape(HenonHeiles):
    def filtered_field(self, taus, u):
        return super().filtered_field(taus, u)[:, :1]


class StringDim(HenonHeiles):
    def __init__(self, eps):
        super().__init__(eps)
        self.dim = "4"


class HugeDim(HenonHeiles):
    dim = 2 ** 40


class RaisingInit(HenonHeiles):
    def __init__(self, eps):
        raise ValueError("no")


class NoneInitial(HenonHeiles):
    def initial_value(self):
        return None


class BadFrequency(HenonHeiles):
    max_linear_frequency = math.nan


CLASSES = [HenonHeiles, ComplexReturns, NanReturns, WrongShape, StringDim, HugeDim, RaisingInit, NoneInitial,
           BadFrequency]
FIELDS = [quickstart_f,
          lambda t, u: u[:3],
          lambda t, u: u * math.nan,
          lambda t, u: 1j * u,
          lambda t, u: 0j + u,
          lambda t, u: 1 / 0,
          lambda t, u: None,
          lambda t, u: "x",
          lambda t, u: 1.0,
          lambda t, u: [list(row) for row in u],
          lambda t, u: np.zeros((u.shape[0], u.shape[1] + 1)),
          lambda t, u: u.astype(object),
          lambda u: u,
          lambda t, u, v: u,
          lambda *args: 0 * args[1],
          np.add]


# ---- Mutations -----------------------------------------------------------------------------

def paths(value, prefix=()):
    """The (container path, key) pairs inside a config down to 6 levels: where a mutation acts."""
    out = []
    if len(prefix) >= 6:
        return out
    if isinstance(value, dict):
        for key, item in value.items():
            out.append((prefix, key))
            out.extend(paths(item, prefix + (key,)))
    elif isinstance(value, list):
        for k, item in enumerate(value):
            out.append((prefix, k))
            out.extend(paths(item, prefix + (k,)))
    return out


def scaled(rng, value):
    """A number changed the ways careless edits change one: scaled by a power of ten, negated,
    off by one, turned into its string."""
    if not math.isfinite(value):
        return value
    choice = rng.randrange(5)
    if choice == 0:
        return value * 10.0 ** rng.randint(-3, 3)
    if choice == 1:
        return -value
    if choice == 2:
        return value + rng.choice((-1, 1))
    if choice == 3:
        return str(value)
    return float(value) if isinstance(value, int) else int(value)


def mutated_config(rng, config):
    config = copy.deepcopy(config)
    for _ in range(rng.randint(1, 3)):
        where = paths(config)
        if not where or rng.random() < 0.05:
            return rng.choice(HOSTILE)  # the whole config
        prefix, key = rng.choice(where)
        node = config
        for step in prefix:
            node = node[step]
        op = rng.randrange(4)
        value = node[key]
        if op == 0:
            node[key] = rng.choice(HOSTILE)
        elif op == 1 and isinstance(value, (int, float)) and not isinstance(value, bool):
            node[key] = scaled(rng, value)
        elif op == 2 and isinstance(node, dict):
            del node[key]
        elif isinstance(node, dict):
            node[rng.choice(("extra", "tol", "order", "n_tau", "times", "u0", "h", "plugins"))] = rng.choice(HOSTILE)
        else:
            node.append(rng.choice(HOSTILE))
    return config


def mutated_arguments(rng, arguments, choices):
    arguments = dict(arguments)
    for _ in range(rng.randint(1, 2)):
        name = rng.choice(sorted(arguments))
        value = arguments[name]
        pick = rng.random()
        if pick < 0.4 and name in choices:
            arguments[name] = rng.choice(choices[name])
        elif pick < 0.6 and isinstance(value, (int, float)) and not isinstance(value, bool):
            arguments[name] = scaled(rng, value)
        else:
            arguments[name] = rng.choice(HOSTILE)
    return arguments


# ---- The calls -----------------------------------------------------------------------------

class Slow(Exception):
    """Raised by SIGALRM in Python code; inside a run it becomes tsi.Interrupted."""


def on_alarm(signum, frame):
    raise Slow()


def case_run(rng, tmp):
    config = mutated_config(rng, rng.choice(CONFIGS))
    return "run", lambda: tsi.run(config, threads=1)


def case_study(rng, tmp):
    spec = mutated_config(rng, SPEC)
    return "study", lambda: tsi.study(spec, jobs=1, overrides=rng.choice([None, {"model.eps": 0.1}, ["time.t_end=1"],
                                                                            {"model.eps": rng.choice(HOSTILE)}]))


def case_solve(rng, tmp):
    base = {"A": QUICKSTART_A, "f": quickstart_f, "eps": 1e-3, "u0": QUICKSTART_U0, "t_span": (0.0, 1.0),
            "h": 0.125, "n_tau": 16, "scheme": "eab", "times": None, "time_dependent": False,
            "error_estimate": False, "threads": 1}
    choices = {"f": FIELDS, "A": [[[0, 1.1], [-1.1, 0]], [[0, 1j], [-1j, 0]], [[0]], np.array(QUICKSTART_A) * 1j,
                                  np.zeros((5, 5))],
               "u0": [[0.1, 0.2], np.array(QUICKSTART_U0, dtype=complex), np.ones((4, 1))],
               "t_span": [(1.0, 0.0), (0.0, 0.0), (-1e308, 1e308), (2.0, 3.0), [0, 1], np.array([0.0, 0.5])],
               "times": [[0.0, 0.5, 1.0], [1.0 + 1e-15], [-0.5], np.linspace(0, 1, 7), [[0.5]], []],
               "scheme": [{"name": "eab", "order": 6}, {"name": "se1"}, "nope", {"order": 4}, ("eab",)],
               "out": [5, "\0", b"\xff", BadPath(), None, os.path.join(tmp, "solve")]}
    arguments = mutated_arguments(rng, base, choices)
    if isinstance(arguments.get("out"), str) and not arguments["out"].startswith(tmp):
        arguments["out"] = None  # files are written only under the fuzz run's directory
    positional = [arguments.pop(name) for name in ("A", "f", "eps", "u0", "t_span")]
    return "solve", lambda: tsi.solve(*positional, **arguments)


def case_register_model(rng, tmp):
    base = {"name": "fuzz-model", "cls": HenonHeiles, "params": None, "aliases": (), "n_tau": 64,
            "nonlinearity_degree": 2, "summary": ""}
    choices = {"cls": CLASSES, "params": [{"scale": 1.0}, {"eps": 0.1}, {"a.b": 1}, {"x": None}, {"x": [1, 2]}],
               "aliases": [["fuzz-alias"], ["hh"], ["fuzz-model"], ["a", "a"], "abc", [None]],
               "name": ["henon-heiles", "fuzz-model-2", "quickstart", " x", "x\ny"]}
    arguments = mutated_arguments(rng, base, choices)
    name = arguments.pop("name")

    def call():
        tsi.register_model(name, **arguments)
        return tsi.run(dict(HH, model={"name": name, "eps": 0.1}, reference={}), threads=1)

    return "register_model", call


def case_register_field(rng, tmp):
    base = {"name": "fuzz-f", "f": quickstart_f, "dim": 4, "time_dependent": False, "is_complex": False,
            "u0": None, "summary": ""}
    choices = {"f": FIELDS, "u0": [QUICKSTART_U0, [1j, 0, 0, 0], [[1, 2], [3, 4]], [0.1]],
               "name": ["quickstart", "linear", "fuzz-f-2", ""]}
    arguments = mutated_arguments(rng, base, choices)
    name = arguments.pop("name")

    def call():
        tsi.register_field(name, **arguments)
        return tsi.run(dict(CONFIGS[3], model=dict(CONFIGS[3]["model"], f=name)), threads=1)

    return "register_field", call


CASES = [case_run, case_study, case_solve, case_register_model, case_register_field]


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=40.0, help="how long to fuzz (default 40)")
    parser.add_argument("--seed", type=int, default=20240601)
    parser.add_argument("--max-calls", type=int, default=100000)
    args = parser.parse_args()
    rng = random.Random(args.seed)
    signal.signal(signal.SIGALRM, on_alarm)
    tsi.register_field("fuzz-f", quickstart_f, dim=4)
    outcomes = collections.Counter()
    findings = []
    start = time.monotonic()
    with tempfile.TemporaryDirectory() as tmp:
        calls = 0
        while calls < args.max_calls and time.monotonic() - start < args.seconds:
            kind, call = rng.choice(CASES)(rng, tmp)
            calls += 1
            faulthandler.dump_traceback_later(HANG_SECONDS, exit=True)
            signal.setitimer(signal.ITIMER_REAL, CALL_SECONDS)
            try:
                call()
                outcome = "returned"
            except tsi.ConfigError as e:
                outcome = "ConfigError"
                if not (isinstance(getattr(e, "field", None), str) and e.field):
                    outcome, text = "finding", f"a ConfigError without a field: {e}"
            except tsi.Error:
                outcome = "Error"
            except (tsi.Interrupted, Slow):
                outcome = "stopped (slow)"
            except BaseException:  # every other exception is what the run looks for
                outcome, text = "finding", traceback.format_exc(limit=-4)
            finally:
                signal.setitimer(signal.ITIMER_REAL, 0)
                faulthandler.cancel_dump_traceback_later()
            outcomes[(kind, outcome)] += 1
            if outcome == "finding":
                findings.append((calls, kind, text))
    elapsed = time.monotonic() - start
    print(f"fuzz_python_api: {calls} calls in {elapsed:.1f} s (seed {args.seed})")
    for (kind, outcome), n in sorted(outcomes.items()):
        print(f"  {kind:15} {outcome:15} {n}")
    for number, kind, text in findings[:20]:
        print(f"\nfinding at call {number} ({kind}):\n{text}")
    print(f"{len(findings)} findings")
    return 1 if findings else 0


if __name__ == "__main__":
    sys.exit(main())
