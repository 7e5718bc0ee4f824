#!/usr/bin/env bash
# Builds the documentation site into build/docs/html (open build/docs/html/index.html; it works
# offline, from file://):
#   scripts/build-docs.sh
# 1. installs the Debian packages it needs when missing (Sphinx, MyST, furo, breathe, Doxygen,
#    sphinxcontrib-programoutput, MathJax; Debian 12's, no pip);
# 2. builds the runner, the shipped plugins and the Python module (scripts/build.sh, in build/);
# 3. generates the reference from the built runner (scripts/docs/generate_reference.py) and the
#    C++ API's XML (Doxygen, docs/Doxyfile);
# 4. runs Sphinx nitpicky with every warning an error (-n -W --keep-going), reading every page
#    again (-E: the Python docstrings and the commands' output are not tracked by Sphinx);
# 5. checks every internal link and anchor of the built site (scripts/docs/check_links.py).
# TSI_DOCS_TSI_BUILD=DIR documents the tsi already built in DIR instead of building build/;
# TSI_DOCS_OUT=DIR writes DIR/html (and DIR/doctrees, DIR/doxygen) instead of build/docs.
set -euo pipefail
root="$(cd "$(dirname "$0")/.." && pwd)"

packages=(python3-sphinx python3-myst-parser furo python3-breathe doxygen python3-sphinxcontrib.programoutput
          libjs-mathjax)
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "build-docs: installing ${missing[*]}"
  sudo=""
  [ "$(id -u)" -eq 0 ] || sudo="sudo"
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi

if [ -n "${TSI_DOCS_TSI_BUILD:-}" ]; then
  build="$(cd "$TSI_DOCS_TSI_BUILD" && pwd)"
else
  build="$root/build"
  echo "build-docs: building tsi, its plugins and its Python module in $build"
  "$root/scripts/build.sh" tsi tsi_plugins tsi_python
fi
out="${TSI_DOCS_OUT:-$root/build/docs}"
mkdir -p "$out"
out="$(cd "$out" && pwd)"
export TSI_DOCS_TSI_BUILD="$build" TSI_DOXYGEN_OUT="$out/doxygen" TSI_DOXYGEN_XML="$out/doxygen/xml"
unset TSI_PLUGIN_PATH  # the shipped plugins alone

echo "build-docs: the reference from $build/bin/tsi"
/usr/bin/python3 "$root/scripts/docs/generate_reference.py" --tsi "$build/bin/tsi" \
  --out "$root/docs/reference/generated"
mkdir -p "$TSI_DOXYGEN_OUT"
(cd "$root" && doxygen docs/Doxyfile)
if [ -s "$TSI_DOXYGEN_OUT/warnings.log" ]; then
  echo "build-docs: doxygen could not read $(wc -l <"$TSI_DOXYGEN_OUT/warnings.log") comment lines of the headers" \
       "($TSI_DOXYGEN_OUT/warnings.log)"
fi

echo "build-docs: sphinx-build -n -W into $out/html"
rm -rf "$out/html"  # no page left over from an earlier build's sources
/usr/bin/python3 -m sphinx -b html -E -n -W --keep-going -q -j auto -d "$out/doctrees" "$root/docs" "$out/html"

/usr/bin/python3 "$root/scripts/docs/check_links.py" "$out/html"
echo "build-docs: $out/html/index.html"
