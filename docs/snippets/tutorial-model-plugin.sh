#!/usr/bin/env bash
# A model plugin in C++, built against an installed tsi: the general class (van der Pol),
# then the Hamiltonian class (the FPUT chain).
set -euo pipefail

# 0. An installed tsi: here the build tree the runner on PATH comes from, installed into ./prefix.
build_dir="$(dirname "$(dirname "$(command -v tsi)")")"
cmake --install "$build_dir" --prefix "$PWD/prefix" > install.log
export PATH="$PWD/prefix/bin:$PATH"
ls prefix/share/tsi/examples/plugins

# 1. Start from the installed example of the general class: two files, CMakeLists.txt and the model.
cp -r prefix/share/tsi/examples/plugins/van_der_pol .
cmake -S van_der_pol -B van_der_pol/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PWD/prefix" > configure.log
cmake --build van_der_pol/build

# 2. Load it: the model is listed, marked as the plugin's.
tsi --plugin van_der_pol/build/tsi_van_der_pol.so list models | grep -A6 'van-der-pol'

# 3. Run it: no energy is shown (the model declares no Hamiltonian structure).
tsi --plugin van_der_pol/build/tsi_van_der_pol.so run van_der_pol/van-der-pol-se1.json --out out/vdp

# 4. Check it: the interface, and SE1's uniform order over a dense sample of eps in [1e-4, 1e-2].
tsi check --plugin van_der_pol/build/tsi_van_der_pol.so --scheme se1 --eps 1e-2 --eps 1e-4

# 5. The Hamiltonian class: the FPUT chain, with energies and their checks.
cp -r prefix/share/tsi/examples/plugins/fput .
cmake -S fput -B fput/build -G Ninja -DCMAKE_BUILD_TYPE=Release -DCMAKE_PREFIX_PATH="$PWD/prefix" > configure.log
cmake --build fput/build
TSI_PLUGIN_PATH=fput/build tsi run fput/fput-se1.json --out out/fput-se1
tsi --plugin fput/build/tsi_fput.so study fput/fput-study.json --out out/fput-study --jobs 2 --no-plots
tsi check --plugin fput/build/tsi_fput.so --scheme se1 --scheme fd --eps 1e-2
