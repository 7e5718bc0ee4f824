"""The Python package tsi: runs, studies, errors, models written in Python, plots, Ctrl-C.

Run by ctest with PYTHONPATH=<build>/python and TSI_TEST_RUNNER=<build>/bin/tsi, one ctest
test per class:  /usr/bin/python3 tests/python/test_tsi.py RunTests
"""
import csv
import json
import os
import signal
import subprocess
import sys
import tempfile
import threading
import time
import unittest

import numpy as np

import tsi
from tsi.models import HenonHeiles

RUNNER = os.environ.get("TSI_TEST_RUNNER", "")

HH = {"model": {"name": "henon-heiles", "eps": 0.01}, "scheme": {"name": "se1"},
      "time": {"h": 0.125, "t_end": 1.0}, "reference": {}}


def with_(config, **sections):
    out = json.loads(json.dumps(config))
    for key, value in sections.items():
        out.setdefault(key, {}).update(value)
    return out


def have(module):
    try:
        __import__(module)
        return True
    except ImportError:
        return False


class RunTests(unittest.TestCase):
    def test_list_names_the_shipped_models_and_schemes(self):
        listing = tsi.list()
        self.assertIn("henon-heiles", [m["name"] for m in listing["models"]])
        self.assertIn("se1", [s["name"] for s in listing["schemes"]])
        self.assertEqual([s["name"] for s in tsi.list("schemes")], [s["name"] for s in listing["schemes"]])

    def test_output_times_give_u_between_the_steps(self):
        config = with_(HH, output={"times": [1.0, 0.3, 0.0]})
        config.pop("reference")
        r = tsi.run(config)
        np.testing.assert_array_equal(r.times, [1.0, 0.3, 0.0])
        self.assertEqual(r.u_times.shape, (3, 4))
        np.testing.assert_array_equal(r.u_times[0], r.u_final)  # t_end is the last step's u
        self.assertTrue(np.all(np.isfinite(r.u_times)))
        # The files hold the same values: result.json inline, u_times.npy one row per time.
        with tempfile.TemporaryDirectory() as tmp:
            tsi.run(config, out=tmp)
            with open(os.path.join(tmp, "result.json")) as f:
                np.testing.assert_array_equal(json.load(f)["dense_output"]["u"], r.u_times)
            np.testing.assert_array_equal(np.load(os.path.join(tmp, "u_times.npy")), r.u_times)

    def test_run_returns_numpy_arrays_consistent_with_each_other(self):
        r = tsi.run(HH)
        self.assertEqual(r.status, "completed")
        self.assertEqual(r.u_final.shape, (4,))
        self.assertEqual(r.u_final.dtype, np.float64)
        self.assertEqual(r.reference.shape, (4,))
        # The relative error recomputed from the two states the result carries.
        own = np.linalg.norm(r.u_final - r.reference) / np.linalg.norm(r.reference)
        self.assertAlmostEqual(r.error / own, 1.0, delta=1e-12)
        self.assertGreater(r.error, 1e-7)
        self.assertLess(r.error, 1e-3)
        # One row per step and the initial one; the largest err_H is the one result.json reports.
        self.assertEqual(len(r.t), r.steps + 1)
        self.assertEqual(r.steps, 8)
        self.assertAlmostEqual(r.t[-1], 1.0, delta=1e-12)
        self.assertEqual(r.invariants["err_H"][0], 0.0)
        self.assertAlmostEqual(r.invariants["err_H"].max(), r.result["invariants"]["H"]["max_rel_error"],
                               delta=1e-6 * r.invariants["err_H"].max())  # the file's 7 digits

    def test_run_on_two_threads_gives_the_one_thread_state(self):
        nls = {"model": {"name": "nls", "eps": 0.01, "n_x": 64},  # 64 x 256 values: split
               "reformulation": {"name": "two-scale", "n_tau": 256},
               "scheme": {"name": "se1"}, "time": {"h": 0.125, "t_end": 0.5}}
        one, two = tsi.run(nls, threads=1), tsi.run(nls, threads=2)
        self.assertEqual(one.result["threads"], 1)
        self.assertIn(two.result["threads"], (1, 2))  # 1 only in a build without OpenMP
        np.testing.assert_array_equal(one.u_final, two.u_final)
        with self.assertRaises(tsi.ConfigError) as e:
            tsi.run(nls, threads=-1)
        self.assertEqual(e.exception.field, "threads")

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_run_computes_what_the_cli_computes(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "hh.json")
            with open(path, "w") as f:
                json.dump(HH, f)
            subprocess.run([RUNNER, "run", path, "--out", os.path.join(tmp, "cli")], check=True,
                           stdout=subprocess.DEVNULL)
            with open(os.path.join(tmp, "cli", "result.json")) as f:
                cli = json.load(f)
            r = tsi.run(HH, out=os.path.join(tmp, "py"))
            self.assertEqual(r.u_final.tolist(), cli["u_final"])
            self.assertEqual(r.error, cli["error"]["relative"])
            self.assertEqual(r.config, cli["config"])
            with open(os.path.join(tmp, "py", "result.json")) as f:
                self.assertEqual(json.load(f)["u_final"], cli["u_final"])

    def test_a_complex_model_gives_a_complex_state(self):
        r = tsi.run({"model": {"name": "nls", "eps": 0.1, "n_x": 8}, "reformulation": {"n_tau": 16},
                     "time": {"h": 0.25, "t_end": 0.5}})
        self.assertEqual(r.status, "completed")
        self.assertEqual(r.u_final.dtype, np.complex128)
        self.assertEqual(r.u_final.shape, (8,))
        self.assertIsNone(r.error)

    def test_u0_from_a_npy_file_and_u_final_npy(self):
        with tempfile.TemporaryDirectory() as tmp:
            u0 = np.array([0.12, -0.1, 0.13, 1 / 9])
            np.save(os.path.join(tmp, "u0.npy"), u0.reshape(2, 2))
            from_json = tsi.run(with_(HH, model={"u0": u0.tolist()}))
            from_file = tsi.run(with_(HH, model={"u0": os.path.join(tmp, "u0.npy")}), out=os.path.join(tmp, "out"))
            self.assertEqual(from_file.config["model"]["u0"], os.path.join(tmp, "u0.npy"))
            # The same run; the state keeps u0's shape, as u_final.npy does.
            self.assertEqual(from_file.u_final.shape, (2, 2))
            np.testing.assert_array_equal(from_file.u_final.ravel(), from_json.u_final)
            np.testing.assert_array_equal(from_file.reference.ravel(), from_json.reference)
            self.assertEqual(from_file.error, from_json.error)
            np.testing.assert_array_equal(np.load(os.path.join(tmp, "out", "u_final.npy")), from_file.u_final)
            np.testing.assert_array_equal(np.load(os.path.join(tmp, "out", "reference_u_final.npy")),
                                          from_file.reference)
            with self.assertRaises(tsi.ConfigError) as e:
                tsi.run(with_(HH, model={"u0": os.path.join(tmp, "missing.npy")}))
            self.assertEqual(e.exception.field, "model.u0")

    def test_a_large_state_arrives_as_an_array(self):
        # 8192 complex values: result.json names u_final.npy instead of holding them.
        r = tsi.run({"model": {"name": "nls", "eps": 0.1, "n_x": 8192}, "reformulation": {"name": "direct"},
                     "scheme": {"name": "strang"}, "time": {"h": 0.125, "t_end": 0.25},
                     "reference": {"scheme": "strang", "reformulation": "direct", "h": 0.0625}})
        self.assertEqual(r.result["u_final"], {"file": "u_final.npy", "dtype": "complex128", "shape": [8192]})
        self.assertEqual(r.u_final.dtype, np.complex128)
        self.assertEqual(r.u_final.shape, (8192,))
        self.assertEqual(r.reference.shape, (8192,))
        own = np.linalg.norm(r.u_final - r.reference) / np.linalg.norm(r.reference)
        self.assertAlmostEqual(r.error / own, 1.0, delta=1e-12)

    def test_numpy_values_in_a_config_are_accepted(self):
        r = tsi.run(with_(HH, model={"eps": np.float64(0.01)}, time={"h": np.float32(0.25)}))
        self.assertEqual(r.steps, 4)


class ErrorTests(unittest.TestCase):
    def assert_field(self, config, field, words):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(config)
        self.assertEqual(caught.exception.field, field)
        self.assertIn(words, str(caught.exception))
        self.assertIsInstance(caught.exception, tsi.Error)

    def test_bad_values_name_their_field(self):
        self.assert_field(with_(HH, model={"eps": 2}), "model.eps", "expected a number in (0, 1]")
        self.assert_field(with_(HH, time={"h": 0.3}), "time.h", "whole number of steps")
        self.assert_field(with_(HH, scheme={"tol": "tight"}), "scheme.tol", "tight")
        self.assert_field(with_(HH, model={"name": "no-such-model"}), "model.name", "no-such-model")
        self.assert_field({"model": {"name": "hh"}, "modle": {}}, "modle", "unknown section")

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_the_message_is_the_clis(self):
        bad = with_(HH, model={"eps": 2})
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(bad)
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "bad.json")
            with open(path, "w") as f:
                json.dump(bad, f)
            cli = subprocess.run([RUNNER, "run", path, "--out", tmp], capture_output=True, text=True)
        self.assertEqual(cli.returncode, 2)
        self.assertIn(str(caught.exception), cli.stderr)

    def test_a_plugin_that_cannot_load_is_a_plugin_error(self):
        with self.assertRaises(tsi.PluginError):
            tsi.load_plugin("/nonexistent/tsi_nothing.so")

    def test_a_study_with_a_bad_path_names_it(self):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.study({"base": HH, "vary": {"model.eps": [0.1, 7]}})
        self.assertEqual(caught.exception.field, "model.eps")
        self.assertIn("r0002", str(caught.exception))


class StudyTests(unittest.TestCase):
    SPEC = {"kind": "convergence", "title": "se1 and fd on Henon-Heiles",
            "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
            "vary": {"scheme.name": ["se1", "fd"], "model.eps": [1, 0.0625], "time.h": [0.25, 0.125, 0.0625]}}

    @classmethod
    def setUpClass(cls):
        cls.study = tsi.study(cls.SPEC, jobs=2)

    def test_rows_and_runs(self):
        s = self.study
        self.assertEqual(len(s.rows), 12)
        self.assertEqual([r.id for r in s.runs], [row["id"] for row in s.rows])
        for row, run in zip(s.rows, s.runs):
            self.assertEqual(row["status"], "completed")
            self.assertEqual(row["error"], run.error)
            self.assertEqual(row["scheme"], run.config["scheme"]["name"])
            self.assertEqual(row["time.h"], run.assignments["time.h"])
            self.assertEqual(len(run.t), round(1 / row["h"]) + 1)

    def test_orders_are_two(self):
        orders = [row["order"] for row in self.study.rows if row["order"] is not None]
        self.assertEqual(len(orders), 8)
        for order in orders:
            self.assertGreater(order, 1.9)
            self.assertLess(order, 2.1)
        fits = [series["least_squares_order"] for series in self.study.convergence["series"]]
        self.assertEqual(len(fits), 4)
        for order in fits:
            self.assertAlmostEqual(order, 2.0, delta=0.1)

    @unittest.skipUnless(have("pandas"), "pandas not installed")
    def test_to_pandas(self):
        df = self.study.to_pandas()
        self.assertEqual(len(df), 12)
        self.assertEqual(list(df["error"]), [row["error"] for row in self.study.rows])
        self.assertIn("time.h", df.columns)

    def test_overrides_apply_to_the_base(self):
        s = tsi.study({"base": HH, "vary": {"time.h": [0.5, 0.25]}}, jobs=1, overrides={"scheme.name": "se2"})
        self.assertEqual({r["scheme"] for r in s.rows}, {"se2"})

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_the_cli_writes_the_same_table(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "study.json")
            with open(path, "w") as f:
                json.dump(self.SPEC, f)
            subprocess.run([RUNNER, "study", path, "--out", os.path.join(tmp, "cli"), "--no-plots", "--jobs", "2"],
                           check=True, stdout=subprocess.DEVNULL)
            with open(os.path.join(tmp, "cli", "table.csv")) as f:
                cli = list(csv.DictReader(f))
        self.assertEqual([r["id"] for r in cli], [r["id"] for r in self.study.rows])
        for a, b in zip(cli, self.study.rows):
            self.assertEqual(float(a["error"]), float(f"{b['error']:.10g}"))


class StudyUxTests(unittest.TestCase):
    """Studies do what a user means: settings some runs take, --set on varied paths,
    a column per varied path, a hint about plugins."""

    BASE = {"model": {"name": "hh", "eps": 0.1}, "scheme": {"tol": 1e-12}, "time": {"t_end": 0.5}}

    def test_a_base_setting_only_some_schemes_take_is_applied_where_taken(self):
        s = tsi.study({"base": self.BASE, "vary": {"scheme.name": ["se1", "fd"], "time.h": [0.25, 0.125]}}, jobs=1)
        self.assertEqual(s.not_used, {"scheme.tol": ["r0003", "r0004"]})
        for run in s.runs:
            if run.config["scheme"]["name"] == "se1":
                self.assertEqual(run.config["scheme"]["tol"], 1e-12)
            else:
                self.assertNotIn("tol", run.config["scheme"])
            self.assertEqual(run.status, "completed")
        # The tighter tol is really used: more sweeps than at the default 1e-10.
        loose = tsi.study({"base": with_(self.BASE, scheme={"tol": 1e-10}), "vary": {"scheme.name": ["se1"],
                                                                                   "time.h": [0.25]}}, jobs=1)
        self.assertGreater(s.rows[0]["sweeps_mean"], loose.rows[0]["sweeps_mean"])

    def test_a_setting_no_run_takes_is_still_an_error(self):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.study({"base": with_(self.BASE, scheme={"tolerance": 1e-12}),
                       "vary": {"scheme.name": ["se1", "fd"]}}, jobs=1)
        self.assertEqual(caught.exception.field, "scheme.tolerance")
        self.assertIn("no run of the study takes it", str(caught.exception))

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_the_cli_reports_not_used(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "study.json")
            with open(path, "w") as f:
                json.dump({"base": self.BASE, "vary": {"scheme.name": ["se1", "fd"]}}, f)
            out = subprocess.run([RUNNER, "study", path, "--out", os.path.join(tmp, "o"), "--no-plots"],
                                 capture_output=True, text=True, check=True).stdout
            self.assertIn("scheme.tol (from the base) is not used by r0002", out)
            with open(os.path.join(tmp, "o", "study.json")) as f:
                self.assertEqual(json.load(f)["not_used"], {"scheme.tol": ["r0002"]})

    def test_set_on_a_varied_path_is_refused(self):
        spec = {"base": self.BASE, "vary": {"time.h": [0.25, 0.125]},
                "cases": [{"label": "a"}, {"label": "b", "set": {"scheme": {"name": "se2"}}}]}
        for path, where in (("time.h", "vary.time.h"), ("scheme.name", "cases[1].set.scheme.name")):
            with self.assertRaises(tsi.ConfigError) as caught:
                tsi.study(spec, jobs=1, overrides={path: 0.5})
            self.assertEqual(caught.exception.field, "--set " + path)
            self.assertIn(where, str(caught.exception))
        s = tsi.study(spec, jobs=1, overrides={"model.eps": 0.05})  # a path it does not vary
        self.assertEqual({r["eps"] for r in s.rows}, {0.05})

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_set_on_a_varied_path_is_refused_by_the_cli(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "study.json")
            with open(path, "w") as f:
                json.dump({"base": self.BASE, "vary": {"time.h": [0.25]}}, f)
            cli = subprocess.run([RUNNER, "study", path, "--out", tmp, "--set", "time.h=0.5"], capture_output=True,
                                 text=True)
            self.assertEqual(cli.returncode, 2)
            self.assertIn("--set time.h: the study varies this path", cli.stderr)

    @unittest.skipUnless(RUNNER, "TSI_TEST_RUNNER not set")
    def test_table_csv_has_a_column_per_varied_path(self):
        spec = {"base": {"model": {"name": "nls", "eps": 0.1}, "reformulation": {"n_tau": 16},
                         "time": {"h": 0.25, "t_end": 0.5}},
                "vary": {"model.n_x": [8, 16]},
                "cases": [{"label": "tol", "vary": {"scheme.tol": [1e-8, 1e-10]}},
                          {"label": "anderson", "set": {"scheme": {"solver": "anderson"}}}]}
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "study.json")
            with open(path, "w") as f:
                json.dump(spec, f)
            subprocess.run([RUNNER, "study", path, "--out", os.path.join(tmp, "o"), "--no-plots"], check=True,
                           stdout=subprocess.DEVNULL)
            with open(os.path.join(tmp, "o", "table.csv")) as f:
                rows = list(csv.DictReader(f))
        self.assertEqual(len(rows), 6)
        for column in ("model.n_x", "scheme.tol", "scheme.solver"):
            self.assertIn(column, rows[0])
        self.assertEqual([r["model.n_x"] for r in rows], ["8", "8", "16", "16", "8", "16"])
        self.assertEqual([r["scheme.solver"] for r in rows], ["", "", "", "", "anderson", "anderson"])

    def test_an_unknown_model_mentions_plugins(self):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(with_(HH, model={"name": "fput"}))
        self.assertEqual(caught.exception.field, "model.name")
        self.assertIn("--plugin FILE", str(caught.exception))
        self.assertIn("tsi.load_plugin", str(caught.exception))


class PythonModelTests(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        tsi.register_model("py-hh", HenonHeiles, n_tau=64, nonlinearity_degree=2,
                           summary="Henon-Heiles written in Python")

    def test_it_is_listed(self):
        entry = [m for m in tsi.list("models") if m["name"] == "py-hh"]
        self.assertEqual(len(entry), 1)

    def test_errors_agree_with_the_cpp_model(self):
        # The same scheme, eps and h with either model, measured against the C++ run's reference.
        worst = 0.0
        for scheme in ("se1", "se2", "fd", "me"):
            for eps in (1.0, 0.01, 1 / 4096):
                for h in (0.25, 0.0625):
                    cfg = with_(HH, model={"eps": eps}, scheme={"name": scheme}, time={"h": h})
                    cpp = tsi.run(cfg)
                    cfg = with_(cfg, model={"name": "py-hh"})
                    del cfg["reference"]
                    py = tsi.run(cfg)
                    self.assertEqual(py.status, "completed")
                    self.assertEqual(py.config["reformulation"], cpp.config["reformulation"])
                    error = np.linalg.norm(py.u_final - cpp.reference) / np.linalg.norm(cpp.reference)
                    worst = max(worst, abs(error - cpp.error) / cpp.error)
                    self.assertLess(abs(error - cpp.error), 1e-12, (scheme, eps, h))
                    np.testing.assert_allclose(py.invariants["err_H"], cpp.invariants["err_H"], rtol=1e-6,
                                               atol=1e-15)
        print(f"\n  python vs C++ Henon-Heiles: largest relative difference of the errors {worst:.2e}")

    def test_its_own_reference_agrees_too(self):
        # The reference (rk78 on the filtered problem) computed with the Python model.
        cpp = tsi.run(HH)
        py = tsi.run(with_(HH, model={"name": "py-hh"}))
        self.assertLess(abs(py.error - cpp.error), 1e-12)
        np.testing.assert_allclose(py.reference, cpp.reference, rtol=0, atol=1e-13)

    def test_cost_against_the_cpp_model(self):
        cfg = with_(HH, time={"h": 1 / 64, "t_end": 1})
        del cfg["reference"]
        times = {}
        for name in ("henon-heiles", "py-hh"):
            runs = [tsi.run(with_(cfg, model={"name": name})) for _ in range(3)]
            times[name] = min(r.wall_seconds for r in runs)
        ratio = times["py-hh"] / times["henon-heiles"]
        print(f"\n  se1, eps = 0.01, h = 1/64, T = 1: C++ {times['henon-heiles'] * 1e3:.2f} ms, "
              f"python {times['py-hh'] * 1e3:.2f} ms, ratio {ratio:.1f}")
        self.assertGreater(ratio, 1.0)

    def test_a_python_exception_fails_the_run_with_its_message(self):
        class Broken(HenonHeiles):
            def filtered_field(self, taus, u):
                raise ValueError("deliberately broken")

        tsi.register_model("py-broken", Broken, nonlinearity_degree=2)
        r = tsi.run(with_(HH, model={"name": "py-broken"}))
        self.assertEqual(r.status, "failed")
        self.assertIn("deliberately broken", r.message)
        self.assertIn("filtered_field", r.message)

    def test_a_wrong_shape_is_reported(self):
        class Wrong(HenonHeiles):
            def filtered_field(self, taus, u):
                return super().filtered_field(taus, u)[:3]

        tsi.register_model("py-wrong", Wrong, nonlinearity_degree=2)
        r = tsi.run(with_(HH, model={"name": "py-wrong"}))
        self.assertEqual(r.status, "failed")
        self.assertIn("shape (3, 64), expected (4, 64)", r.message)

    def test_parameters_reach_the_class_and_are_checked(self):
        class Scaled(HenonHeiles):
            def __init__(self, eps, scale):
                super().__init__(eps)
                self.scale = scale

            def initial_value(self):
                return super().initial_value() * self.scale

        tsi.register_model("py-scaled", Scaled, params={"scale": 1.0}, nonlinearity_degree=2)
        base = tsi.run(with_(HH, model={"name": "py-scaled"}))
        half = tsi.run(with_(HH, model={"name": "py-scaled", "scale": 0.5}))
        self.assertAlmostEqual(base.result["invariants"]["m"]["initial"],
                               4 * half.result["invariants"]["m"]["initial"], delta=1e-15)
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(with_(HH, model={"name": "py-scaled", "scale": "big"}))
        self.assertEqual(caught.exception.field, "model.scale")

    def test_a_cpp_models_name_is_refused(self):
        with self.assertRaises(tsi.PluginError):
            tsi.register_model("henon-heiles", HenonHeiles)


QUICKSTART_A = [[0, 0, 1, 0], [0, 0, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 0]]
QUICKSTART_U0 = [0.55, 0.12, 0.03, 0.89]


def quickstart_f(t, u):
    """HOODESolver.jl's quickstart f(u) = (0, u4, 2 u1 u2, -u2 - u1^2 + u2^2), one state per column."""
    u1, u2, u4 = u[0], u[1], u[3]
    return np.array([np.zeros_like(u1), u4, 2 * u1 * u2, -u2 - u1 * u1 + u2 * u2])


LINEAR_B = np.array([[0.12, -0.78, 0.91, 0.34], [-0.45, 0.56, 0.03, 0.54], [-0.67, 0.09, 0.18, 0.89],
                     [-0.91, -0.56, 0.11, -0.56]])
LINEAR_a = np.array([0.12, -0.98, 0.45, 0.26])
LINEAR_b = np.array([-0.04, 0.48, 0.23, -0.87])
LINEAR_U0 = [-0.34, 0.78, 0.67, -5.6]


def linear_f(t, u):
    """HOODESolver.jl's linear test f(t, u) = B u + t a + b (t: one time per column)."""
    return LINEAR_B @ u + np.outer(LINEAR_a, t) + LINEAR_b[:, None]


class SolveTests(unittest.TestCase):
    A = [[0, 0, 1, 0], [0, 0, 0, 0], [-1, 0, 0, 0], [0, 0, 0, 0]]

    def test_solve_gives_hoodesolvers_quickstart_digits(self):
        def f(t, u):
            return np.array([0 * u[0], u[3], 2 * u[0] * u[1], -u[1] - u[0] ** 2 + u[1] ** 2])

        t, u, r = tsi.solve(self.A, f, 1e-4, [0.55, 0.12, 0.03, 0.89], (0.0, 3.0), h=0.1,
                            scheme={"name": "eab", "startup": "hoodesolver"}, time_dependent=False)
        self.assertEqual(t.shape, (31,))
        self.assertEqual(u.shape, (31, 4))
        np.testing.assert_allclose(t, 0.1 * np.arange(31), rtol=0, atol=1e-14)
        printed = [0.36354863065271914, 2.0384405589059846, -0.4134978102269046, 1.3093799931994603]
        np.testing.assert_allclose(u[-1], printed, rtol=0, atol=1e-10)
        np.testing.assert_array_equal(u[-1], r.u_final)

    def test_solve_shifts_time_for_a_time_dependent_field(self):
        # u4' = cos t from t0 = 1: u4(t) = u4(1) + sin t - sin 1; u2 stays; (u1, u3) turn.
        def f(t, u):
            return np.array([0 * u[0], 0 * u[1], 0 * u[2], np.cos(t)])

        times = [1.0, 1.37, 2.0, 2.61]
        exact = 0.5 + np.sin(times) - np.sin(1.0)
        errors = []
        for h in (0.05, 0.025):
            t, u, r = tsi.solve(self.A, f, 1e-3, [0.3, 0.2, 0.1, 0.5], (1.0, 3.0), h=h, times=times)
            np.testing.assert_array_equal(t, times)
            errors.append(np.max(np.abs(u[:, 3] - exact)))
            np.testing.assert_allclose(u[:, 1], 0.2, rtol=0, atol=1e-12)
            # e^{(t - t0) A / eps} turns (u1, u3) = (0.3, 0.1) by (t - 1) / eps, exactly.
            phase = (np.asarray(times) - 1.0) / 1e-3
            np.testing.assert_allclose(u[:, 0], 0.3 * np.cos(phase) + 0.1 * np.sin(phase), rtol=0, atol=1e-9)
        # eab of order 4 in the time variable t' = 1 (measured: 4.9e-7, then 16x less).
        self.assertLess(errors[0], 1e-6)
        self.assertGreater(errors[0] / errors[1], 12.0)

    def test_solve_estimates_its_error_without_a_reference(self):
        # HOODESolver.jl's linear test through tsi.solve with an error estimate, against the
        # exact solution of the same problem from the core's "linear" field (quad precision).
        B = np.array([[0.12, -0.78, 0.91, 0.34], [-0.45, 0.56, 0.03, 0.54],
                      [-0.67, 0.09, 0.18, 0.89], [-0.91, -0.56, 0.11, -0.56]])
        a = np.array([0.12, -0.98, 0.45, 0.26])
        b = np.array([-0.04, 0.48, 0.23, -0.87])
        u0 = [-0.34, 0.78, 0.67, -5.6]

        def f(t, u):
            return B @ u + np.outer(a, t) + b[:, None]

        t, u, r = tsi.solve(self.A, f, 1.5e-4, u0, (0.0, 1.0), h=1 / 16, error_estimate=True)
        self.assertEqual(r.result["error_estimate"]["status"], "completed")
        self.assertTrue(r.result["error_estimate"]["asymptotic"])
        exact = tsi.run({"model": {"name": "matrix", "eps": 1.5e-4, "f": "linear"},
                         "reformulation": {"name": "two-scale", "n_tau": 32},
                         "scheme": {"name": "eab"}, "time": {"h": 1 / 16, "t_end": 1.0},
                         "reference": {"scheme": "exact"}})
        error = np.linalg.norm(u[-1] - exact.reference) / np.linalg.norm(exact.reference)
        self.assertAlmostEqual(error / exact.error, 1.0, delta=1e-6)  # the same run, f in Python
        self.assertGreater(r.error_estimate / error, 0.5)
        self.assertLess(r.error_estimate / error, 2.0)

    def test_solve_refuses_an_empty_span(self):
        with self.assertRaises(ValueError):
            tsi.solve(self.A, lambda t, u: 0 * u, 1e-3, [0, 0, 0, 0], (1.0, 1.0))


class MatrixModelTests(unittest.TestCase):
    """The "matrix" model: A a matrix in the config, f a Python function (tsi.register_field)."""

    @classmethod
    def setUpClass(cls):
        tsi.register_field("py-quickstart", quickstart_f, dim=4)
        tsi.register_field("py-linear", linear_f, dim=4, time_dependent=True, u0=LINEAR_U0)

    def config(self, f, scheme, h=0.1, **model):
        return {"model": {"name": "matrix", "A": QUICKSTART_A, "f": f, "eps": 1e-4, "u0": QUICKSTART_U0, **model},
                "reformulation": {"name": "two-scale", "n_tau": 32}, "scheme": scheme,
                "time": {"h": h, "t_end": 3.0}}

    def test_fields_are_listed(self):
        names = {f["name"]: f for f in tsi.list("fields")}
        self.assertIn("quickstart", names)
        self.assertTrue(names["py-linear"]["time_dependent"])
        self.assertEqual(names["py-quickstart"]["dim"], 4)

    def test_python_f_agrees_with_the_cpp_field(self):
        # The same JSON A with f in Python and with the core's C++ "quickstart" field.
        for scheme in ({"name": "eab", "order": 4}, {"name": "collocation"}, {"name": "se1"}):
            py = tsi.run(self.config("py-quickstart", scheme))
            cpp = tsi.run(self.config("quickstart", scheme))
            self.assertEqual(py.status, "completed", py.message)
            self.assertNotIn("H", py.invariants)
            difference = np.linalg.norm(py.u_final - cpp.u_final) / np.linalg.norm(cpp.u_final)
            print(f"\n  {scheme['name']}: python f vs C++ f, relative difference {difference:.1e}")
            self.assertLess(difference, 1e-12, scheme)

    def test_a_numpy_matrix_is_taken(self):
        r = tsi.run(self.config("py-quickstart", {"name": "se1"}, A=np.array(QUICKSTART_A, dtype=float)))
        self.assertEqual(r.status, "completed")

    def test_time_dependent_f_against_the_exact_solution(self):
        # u(t) = e^{tC} u0 + C^{-1} (e^{tC} - I) b + (C^{-2} (e^{tC} - I) - t C^{-1}) a, C = A/eps + B:
        # the exponential of the augmented matrix [[C, a, b], [0, 0, 1], [0, 0, 0]] applied to (u0, 0, 1),
        # by eigen-decomposition (C has distinct eigenvalues).
        eps, T = 0.015, 1.0
        C = np.array(QUICKSTART_A, dtype=float) / eps + LINEAR_B
        w, V = np.linalg.eig(C)
        E = (V * np.exp(T * w)) @ np.linalg.inv(V)
        Ci = np.linalg.inv(C)
        exact = (E @ LINEAR_U0 + Ci @ (E - np.eye(4)) @ LINEAR_b
                 + (Ci @ Ci @ (E - np.eye(4)) - T * Ci) @ LINEAR_a).real
        errors = []
        for h in (0.25, 0.125):
            r = tsi.run({"model": {"name": "matrix", "A": QUICKSTART_A, "f": "py-linear", "eps": eps},
                         "scheme": {"name": "eab", "order": 4}, "time": {"h": h, "t_end": T}})
            self.assertEqual(r.status, "completed", r.message)
            self.assertEqual(r.u_final.shape, (4,))
            errors.append(np.linalg.norm(r.u_final - exact) / np.linalg.norm(exact))
        order = np.log2(errors[0] / errors[1])
        print(f"\n  eab order 4, eps = {eps}: errors {errors[0]:.2e} {errors[1]:.2e}, order {order:.2f}")
        self.assertGreater(order, 3.5)

    def test_a_non_periodic_A_is_refused(self):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(self.config("py-quickstart", {"name": "se1"}, A=(1.1 * np.array(QUICKSTART_A)).tolist()))
        self.assertEqual(caught.exception.field, "model.A")
        self.assertIn("e^(2 pi A) differs from the identity", str(caught.exception))

    def test_a_python_exception_fails_the_run_with_its_message(self):
        def broken(t, u):
            raise ValueError("deliberately broken")

        tsi.register_field("py-broken-f", broken, dim=4)
        r = tsi.run(self.config("py-broken-f", {"name": "se1"}))
        self.assertEqual(r.status, "failed")
        self.assertIn("deliberately broken", r.message)

    def test_a_cpp_fields_name_is_refused(self):
        with self.assertRaises(tsi.PluginError):
            tsi.register_field("quickstart", quickstart_f)

    def test_the_wrong_size_is_refused(self):
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.run(self.config("py-quickstart", {"name": "se1"}, A=[[0, 1], [-1, 0]], u0=[1, 0]))
        self.assertEqual(caught.exception.field, "model.A")


class InterruptTests(unittest.TestCase):
    def test_sigint_stops_a_run_and_keeps_what_it_computed(self):
        long_run = with_(HH, time={"h": 1 / 64, "t_end": 1e5})
        del long_run["reference"]
        timer = threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT))
        start = time.monotonic()
        timer.start()
        with self.assertRaises(tsi.Interrupted) as caught:
            tsi.run(long_run)
        elapsed = time.monotonic() - start
        r = caught.exception.result
        self.assertIsInstance(caught.exception, KeyboardInterrupt)
        self.assertEqual(r.status, "interrupted")
        self.assertGreater(r.t_reached, 0.0)
        self.assertLess(r.t_reached, 1e5)
        self.assertEqual(len(r.t), r.steps + 1)
        self.assertLess(elapsed, 5.0)
        # The next run is not interrupted.
        self.assertEqual(tsi.run(HH).status, "completed")


@unittest.skipUnless(have("matplotlib"), "matplotlib not installed")
class PlotTests(unittest.TestCase):
    def lines(self, fig):
        return [[(ax.get_title(), line.get_label(), np.asarray(line.get_xydata()).round(8).tolist())
                 for line in ax.lines] for ax in fig.axes]

    def check_same_as_the_script(self, spec, draw):
        import matplotlib

        matplotlib.use("Agg")
        from tsi import _plot_study

        with tempfile.TemporaryDirectory() as tmp:
            s = tsi.study(spec, jobs=2, out=tmp)
            fig = draw(s)
            with open(os.path.join(tmp, "table.csv")) as f:
                rows = list(csv.DictReader(f))
            if s.kind == "conservation":
                script = _plot_study.conservation_figure(rows, s.title, _plot_study.read_runs(rows, tmp))
            elif s.kind == "convergence":
                script = _plot_study.convergence_figure(rows, s.title)
            else:
                script = _plot_study.work_precision_figure(rows, s.title)
            self.assertEqual(self.lines(fig), self.lines(script))
            self.assertGreater(sum(len(ax.lines) for ax in fig.axes), 0)
            s.plot(tmp)
            name = _plot_study.FILES[s.kind][0]
            self.assertTrue(os.path.getsize(os.path.join(tmp, name)) > 1000)

    def test_convergence(self):
        self.check_same_as_the_script(StudyTests.SPEC, tsi.plot.convergence)

    def test_conservation(self):
        spec = {"kind": "conservation", "base": {"model": {"name": "hh", "eps": 0.1}, "time": {"t_end": 5}},
                "vary": {"scheme.name": ["se1", "me"], "time.h": [0.5, 0.25]}}
        self.check_same_as_the_script(spec, tsi.plot.conservation)

    def test_work_precision(self):
        spec = {"kind": "work-precision", "base": {"model": {"name": "hh", "eps": 1e-2}, "reference": {}},
                "vary": {"scheme.name": ["se1"], "time.h": [0.5, 0.25, 0.125]}}
        self.check_same_as_the_script(spec, tsi.plot.work_precision)

    def test_work_precision_colours_schemes_apart_at_one_eps(self):
        spec = {"kind": "work-precision", "base": {"model": {"name": "hh", "eps": 1e-2}, "reference": {}},
                "vary": {"scheme.name": ["se1", "me", "fd"], "time.h": [0.5, 0.25]}}
        fig = tsi.plot.work_precision(tsi.study(spec, jobs=1))
        lines = fig.axes[0].get_lines()
        self.assertEqual(len(lines), 3)
        self.assertEqual(len({line.get_color() for line in lines}), 3)
        # Two eps: one colour per eps, the schemes told apart by their line styles.
        spec["vary"]["model.eps"] = [1e-2, 1e-3]
        fig = tsi.plot.work_precision(tsi.study(spec, jobs=1))
        lines = fig.axes[0].get_lines()
        self.assertEqual(len(lines), 6)
        self.assertEqual(len({line.get_color() for line in lines}), 2)
        self.assertEqual(len({line.get_linestyle() for line in lines}), 3)

    def test_the_wrong_kind_is_refused(self):
        s = tsi.study({"kind": "conservation", "base": HH, "vary": {"time.h": [0.5]}}, jobs=1)
        with self.assertRaises(ValueError):
            tsi.plot.convergence(s)


if __name__ == "__main__":
    unittest.main(verbosity=2)
