"""Reads what `tsi run` and `tsi study` wrote, with json, numpy and pandas only."""
import json

import numpy as np
import pandas as pd

# A run: result.json, invariants.csv, u_final.npy (and reference_u_final.npy with a reference).
result = json.load(open("out/run/result.json"))
print(result["status"], result["steps"], result["error"]["relative"])
print("resolved scheme:", result["config"]["scheme"])
print("sweeps per stage:", result["solver"]["iterations_mean"], "evaluations:", result["rhs_evaluations"])
print("H:", result["invariants"]["H"])

u = np.load("out/run/u_final.npy")            # the physical state, float64 or complex128
ref = np.load("out/run/reference_u_final.npy")
print("error again:", np.linalg.norm(u - ref) / np.linalg.norm(ref))

inv = pd.read_csv("out/run/invariants.csv")    # one row per recorded step
print(inv[["t", "err_H", "err_I", "err_m", "tau_roughness"]].tail(3))

# A study: table.csv has one row per run, a column per varied path.
table = pd.read_csv("out/study/table.csv")
print(table.pivot_table(index="h", columns=["scheme", "eps"], values="error"))
study = json.load(open("out/study/study.json"))
print("study keys:", sorted(study))

# Every run of the study has its own directory.
first = table.iloc[0]["id"]
print(json.load(open(f"out/study/runs/{first}/result.json"))["status"])

# The tsi package gives the same as objects (numpy arrays, a DataFrame).
import tsi
s = tsi.study(json.load(open("study.json")), jobs=2)
print(s.to_pandas()[["scheme", "eps", "h", "error"]].head(3))
