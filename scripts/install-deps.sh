#!/usr/bin/env bash
# Installs the Debian packages tsi needs, only those missing (README.md, "Dependencies").
set -euo pipefail
packages=(g++ cmake ninja-build pkg-config libeigen3-dev libfftw3-dev nlohmann-json3-dev
          libfmt-dev libspdlog-dev doctest-dev libcli11-dev libboost-dev libbenchmark-dev python3
          python3-matplotlib pybind11-dev python3-dev python3-numpy python3-pandas libopenmpi-dev openmpi-bin
          python3-venv python3-pip python3-setuptools python3-wheel ccache libfftw3-mpi-dev libhdf5-dev
          python3-h5py)
# libfftw3-mpi-dev: a split run's grid transforms; libhdf5-dev: field snapshots (output.fields_every),
# which the tests read back with python3-h5py.
# python3-venv .. python3-wheel: `pip install .` (pyproject.toml, setup.py) and its test.
# ccache: never required; where present the builds go through it (scripts/build.sh), and the
# pip test's build reuses the Release build's objects.
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
[ ${#missing[@]} -eq 0 ] && exit 0
echo "tsi: installing ${missing[*]}"
sudo=""
[ "$(id -u)" -eq 0 ] || sudo="sudo"
$sudo apt-get update -qq
DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
