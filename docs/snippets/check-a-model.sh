#!/usr/bin/env bash
# tsi check: the conformance checks of a model (or of a plugin's models and schemes).
set -euo pipefail

# Two schemes on Henon-Heiles, judged on the maximum of the error over a dense sample of
# eps in [1e-3, 1e-2] (32 log-spaced, the two given, and the step-size resonances inside).
tsi check henon-heiles --scheme se1 --scheme fd --eps 1e-2 --eps 1e-3

# A model's own parameters, the two-scale problem's and a scheme's go in with --set.
tsi check nls --set model.n_x=8 --set reformulation.n_tau=64 --scheme se1 --eps 1e-2 --steps 4 --steps 8 --steps 16 --steps 32

# A check that fails says what it measured: here n_tau = 4 does not resolve tau (exit code 1).
tsi check henon-heiles --set reformulation.n_tau=4 --scheme se1 --eps 1e-2 || echo "exit code $?"
