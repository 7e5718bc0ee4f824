"""Runs a notebook's code cells in order as one script (what nbconvert --execute would do,
without needing it), in a fresh temporary directory: python3 run_notebook.py NOTEBOOK.ipynb.
Cell magics and shell lines (% and !) are skipped. Exits non-zero when a cell raises, naming the cell."""
import json
import os
import sys
import tempfile
import traceback


def main():
    path = sys.argv[1]
    with open(path) as f:
        notebook = json.load(f)
    scope = {"__name__": "__main__"}
    os.chdir(tempfile.mkdtemp(prefix="tsi-notebook-"))  # whatever the cells write stays out of the tree
    cells = [c for c in notebook["cells"] if c["cell_type"] == "code"]
    for k, cell in enumerate(cells, 1):
        source = "".join(cell["source"])
        lines = [line for line in source.splitlines() if not line.lstrip().startswith(("%", "!"))]
        try:
            exec(compile("\n".join(lines), f"{os.path.basename(path)} [cell {k}]", "exec"), scope)
        except Exception:
            traceback.print_exc()
            sys.exit(f"{path}: code cell {k} of {len(cells)} raised")
    print(f"{path}: {len(cells)} code cells ran")


if __name__ == "__main__":
    main()
