#!/usr/bin/env bash
# Initial data of your own: in the config, from a .npy file, and the models' own forms.
set -euo pipefail

# In the config: physical variables, complex entries as [re, im].
tsi run "$TSI_SOURCE_DIR/examples/hh-se1.json" --set 'model.u0=[0.1, 0.2, 0.1, 0.0]' --out out/hh-u0 --quiet > /dev/null

# From a .npy file (relative to the config's directory): float64 or complex128, C order, any
# shape with the model's number of values. NLS takes samples on its grid.
/usr/bin/python3 - <<'PY'
import numpy as np
x = 2 * np.pi * np.arange(16) / 16
np.save("u0-nls.npy", (1 + 0.3 * np.cos(2 * x)) * np.exp(1j * x))
PY
cat > nls.json <<'JSON'
{"model": {"name": "nls", "eps": 0.01, "n_x": 16, "u0": "u0-nls.npy"},
 "reformulation": {"name": "two-scale", "n_tau": 256},
 "time": {"h": 0.125, "t_end": 1},
 "reference": {}}
JSON
tsi run nls.json --out out/nls

# A file that does not fit is refused before anything runs, naming model.u0 and the file.
/usr/bin/python3 -c "import numpy as np; np.save('wrong.npy', np.zeros(10))"
tsi run nls.json --set model.u0=wrong.npy || echo "exit code $?"

# Klein-Gordon from the literature's data: z(x, 0) and e^2 z_t(x, 0) on the grid (the model
# converts them to its variable v).
/usr/bin/python3 - <<'PY'
import json
import numpy as np
x = 2 * np.pi * np.arange(16) / 16
json.dump({"model": {"name": "klein-gordon", "eps": 0.01, "z0": (np.cos(x) / (1 + np.sin(x) ** 2)).tolist(),
                     "eps_z_t0": (0.5 * np.sin(x)).tolist()},
           "time": {"h": 0.0625, "t_end": 1}, "reference": {}}, open("kg.json", "w"))
PY
tsi run kg.json --out out/kg

# Particles from a file: an N x 4 array (x1, x2, v1, v2) in model.particles.
/usr/bin/python3 -c "
import numpy as np
rng = np.random.default_rng(0)
n = 512
np.save('particles.npy', np.column_stack([rng.uniform(0, 4 * np.pi, n), rng.uniform(0, 2 * np.pi, n), rng.normal(size=(n, 2))]))"
cat > pic.json <<'JSON'
{"model": {"name": "vlasov-poisson-2d", "eps": 0.1, "particles": "particles.npy"},
 "reformulation": {"name": "two-scale", "n_tau": 16},
 "time": {"h": 0.25, "t_end": 1}}
JSON
tsi run pic.json --out out/pic
