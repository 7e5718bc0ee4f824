#!/usr/bin/env bash
# Installs the Debian packages tsi needs, only those missing (README.md, "Dependencies").
set -euo pipefail
packages=(g++ cmake ninja-build pkg-config libeigen3-dev libfftw3-dev nlohmann-json3-dev
          libfmt-dev libspdlog-dev doctest-dev libcli11-dev libboost-dev libbenchmark-dev python3
          python3-matplotlib pybind11-dev python3-dev python3-numpy python3-pandas libopenmpi-dev openmpi-bin)
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
