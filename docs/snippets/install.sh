#!/usr/bin/env bash
# Install a built tsi into a prefix and use it from there: the runner, the Python package,
# the SDK for plugins.
set -euo pipefail

# The build directory (here: the one the tsi on PATH comes from; usually build/).
build_dir="$(dirname "$(dirname "$(command -v tsi)")")"
prefix="$PWD/opt/tsi"
cmake --install "$build_dir" --prefix "$prefix" > install.log

# The runner finds its library and shipped plugins relative to itself: no LD_LIBRARY_PATH.
"$prefix/bin/tsi" --version
"$prefix/bin/tsi" list schemes | sed -n 1,3p

# The Python package, under the prefix's site-packages, finds the installed core and plugins.
site="$(ls -d "$prefix"/lib/python3*/site-packages)"
PYTHONPATH="$site" /usr/bin/python3 -c "import tsi; print(tsi.__version__, tsi.plugin_directory())"

# What a plugin author gets: headers, the CMake package, example plugins, the plotting script.
ls "$prefix/include/tsi" | sed -n 1,3p
ls "$prefix/lib/cmake/tsi" "$prefix/share/tsi" "$prefix/share/tsi/examples/plugins"
