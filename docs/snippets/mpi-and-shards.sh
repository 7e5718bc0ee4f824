#!/usr/bin/env bash
# A study split into shards (no MPI needed) and merged; the same study over MPI ranks; one
# particle run split over MPI ranks.
set -euo pipefail

cat > study.json <<'JSON'
{"kind": "convergence",
 "base": {"model": {"name": "henon-heiles"}, "time": {"t_end": 1}, "reference": {}},
 "vary": {"scheme.name": ["se1", "fd"], "model.eps": [1, 0.001], "time.h": [0.25, 0.125, 0.0625]}}
JSON

# Shards: each an independent process (a batch array job), anywhere; then one merge.
tsi study study.json --shard 1/2 --out shards/1 --quiet
tsi study study.json --shard 2/2 --out shards/2 --quiet
tsi study --merge shards/1 shards/2 --out out/merged --no-plots

# The rest needs a tsi built with MPI (Open MPI found by CMake) and mpirun.
if ! command -v mpirun > /dev/null; then echo "no mpirun on PATH: the MPI part is left out"; exit 0; fi

# Open MPI refuses to start as root unless told; in a container that is the usual user.
if [ "$(id -u)" = 0 ]; then export OMPI_ALLOW_RUN_AS_ROOT=1 OMPI_ALLOW_RUN_AS_ROOT_CONFIRM=1; fi
# Two ranks even where fewer cores are free.
export OMPI_MCA_rmaps_base_oversubscribe=1

# The same study over two MPI ranks: rank 0 hands out the references, then the runs.
mpirun -np 2 tsi study study.json --out out/mpi --no-plots

# The tables agree but for the wall times.
cut -d, -f1-10 out/merged/table.csv | sed -n 1,4p
cut -d, -f1-10 out/mpi/table.csv | sed -n 1,4p

# One particle run over two ranks: each holds half the particles, the density is summed.
cat > pic.json <<'JSON'
{
  "model": {"name": "vlasov-poisson-2d", "eps": 0.1, "particles": 2048, "n_x": 16, "n_y": 16},
  "reformulation": {"name": "two-scale", "n_tau": 16},
  "scheme": {"name": "se1"},
  "time": {"h": 0.25, "t_end": 1}
}
JSON
mpirun -np 2 tsi run pic.json --split --out out/pic-split
tsi run pic.json --out out/pic-one --quiet
/usr/bin/python3 -c "
import numpy as np
a, b = np.load('out/pic-split/u_final.npy'), np.load('out/pic-one/u_final.npy')
print('two ranks against one process:', np.abs(a - b).max() / np.abs(b).max())"
