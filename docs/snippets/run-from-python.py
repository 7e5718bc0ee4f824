"""tsi from Python: runs and studies as objects, errors as exceptions."""
import numpy as np

import tsi

print(tsi.__version__, [m["name"] for m in tsi.list("models")])

# A run: the config is the dict `tsi run` reads as JSON; `out` also writes its files.
r = tsi.run({"model": {"name": "henon-heiles", "eps": 0.01}, "scheme": {"name": "se1"},
             "time": {"h": 0.125, "t_end": 1}, "reference": {}}, out="out/hh")
print(r)                                    # <tsi.RunResult completed, steps=8, error=...>
print(r.status, r.error, r.u_final, r.reference)
print(r.invariants["err_H"].max(), r.result["rhs_evaluations"])

# Bad input raises tsi.ConfigError naming the field, with the command line's message.
try:
    tsi.run({"model": {"name": "henon-heiles", "eps": 2}})
except tsi.ConfigError as e:
    print("ConfigError:", e.field)

# A run that blows up is returned, not raised: its status says how it ended.
r = tsi.run({"model": {"name": "henon-heiles", "eps": 0.1}, "scheme": {"name": "me"},
             "time": {"h": 0.5, "t_end": 200}})
print(r.status, r.t_reached, r.message[:60])

# A study: the spec as a dict, overrides on its base, the table as a DataFrame.
spec = {"kind": "convergence",
        "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
        "vary": {"scheme.name": ["se1", "se2"], "model.eps": [1, 1e-4], "time.h": [0.25, 0.125, 0.0625]}}
s = tsi.study(spec, jobs=2, overrides={"reformulation.n_tau": 32}, out="out/study")
print(s)
print(s.table[["scheme", "eps", "h", "error", "order"]])
print(s.convergence.keys() if s.convergence else None)
print(s.runs[0].u_final)

# A two-scale run of a large grid on several threads (the answer does not depend on them).
a = tsi.run({"model": {"name": "nls", "n_x": 64}, "time": {"h": 0.125, "t_end": 0.25}}, threads=1)
b = tsi.run({"model": {"name": "nls", "n_x": 64}, "time": {"h": 0.125, "t_end": 0.25}}, threads=2)
print("threads: same answer", np.array_equal(a.u_final, b.u_final))
