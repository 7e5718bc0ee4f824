"""`pip install .` as the README gives it: a fresh venv of the interpreter the package is
built for (/usr/bin/python3; its numpy seen through --system-site-packages), an offline
install of the source tree, then, from an empty directory with no build tree on any path,
`import tsi`, a Henon-Heiles run with the shipped plugins and the `tsi` command. The numbers
must be the build tree's.

    /usr/bin/python3 test_pip_install.py SOURCE_DIR CMAKE_BUILD_DIR

CMAKE_BUILD_DIR is kept between runs (setup.py's TSI_PIP_BUILD_DIR), so that a second run
rebuilds only what changed; a compiler cache is used when ccache is on the PATH.
"""
import json
import os
import subprocess
import sys
import tempfile
import time

CHILD = r"""
import json
import tsi
from tsi.models import HenonHeiles
tsi.register_model("py-hh", HenonHeiles, nonlinearity_degree=2)
config = {"model": {"name": "hh", "eps": 0.01}, "time": {"h": 0.125, "t_end": 1}, "reference": {}}
r = tsi.run(config)
config["model"]["name"] = "py-hh"
p = tsi.run(config)
print(json.dumps({"file": tsi.__file__, "plugins": tsi.plugin_directory(), "error": r.error,
                  "u_final": r.u_final.tolist(), "py_error": p.error, "models": tsi.list("models")}))
"""


def clean_env():
    """The environment without anything that points at a build tree or preloads a sanitizer."""
    drop = ("PYTHONPATH", "LD_LIBRARY_PATH", "LD_PRELOAD", "TSI_PLUGIN_PATH", "PYTHONHOME", "VIRTUAL_ENV")
    return {k: v for k, v in os.environ.items() if k not in drop and not k.startswith(("ASAN_", "UBSAN_"))}


def run(args, **kwargs):
    result = subprocess.run(args, capture_output=True, text=True, **kwargs)
    if result.returncode != 0:
        sys.exit(f"{' '.join(args)} failed ({result.returncode}):\n{result.stdout[-6000:]}\n{result.stderr[-6000:]}")
    return result.stdout


def main():
    source, cmake_build = sys.argv[1:3]
    with tempfile.TemporaryDirectory() as tmp:
        venv = os.path.join(tmp, "venv")
        elsewhere = os.path.join(tmp, "elsewhere")  # empty: no tsi/ beside the import
        os.mkdir(elsewhere)
        env = clean_env()
        run([sys.executable, "-m", "venv", "--system-site-packages", venv], env=env)
        python = os.path.join(venv, "bin", "python")

        start = time.monotonic()
        run([python, "-m", "pip", "install", "--no-build-isolation", "--no-index", "--no-cache-dir", source],
            env=dict(env, TSI_PIP_BUILD_DIR=cmake_build), cwd=elsewhere)
        install_seconds = time.monotonic() - start

        installed = json.loads(run([python, "-c", CHILD], env=env, cwd=elsewhere).strip().splitlines()[-1])
        site = run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['platlib'])"], env=env).strip()
        package = os.path.join(os.path.realpath(site), "tsi")
        assert os.path.realpath(installed["file"]) == os.path.join(package, "__init__.py"), installed["file"]
        assert os.path.realpath(installed["plugins"]) == os.path.join(package, "lib", "tsi", "plugins"), \
            installed["plugins"]
        assert "henon-heiles" in json.dumps(installed["models"]), installed["models"]
        # The Python-coded model against the plugin: independent code, the same numbers.
        assert abs(installed["py_error"] - installed["error"]) < 1e-12, installed

        # The runner on the venv's PATH, with the same plugins.
        listing = run([os.path.join(venv, "bin", "tsi"), "list", "models"], env=env, cwd=elsewhere)
        assert "henon-heiles" in listing, listing

    import tsi  # the build tree's (PYTHONPATH from ctest): the same numbers

    r = tsi.run({"model": {"name": "hh", "eps": 0.01}, "time": {"h": 0.125, "t_end": 1}, "reference": {}})
    assert abs(r.error - installed["error"]) <= 1e-14, (r.error, installed["error"])
    worst = max(abs(a - b) for a, b in zip(r.u_final.tolist(), installed["u_final"]))
    assert worst <= 1e-14, (r.u_final.tolist(), installed["u_final"])
    print(f"pip install in {install_seconds:.0f} s; {installed['file']}: error {installed['error']:.6e}, "
          f"the build tree's {r.error:.6e}")


if __name__ == "__main__":
    main()
