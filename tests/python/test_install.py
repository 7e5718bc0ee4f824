"""The installed package: `cmake --install` into a temporary prefix, then import tsi from
<prefix>/<TSI_PYTHON_INSTALL_DIR> alone (a fresh interpreter, another working directory, no
build tree on any path), run Henon-Heiles and compare with the build tree's package.

    /usr/bin/python3 test_install.py CMAKE BUILD_DIR PYTHON_INSTALL_DIR
"""
import json
import os
import subprocess
import sys
import tempfile

CHILD = r"""
import json, sys
import tsi
from tsi.models import HenonHeiles
tsi.register_model("py-hh", HenonHeiles, nonlinearity_degree=2)
config = {"model": {"name": "hh", "eps": 0.01}, "time": {"h": 0.125, "t_end": 1}, "reference": {}}
r = tsi.run(config)
config["model"]["name"] = "py-hh"
p = tsi.run(config)
print(json.dumps({"file": tsi.__file__, "plugins": tsi.plugin_directory(), "error": r.error,
                  "u_final": r.u_final.tolist(), "py_error": p.error}))
"""


def main():
    cmake, build, site = sys.argv[1:4]
    with tempfile.TemporaryDirectory() as tmp:
        prefix = os.path.join(tmp, "prefix")
        subprocess.run([cmake, "--install", build, "--prefix", prefix], check=True, stdout=subprocess.DEVNULL)
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "LD_LIBRARY_PATH", "TSI_PLUGIN_PATH")}
        env["PYTHONPATH"] = os.path.join(prefix, site)
        out = subprocess.run([sys.executable, "-c", CHILD], env=env, cwd=tmp, check=True, capture_output=True,
                             text=True).stdout
        installed = json.loads(out.strip().splitlines()[-1])
        real_prefix = os.path.realpath(prefix)
        assert os.path.realpath(installed["file"]).startswith(real_prefix), installed["file"]
        assert os.path.realpath(installed["plugins"]) == os.path.join(real_prefix, "lib", "tsi", "plugins"), \
            installed["plugins"]
        assert abs(installed["py_error"] - installed["error"]) < 1e-12, installed

    import tsi  # the build tree's (PYTHONPATH from ctest): the same numbers

    r = tsi.run({"model": {"name": "hh", "eps": 0.01}, "time": {"h": 0.125, "t_end": 1}, "reference": {}})
    assert r.u_final.tolist() == installed["u_final"], (r.u_final.tolist(), installed["u_final"])
    assert r.error == installed["error"]
    print(f"installed package: {installed['file']}, error {installed['error']:.6e} as in the build tree")


if __name__ == "__main__":
    main()
