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
            tsi.run(with_(HH, model={"name": "fput-example"}))  # the example plugin's model, not loaded
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
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.register_model("henon-heiles", HenonHeiles)
        self.assertEqual(caught.exception.field, "name")


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
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.solve(self.A, lambda t, u: 0 * u, 1e-3, [0, 0, 0, 0], (1.0, 1.0))
        self.assertEqual(caught.exception.field, "t_span")


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
        with self.assertRaises(tsi.ConfigError) as caught:
            tsi.register_field("quickstart", quickstart_f)
        self.assertEqual(caught.exception.field, "name")

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
        # Two eps: a scheme keeps its colour and marker, the eps are told apart by line styles.
        spec["vary"]["model.eps"] = [1e-2, 1e-3]
        fig = tsi.plot.work_precision(tsi.study(spec, jobs=1))
        lines = fig.axes[0].get_lines()
        self.assertEqual(len(lines), 6)
        self.assertEqual(len({line.get_color() for line in lines}), 3)
        self.assertEqual(len({line.get_marker() for line in lines}), 3)
        self.assertEqual(len({line.get_linestyle() for line in lines}), 2)

    def test_side_by_side_names_every_scheme_in_one_colour_each(self):
        from tsi import _plot_study
        # Thirteen series: colours and markers stay apart, and the legend names each.
        styles = [_plot_study.series_style(k) for k in range(13)]
        self.assertEqual(len({str(s["color"]) for s in styles}), 13)
        rows = []
        for k in range(13):
            for eps in (1.0, 1e-3):
                for h in (0.5, 0.25):
                    failed = k == 12 and h == 0.5
                    rows.append({"label": f"scheme {k}", "scheme": "se1", "eps": str(eps), "h": str(h),
                                 "error": "" if failed else str(h * h * (k + 1)),
                                 "status": "blow-up" if failed else "completed"})
        fig = _plot_study.side_by_side_figure(rows, "thirteen")
        self.assertEqual(len([ax for ax in fig.axes if ax.get_visible()]), 2)
        labels = [t.get_text() for t in fig.legends[0].get_texts()]
        self.assertEqual(len(labels), 13)
        self.assertEqual(labels[12], "scheme 12 (2 failed: x)")

    def test_the_wrong_kind_is_refused(self):
        s = tsi.study({"kind": "conservation", "base": HH, "vary": {"time.h": [0.5]}}, jobs=1)
        with self.assertRaises(ValueError):
            tsi.plot.convergence(s)


class BadArgumentTests(unittest.TestCase):
    """Every bad argument of run, study, solve, register_model and register_field raises
    tsi.ConfigError naming it (and saying what was expected) before anything is computed."""

    SPEC = {"base": HH, "vary": {"time.h": [0.5, 0.25]}}

    def refused(self, field, call, words):
        with self.assertRaises(tsi.ConfigError) as caught:
            call()
        self.assertEqual((caught.exception.field, str(caught.exception).startswith(field + ": "),
                          words in str(caught.exception)), (field, True, True), str(caught.exception))

    def test_run(self):
        nan_u0 = np.array([0.1, 0.2, np.nan, 0.3])
        looped = with_(HH)
        looped["model"]["self"] = looped
        for field, config, words in (
                ("model.eps", with_(HH, model={"eps": float("nan")}), "got nan, expected a finite number"),
                ("time.h", with_(HH, time={"h": float("inf")}), "got inf, expected a finite number"),
                ("model.u0[2]", with_(HH, model={"u0": nan_u0}), "got nan, expected a finite number"),
                ("model.eps", with_(HH, model={"eps": {0.1}}), "(set), expected a JSON value"),
                ("model", {"model": {("name",): "hh"}}, "expected string keys"),
                ("model.self", looped, "contains itself")):
            with self.subTest(field=field, words=words):
                self.refused(field, lambda: tsi.run(config), words)
        for field, kwargs, words in (
                ("threads", {"threads": "2"}, "got '2' (str), expected an integer from 1 to 1024"),
                ("threads", {"threads": 1.5}, "got 1.5 (float), expected an integer"),
                ("threads", {"threads": True}, "got True (bool), expected an integer"),
                ("threads", {"threads": 0}, "got 0 (int), expected an integer from 1 to 1024"),
                ("threads", {"threads": 10 ** 12}, "expected an integer from 1 to 1024"),
                ("out", {"out": 5}, "got 5 (int), expected a directory"),
                ("progress", {"progress": "no"}, "got 'no' (str), expected True or False")):
            with self.subTest(**kwargs):
                self.refused(field, lambda: tsi.run(HH, **kwargs), words)

    def test_study(self):
        nan_h = {"base": HH, "vary": {"time.h": [0.5, float("nan")]}}
        for field, spec, kwargs, words in (
                ("jobs", self.SPEC, {"jobs": "2"}, "got '2' (str), expected an integer from 1 to 1024"),
                ("jobs", self.SPEC, {"jobs": -1}, "got -1 (int), expected an integer from 1 to 1024"),
                ("jobs", self.SPEC, {"jobs": 2.5}, "got 2.5 (float)"),
                ("jobs", self.SPEC, {"jobs": 2 ** 40}, "expected an integer from 1 to 1024"),
                ("overrides", self.SPEC, {"overrides": "model.eps=0.1"}, "expected a dict"),
                ("overrides[0]", self.SPEC, {"overrides": [0.1]}, "expected a \"path=value\" string"),
                ("--set model.eps", self.SPEC, {"overrides": {"model.eps": float("nan")}}, "got nan"),
                ("vary.time.h[1]", nan_h, {}, "got nan, expected a finite number"),
                ("out", self.SPEC, {"out": object()}, "expected a directory"),
                ("progress", self.SPEC, {"progress": 1}, "got 1 (int), expected True or False")):
            with self.subTest(field=field, kwargs=kwargs):
                self.refused(field, lambda: tsi.study(spec, **kwargs), words)

    def test_solve(self):
        calls = []

        def f(t, u):
            calls.append(t)
            return 0 * u

        A, u0 = QUICKSTART_A, QUICKSTART_U0
        good = {"A": A, "f": f, "eps": 1e-3, "u0": u0, "t_span": (0.0, 1.0)}
        for field, change, words in (
                ("A", {"A": "A"}, "got 'A' (str), expected a square matrix"),
                ("A", {"A": [[0, 1], [1]]}, "expected a square matrix"),
                ("A", {"A": [[0, 1, 0], [1, 0, 0]]}, "got an array of shape (2, 3)"),
                ("A[1][0]", {"A": [[0, 1], [np.nan, 0]], "u0": [1, 0]}, "got nan, expected a finite number"),
                ("A", {"A": [[object()]]}, "of numbers"),
                ("A", {"A": np.zeros((1025, 1025))}, "1 x 1 to 1024 x 1024"),
                ("u0", {"u0": [0.1, 0.2, 0.3]}, "expected a 1-d array of 4 numbers (A is 4 x 4)"),
                ("u0", {"u0": np.ones((2, 2))}, "got an array of shape (2, 2)"),
                ("u0", {"u0": None}, "got None (NoneType)"),
                ("u0[3]", {"u0": [0, 0, 0, np.inf]}, "got inf, expected a finite number"),
                ("f", {"f": 3}, "got 3 (int), expected a function f(t, u)"),
                ("f", {"f": lambda u: u}, "cannot be called as f(t, u)"),
                ("eps", {"eps": "1e-3"}, "got '1e-3' (str), expected a number in (0, 1]"),
                ("eps", {"eps": np.array([1e-3])}, "got an array of shape (1,)"),
                ("eps", {"eps": float("nan")}, "got nan (float)"),
                ("eps", {"eps": 2.0}, "got 2.0, expected a number in (0, 1]"),
                ("t_span", {"t_span": 1.0}, "got 1.0 (float), expected (t0, t1)"),
                ("t_span", {"t_span": (0, 1, 2)}, "expected (t0, t1): two finite numbers"),
                ("t_span[1]", {"t_span": (0, float("inf"))}, "got inf (float), expected a finite real number"),
                ("t_span[0]", {"t_span": ("0", 1)}, "got '0' (str)"),
                ("t_span", {"t_span": (1.0, 0.0)}, "got (1.0, 0.0), expected t0 < t1"),
                ("t_span", {"t_span": (-1e308, 1e308)}, "beyond a double"),
                ("h", {"h": 0}, "got 0.0, expected a step in (0, 1.0]"),
                ("h", {"h": -0.1}, "got -0.1, expected a step in (0, 1.0]"),
                ("h", {"h": 5}, "got 5.0, expected a step in (0, 1.0]"),
                ("h", {"h": "0.1"}, "got '0.1' (str)"),
                ("h", {"h": 1e-12}, "got 1e-12 for t_span (0.0, 1.0): u at every step would be 1e+12 states of 4 "
                                    "float64, 3.2e+13 bytes"),
                ("h", {"h": 1e-12, "times": [0.5]}, "1e+12 steps, more than a run takes (1e+09"),
                ("times[0]", {"times": [2.0]}, "got 2.0, outside t_span (0.0, 1.0)"),
                ("times[1]", {"times": [0.5, -1.0]}, "got -1.0, outside t_span (0.0, 1.0)"),
                ("times[0]", {"times": [np.nan]}, "got nan, expected a finite number"),
                ("times", {"times": 0.5}, "got 0.5 (float), expected a 1-d list of 1 to 100000 times"),
                ("times", {"times": [[0.5]]}, "expected a 1-d list"),
                ("times", {"times": []}, "expected a 1-d list of 1 to 100000 times"),
                ("times", {"times": "0.5"}, "got '0.5' (str)"),
                ("scheme", {"scheme": 4}, "got 4 (int), expected a scheme's name"),
                ("scheme", {"scheme": [("name", "eab")]}, "expected a scheme's name"),
                ("scheme.order", {"scheme": {"name": "eab", "order": np.nan}}, "got nan"),
                ("scheme.name", {"scheme": "no-such-scheme"}, "unknown scheme"),
                ("n_tau", {"n_tau": "32"}, "got '32' (str), expected an even integer from 2 to 1048576"),
                ("n_tau", {"n_tau": 31.5}, "got 31.5 (float)"),
                ("n_tau", {"n_tau": 33}, "got 33, expected an even integer"),
                ("time_dependent", {"time_dependent": "no"}, "got 'no' (str), expected True or False"),
                ("error_estimate", {"error_estimate": None}, "got None (NoneType), expected True or False"),
                ("threads", {"threads": "2"}, "expected an integer from 1 to 1024"),
                ("out", {"out": 5}, "expected a directory")):
            with self.subTest(field=field, change=change):
                self.refused(field, lambda: tsi.solve(**dict(good, **change)), words)
                self.assertLessEqual(len(calls), 1)  # at most f's one check: no run started
                calls.clear()

    def test_solve_checks_f_once_before_the_run(self):
        A, u0 = QUICKSTART_A, QUICKSTART_U0
        for words, f in (("returned None (NoneType), expected an array of u's shape (4, 1)", lambda t, u: None),
                         ("returned 'x' (str)", lambda t, u: "x"),
                         ("returned shape (3, 1), expected (4, 1)", lambda t, u: u[:3]),
                         ("returned shape (), expected (4, 1)", lambda t, u: 1.0),
                         ("returned nan, expected finite values", lambda t, u: u * np.nan),
                         ("returned complex values for a real problem", lambda t, u: 1j * u),
                         ("raised ZeroDivisionError: division by zero", lambda t, u: 1 / 0)):
            with self.subTest(words=words):
                self.refused("f", lambda: tsi.solve(A, f, 1e-3, u0, (0.0, 1.0)),
                             "f(t, u) at t = t0 = 0.0, u = u0 (a 4 x 1 column) " + words)
        # Complex values later in the run fail it (tsi.Error), with the field and the reason named.
        with self.assertRaises(tsi.Error) as caught:
            tsi.solve(A, lambda t, u: 0 * u + 1j * (t > 0.5), 1e-3, u0, (0.0, 1.0))
        self.assertIn("f(t, u) returned complex values (imaginary parts up to 1) where the states are real",
                      str(caught.exception))
        # A zero imaginary part is taken: the state is the real f's.
        real = tsi.solve(A, quickstart_f, 1e-3, u0, (0.0, 1.0), h=0.25)[1]
        zero = tsi.solve(A, lambda t, u: quickstart_f(t, u) + 0j, 1e-3, u0, (0.0, 1.0), h=0.25)[1]
        np.testing.assert_array_equal(zero, real)

    def test_register_model(self):
        class NoSelfField(HenonHeiles):
            def nonlinear_field(self):
                return None

        class Incomplete:
            dim = 4

            def __init__(self, eps):
                pass

        class WordDim(HenonHeiles):
            dim = "four"

        class NeedsScale(HenonHeiles):
            def __init__(self, eps, scale):
                super().__init__(eps)

        for field, args, kwargs, words in (
                ("name", (5, HenonHeiles), {}, "got 5 (int), expected the model's name"),
                ("name", ("", HenonHeiles), {}, "got '', expected the model's name"),
                ("name", (" py-x", HenonHeiles), {}, "without spaces around it"),
                ("name", ("henon-heiles", HenonHeiles), {}, "\"henon-heiles\" is already registered by"),
                ("name", ("hh", HenonHeiles), {}, "as an alias of \"henon-heiles\""),
                ("cls", ("py-x", 5), {}, "got 5 (int), expected a class, built as cls(eps, **params)"),
                ("cls", ("py-x", HenonHeiles(0.1)), {}, "expected a class"),
                ("cls", ("py-x", NeedsScale), {}, "cannot be built as cls(eps, **params) with params []"),
                ("cls", ("py-x", HenonHeiles), {"params": {"scale": 1.0}}, "with params ['scale']"),
                ("cls.nonlinear_field", ("py-x", NoSelfField), {}, "cannot be called as nonlinear_field(U)"),
                ("cls.linear_flow", ("py-x", Incomplete), {}, "Incomplete has no method linear_flow(taus, U)"),
                ("cls.dim", ("py-x", WordDim), {}, "got 'four' (str), expected a positive integer"),
                ("params", ("py-x", HenonHeiles), {"params": [1]}, "got [1] (list), expected a dict"),
                ("params", ("py-x", HenonHeiles), {"params": {"a.b": 1}}, "Python identifiers"),
                ("params.eps", ("py-x", HenonHeiles), {"params": {"eps": 0.1}}, "common to every model"),
                ("params.scale", ("py-x", NeedsScale), {"params": {"scale": np.nan}}, "got nan"),
                ("params.scale", ("py-x", NeedsScale), {"params": {"scale": None}}, "got null, expected a number"),
                ("aliases", ("py-x", HenonHeiles), {"aliases": "hhx"}, "got 'hhx' (str), expected a list of names"),
                ("aliases[0]", ("py-x", HenonHeiles), {"aliases": ["hh"]}, "\"hh\" is already registered by"),
                ("aliases[0]", ("py-x", HenonHeiles), {"aliases": ["py-x"]}, "the name itself"),
                ("aliases[1]", ("py-x", HenonHeiles), {"aliases": ["a", "a"]}, "twice"),
                ("aliases[0]", ("py-x", HenonHeiles), {"aliases": [None]}, "got None (NoneType)"),
                ("n_tau", ("py-x", HenonHeiles), {"n_tau": "64"}, "got '64' (str), expected an even integer"),
                ("n_tau", ("py-x", HenonHeiles), {"n_tau": 63}, "got 63, expected an even integer from 2 to 1048576"),
                ("n_tau", ("py-x", HenonHeiles), {"n_tau": 64.5}, "got 64.5 (float)"),
                ("n_tau", ("py-x", HenonHeiles), {"n_tau": 2 ** 40}, "expected an even integer from 2 to 1048576"),
                ("nonlinearity_degree", ("py-x", HenonHeiles), {"nonlinearity_degree": -1}, "got -1 (int)"),
                ("nonlinearity_degree", ("py-x", HenonHeiles), {"nonlinearity_degree": 2.5}, "got 2.5 (float)"),
                ("summary", ("py-x", HenonHeiles), {"summary": 5}, "got 5 (int), expected a string")):
            with self.subTest(field=field, words=words):
                self.refused(field, lambda: tsi.register_model(*args, **kwargs), words)
        self.assertNotIn("py-x", [m["name"] for m in tsi.list("models")])  # nothing half-registered

    def test_a_refused_registration_keeps_the_earlier_one(self):
        tsi.register_model("py-kept", HenonHeiles, nonlinearity_degree=2)
        self.refused("n_tau", lambda: tsi.register_model("py-kept", HenonHeiles, n_tau=3), "got 3")
        self.assertEqual(tsi.run(with_(HH, model={"name": "py-kept"})).status, "completed")

    def test_a_python_models_bad_attributes_and_returns_are_named(self):
        class FloatDim(HenonHeiles):
            def __init__(self, eps):
                super().__init__(eps)
                self.dim = 4.0

        class Imaginary(HenonHeiles):
            def filtered_field(self, taus, u):
                return super().filtered_field(taus, u) * (1 + 1e-3j)

        class ImaginaryStart(HenonHeiles):
            def initial_value(self):
                return 1j * super().initial_value()

        class Words(HenonHeiles):
            def filtered_field(self, taus, u):
                return "x"

        class ZeroImaginary(HenonHeiles):
            def filtered_field(self, taus, u):
                return super().filtered_field(taus, u) + 0j

        for name, cls in (("py-float-dim", FloatDim), ("py-imaginary", Imaginary), ("py-words", Words),
                          ("py-imaginary-start", ImaginaryStart), ("py-zero-imaginary", ZeroImaginary)):
            tsi.register_model(name, cls, nonlinearity_degree=2)
        self.refused("model.name", lambda: tsi.run(with_(HH, model={"name": "py-float-dim"})),
                     "python model \"py-float-dim\": dim = 4.0 (float), expected a positive integer")
        r = tsi.run(with_(HH, model={"name": "py-imaginary"}))
        self.assertEqual(r.status, "failed")
        self.assertIn("python model \"py-imaginary\": filtered_field returned complex values (imaginary parts up to",
                      r.message)
        r = tsi.run(with_(HH, model={"name": "py-words"}))
        self.assertEqual(r.status, "failed")
        self.assertIn("python model \"py-words\": filtered_field returned a str, expected an array of shape (4, 64)",
                      r.message)
        with self.assertRaises(tsi.Error) as caught:
            tsi.run(with_(HH, model={"name": "py-imaginary-start"}))
        self.assertIn("python model \"py-imaginary-start\": initial_value returned complex values",
                      str(caught.exception))
        zero, real = tsi.run(with_(HH, model={"name": "py-zero-imaginary"})), tsi.run(HH)
        self.assertLess(np.linalg.norm(zero.u_final - real.u_final), 1e-12)

    def test_register_field(self):
        for field, args, kwargs, words in (
                ("name", (5, quickstart_f), {}, "got 5 (int), expected the field's name"),
                ("name", ("quickstart", quickstart_f), {}, "\"quickstart\" is already registered by core"),
                ("f", ("py-f-x", 5), {}, "got 5 (int), expected a function f(t, u)"),
                ("f", ("py-f-x", lambda u: u), {}, "cannot be called as f(t, u)"),
                ("dim", ("py-f-x", quickstart_f), {"dim": "4"}, "got '4' (str), expected 0 (any) or a size"),
                ("dim", ("py-f-x", quickstart_f), {"dim": -1}, "got -1 (int)"),
                ("dim", ("py-f-x", quickstart_f), {"dim": 2 ** 40}, "a size from 1 to 1024"),
                ("time_dependent", ("py-f-x", quickstart_f), {"time_dependent": "yes"}, "expected True or False"),
                ("is_complex", ("py-f-x", quickstart_f), {"is_complex": 0}, "got 0 (int), expected True or False"),
                ("u0", ("py-f-x", quickstart_f), {"u0": "abc"}, "got 'abc' (str), expected a 1-d array of numbers"),
                ("u0", ("py-f-x", quickstart_f), {"u0": [[1, 2], [3, 4]]}, "got an array of shape (2, 2)"),
                ("u0[1]", ("py-f-x", quickstart_f), {"u0": [0, np.nan]}, "got nan, expected a finite number"),
                ("u0", ("py-f-x", quickstart_f), {"dim": 4, "u0": [1, 2]}, "expected a 1-d array of dim = 4 numbers"),
                ("u0[1]", ("py-f-x", quickstart_f), {"u0": [1, 2j]}, "got 2j, expected a real number: the real field"),
                ("summary", ("py-f-x", quickstart_f), {"summary": None}, "got None (NoneType), expected a string")):
            with self.subTest(field=field, words=words):
                self.refused(field, lambda: tsi.register_field(*args, **kwargs), words)
        self.assertNotIn("py-f-x", [f["name"] for f in tsi.list("fields")])

    def test_a_python_fields_complex_values_fail_a_real_run(self):
        tsi.register_field("py-imaginary-f", lambda t, u: quickstart_f(t, u) * (1 + 1e-3j), dim=4)
        r = tsi.run({"model": {"name": "matrix", "A": QUICKSTART_A, "f": "py-imaginary-f", "eps": 1e-4,
                               "u0": QUICKSTART_U0}, "scheme": {"name": "se1"}, "time": {"h": 0.5, "t_end": 1.0}})
        self.assertEqual(r.status, "failed")
        self.assertIn("python field \"py-imaginary-f\": f(t, u) returned complex values", r.message)


if __name__ == "__main__":
    unittest.main(verbosity=2)
