#!/usr/bin/env bash
# Runs the Python model tutorial (docs/snippets/tutorial-python-model.py).
set -euo pipefail
/usr/bin/python3 "$TSI_SOURCE_DIR/docs/snippets/tutorial-python-model.py"
