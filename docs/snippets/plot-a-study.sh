#!/usr/bin/env bash
# The figures of a study: drawn by `tsi study`, redrawn from the files, or drawn from Python.
set -euo pipefail

cat > conservation.json <<'JSON'
{"kind": "conservation",
 "base": {"model": {"name": "henon-heiles", "eps": 0.01}, "time": {"h": 0.2, "t_end": 40}},
 "vary": {"scheme.name": ["se1", "fd"]}}
JSON

# With python3-matplotlib installed, `tsi study` draws the kind's figure itself.
tsi study conservation.json --out out/conservation --quiet
ls out/conservation/conservation.png

# The script reads only table.csv, study.json and runs/: restyle it and redraw without rerunning.
tsi study conservation.json --out out/again --no-plots --quiet
/usr/bin/python3 "$TSI_SOURCE_DIR/scripts/plot_study.py" out/again
ls out/again/conservation.png

# From Python: the same figures, as matplotlib objects.
/usr/bin/python3 - <<'PY'
import json
import matplotlib
matplotlib.use("Agg")
import tsi
s = tsi.study(json.load(open("conservation.json")), jobs=2)
fig = s.plot()                                   # the figure of the study's kind
fig.savefig("from-python.png", dpi=80)
tsi.plot.conservation(s, "conservation-again.png")
print(type(fig).__name__)
PY
ls *.png
