#!/usr/bin/env bash
# A 2-D PDE: the cubic NLS on the torus [0, 2 pi)^2, i u_t = -(1/eps) lap u + |u|^2 u.
set -euo pipefail

# 1. A plane wave, an exact solution: the error against it does not depend on eps.
cp "$TSI_SOURCE_DIR/examples/multi-dim/nls-2d-plane-wave.json" .
cat nls-2d-plane-wave.json
tsi run nls-2d-plane-wave.json --out out/plane-wave
tsi run nls-2d-plane-wave.json --set model.eps=1e-6 --out out/plane-wave-eps1e-6

# 2. Initial data of your own: samples of u0 on the 16 x 16 grid, x_j = 2 pi j / 16, as a .npy file.
/usr/bin/python3 - <<'PY'
import numpy as np
x = 2 * np.pi * np.arange(16) / 16
X, Y = np.meshgrid(x, x, indexing="ij")          # C order: u0[i, j] = u0(x_i, y_j)
u0 = np.exp(1j * X) / (1 + np.sin(X) ** 2) * (1 + 0.5 * np.cos(Y))
np.save("u0.npy", u0.astype(np.complex128))
PY

# n_tau = 4 max |m|^2 = 4 (8^2 + 8^2) = 512 resolves the cubic term's tau frequencies.
cat > nls-2d.json <<'JSON'
{
  "model": {"name": "nls", "eps": 0.01, "dims": 2, "n_x": 16, "u0": "u0.npy"},
  "reformulation": {"name": "two-scale", "n_tau": 512},
  "scheme": {"name": "se1"},
  "time": {"h": 0.0625, "t_end": 1},
  "reference": {},
  "output": {"every": 4}
}
JSON
tsi run nls-2d.json --out out/nls-2d

# 3. u(t_end) comes back on the grid, in u0's shape; plot |u|^2.
/usr/bin/python3 - <<'PY'
import matplotlib
matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np
u = np.load("out/nls-2d/u_final.npy")
print(u.shape, u.dtype, "mass", (np.abs(u) ** 2).mean() * (2 * np.pi) ** 2)
plt.imshow(np.abs(u.T) ** 2, origin="lower", extent=[0, 2 * np.pi, 0, 2 * np.pi])
plt.colorbar(label="|u(1, x, y)|^2")
plt.xlabel("x"); plt.ylabel("y")
plt.savefig("nls-2d.png", dpi=80)
PY

# 4. The same grid for Klein-Gordon: a plane wave at lambda = 0 is exact, met to rounding.
cat > kg-2d.json <<'JSON'
{
  "model": {"name": "klein-gordon", "eps": 1e-3, "dims": 2, "n_x": 8, "initial": "plane-wave",
            "wave_vector": [2, -1], "amplitude": 1, "lambda": 0},
  "scheme": {"name": "se1"},
  "time": {"h": 0.125, "t_end": 1},
  "reference": {"scheme": "exact"}
}
JSON
tsi run kg-2d.json --out out/kg-2d
