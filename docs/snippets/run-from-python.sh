#!/usr/bin/env bash
# Runs docs/snippets/run-from-python.py with the package on PYTHONPATH.
set -euo pipefail
/usr/bin/python3 "$TSI_SOURCE_DIR/docs/snippets/run-from-python.py"
ls out/hh out/study
