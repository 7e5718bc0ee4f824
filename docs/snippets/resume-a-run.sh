#!/usr/bin/env bash
# Resume a run from its last saved state, and an interrupted study from its finished runs.
set -euo pipefail

# A run that saves its state every 40 steps (and at its last): out/first/state.npy.
cat > hh-long.json <<'JSON'
{
  "model": {"name": "henon-heiles", "eps": 0.01},
  "scheme": {"name": "se1"},
  "time": {"h": 0.125, "t_end": 20},
  "output": {"state_every": 40}
}
JSON
tsi run hh-long.json --out out/first
/usr/bin/python3 -c "import json; print(json.load(open('out/first/result.json'))['state'])"

# Go on from there for 10 more time units: u0 is the saved state, t_end the time left.
tsi run hh-long.json --set model.u0=out/first/state.npy --set time.t_end=10 --out out/second

# A particle run resumes the same way from its particles: model.particles names state.npy.
cat > pic.json <<'JSON'
{
  "model": {"name": "vlasov-poisson-2d", "eps": 0.1, "particles": 1024, "n_x": 16, "n_y": 16},
  "reformulation": {"name": "two-scale", "n_tau": 16},
  "scheme": {"name": "se1"},
  "time": {"h": 0.25, "t_end": 2},
  "output": {"state_every": 4}
}
JSON
tsi run pic.json --out out/pic
tsi run pic.json --set model.particles=out/pic/state.npy --set time.t_end=1 --out out/pic-more

# A study whose runs did not all finish (here: one run's files removed) goes on with --resume:
# the finished runs are kept, the others run.
cat > study.json <<'JSON'
{"kind": "convergence",
 "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
 "vary": {"model.eps": [1, 0.001], "time.h": [0.25, 0.125, 0.0625]}}
JSON
tsi study study.json --out out/study --no-plots --quiet
rm -r out/study/runs/r0004
tsi study study.json --out out/study --no-plots --resume
