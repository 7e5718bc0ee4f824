#!/usr/bin/env bash
# Particle-in-cell: particles from a file, a run in a strong magnetic field, the density plotted.
set -euo pipefail

# 1. The particles: an N x 4 float64 array (x1, x2, v1, v2) in the box [0, 4 pi) x [0, 2 pi)
#    (the model's default k_x = 0.5, k_y = 1). Density 1 + 0.5 cos(x1 / 2), Maxwellian velocities.
/usr/bin/python3 - <<'PY'
import numpy as np
rng = np.random.default_rng(1)
n = 4096
x1 = np.empty(0)
while x1.size < n:  # rejection sampling of 1 + 0.5 cos(x1 / 2) on [0, 4 pi)
    x = rng.uniform(0, 4 * np.pi, n)
    keep = rng.uniform(0, 1.5, n) < 1 + 0.5 * np.cos(x / 2)
    x1 = np.concatenate([x1, x[keep]])
particles = np.column_stack([x1[:n], rng.uniform(0, 2 * np.pi, n), rng.normal(size=n), rng.normal(size=n)])
np.save("particles.npy", particles)
print(particles.shape, particles.dtype)
PY

# 2. The run: eps = 0.1 (gyration period 2 pi eps = 0.63), steps h = 0.2 up to t = 4.
cat > pic.json <<'JSON'
{
  "model": {"name": "vlasov-poisson-2d", "eps": 0.1, "particles": "particles.npy", "n_x": 32, "n_y": 16},
  "reformulation": {"name": "two-scale", "n_tau": 16},
  "scheme": {"name": "se1"},
  "time": {"h": 0.2, "t_end": 4},
  "output": {"every": 5}
}
JSON
tsi run pic.json --out out/pic

# 3. The energy W, the momentum |P| and the charge Q as the run recorded them.
head -n 3 out/pic/invariants.csv

# 4. The density at t = 0 (from particles.npy) beside the one at t = 4 (from u_final.npy).
/usr/bin/python3 "$TSI_SOURCE_DIR/scripts/plot_pic_density.py" out/pic
ls out/pic/density.png
