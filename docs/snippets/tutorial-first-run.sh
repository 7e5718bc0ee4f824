#!/usr/bin/env bash
# First run: Henon-Heiles with SE1, checked, run, changed from the command line.
set -euo pipefail

# What is there: models, reformulations, schemes (with their parameters).
tsi list models
tsi list schemes

# The paper's first model at eps = 0.01, SE1, h = 1/8 up to t = 1, against rk78.
cp "$TSI_SOURCE_DIR/examples/hh-se1.json" .
cat hh-se1.json

# Check it as the run would, without running it.
tsi run hh-se1.json --dry-run

# Run it; the files go to out/hh-se1/.
tsi run hh-se1.json --out out/hh-se1
ls out/hh-se1

# eps = 1e-4 with the same step: the error does not grow as eps falls.
tsi run hh-se1.json --set model.eps=1e-4 --out out/hh-se1-eps1e-4

# Half the step: a quarter of the error (second order).
tsi run hh-se1.json --set model.eps=1e-4 --set time.h=0.0625 --out out/hh-se1-half-step
