#!/usr/bin/env bash
# Runs a command the documentation shows: docs/snippets/NAME.sh, as a reader would run it after
# building tsi. A page includes the file (```{literalinclude} ../snippets/NAME.sh```), and the
# docs tests (tests/docs, ctest label docs) run every one of them with this script, so a page
# cannot show a command that fails.
#   run_snippet.sh NAME|FILE [BUILD_DIR]
# The snippet runs with bash in a fresh temporary directory (removed when it succeeds, kept and
# named when it fails), with BUILD_DIR/bin first on PATH (`tsi`), PYTHONPATH=BUILD_DIR/python
# (`import tsi`), TSI_SOURCE_DIR the source tree (`cp "$TSI_SOURCE_DIR/examples/hh-se1.json" .`)
# and MPLBACKEND=Agg. BUILD_DIR defaults to $TSI_DOCS_TSI_BUILD, then build/.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
snippet="$1"
[[ "$snippet" == */* || "$snippet" == *.sh ]] || snippet="$root/docs/snippets/$snippet.sh"
snippet="$(cd "$(dirname "$snippet")" && pwd)/$(basename "$snippet")"
build="$(cd "${2:-${TSI_DOCS_TSI_BUILD:-$root/build}}" && pwd)"
[ -x "$build/bin/tsi" ] || { echo "run_snippet: no $build/bin/tsi: build tsi first" >&2; exit 2; }
work="$(mktemp -d "${TMPDIR:-/tmp}/tsi-snippet.XXXXXX")"
status=0
(
  cd "$work"
  unset TSI_PLUGIN_PATH  # the shipped plugins, as a reader's fresh shell has them
  export PATH="$build/bin:$PATH" PYTHONPATH="$build/python${PYTHONPATH:+:$PYTHONPATH}" TSI_SOURCE_DIR="$root" \
         MPLBACKEND=Agg
  exec bash "$snippet"
) || status=$?
if [ "$status" -eq 0 ]; then
  rm -rf "$work"
else
  echo "run_snippet: $(basename "$snippet") exited with $status; its directory is kept: $work" >&2
fi
exit "$status"
