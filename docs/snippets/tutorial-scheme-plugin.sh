#!/usr/bin/env bash
# A scheme plugin in C++ (the explicit exponential midpoint rule), built against an
# installed tsi, run, compared with SE1 in a study, and checked.
set -euo pipefail

build_dir="$(dirname "$(dirname "$(command -v tsi)")")"
cmake --install "$build_dir" --prefix "$PWD/prefix" > install.log
export PATH="$PWD/prefix/bin:$PATH"

cp -r prefix/share/tsi/examples/plugins/expmid .
cmake -S expmid -B expmid/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PWD/prefix" > configure.log
cmake --build expmid/build
tsi --plugin expmid/build/tsi_expmid.so list schemes | grep -A2 'exp-midpoint'

cat > hh-emp.json <<'JSON'
{
  "model": {"name": "henon-heiles", "eps": 1e-4},
  "scheme": {"name": "exp-midpoint"},
  "time": {"h": 0.125, "t_end": 1.0},
  "reference": {}
}
JSON
tsi run hh-emp.json --plugin expmid/build/tsi_expmid.so --out out/hh-emp

cat > emp-study.json <<'JSON'
{
  "kind": "convergence",
  "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1.0}, "reference": {}},
  "vary": {
    "scheme.name": ["se1", "exp-midpoint"],
    "model.eps": [1, 0.00390625, 1e-6],
    "time.h": [0.25, 0.125, 0.0625, 0.03125]
  }
}
JSON
tsi study emp-study.json --plugin expmid/build/tsi_expmid.so --out out/emp-study --no-plots

# The conformance checks of the plugin's scheme on Henon-Heiles, eps from 1e-3 to 1e-2.
tsi check henon-heiles --plugin expmid/build/tsi_expmid.so --eps 1e-2 --eps 1e-3
