"""`pip install .`: CMake builds the Python package tsi, and installs it with the core library,
the shipped plugins, the runner and the plugin SDK inside site-packages/tsi:

    tsi/__init__.py ... _tsi.*.so    the package (the module's RPATH: $ORIGIN/lib)
    tsi/lib/libtsi_core.so*          the core
    tsi/lib/tsi/plugins/tsi_*.so     the shipped plugins, found next to the core
    tsi/bin/tsi                      the runner; `tsi` on the PATH starts it
    tsi/include, tsi/lib/cmake/tsi   the SDK (find_package(tsi) with tsi_DIR there)

Offline, for Debian 12's python3-setuptools and pybind11-dev (no scikit-build-core there):
    /usr/bin/python3 -m venv --system-site-packages venv
    venv/bin/pip install --no-build-isolation .
Environment: TSI_PIP_BUILD_DIR, the CMake build directory (default: build-pip here; kept, so
a second install rebuilds only what changed); CMAKE_ARGS, more CMake options;
CMAKE_BUILD_PARALLEL_LEVEL, the build's jobs (default: every CPU this process may use).
"""
import os
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Distribution, setup
from setuptools.command.build_ext import build_ext
from distutils.command.build_scripts import build_scripts  # setuptools' own copy, once setuptools is in

SOURCE_DIR = os.path.dirname(os.path.abspath(__file__))
CMAKE_BUILD_DIR = os.path.abspath(os.environ.get("TSI_PIP_BUILD_DIR") or os.path.join(SOURCE_DIR, "build-pip"))
os.makedirs(CMAKE_BUILD_DIR, exist_ok=True)  # egg_info writes there

# The `tsi` command: starts the runner inside the installed package, wherever pip put it.
RUNNER_LAUNCHER = '''\
"""The runner installed with the Python package tsi (site-packages/tsi/bin/tsi)."""
import importlib.util
import os
import sys

spec = importlib.util.find_spec("tsi")  # found, not imported: importing loads every plugin
if spec is None or not spec.submodule_search_locations:
    sys.exit("tsi: the Python package tsi is not importable from " + sys.executable)
runner = os.path.join(list(spec.submodule_search_locations)[0], "bin", "tsi")
os.execv(runner, ["tsi"] + sys.argv[1:])
'''


def project_version():
    """The version in CMakeLists.txt's project(), so that the two never differ."""
    with open(os.path.join(SOURCE_DIR, "CMakeLists.txt"), encoding="utf-8") as f:
        match = re.search(r"project\(\s*tsi\s+VERSION\s+([0-9.]+)", f.read())
    if not match:
        raise RuntimeError("setup.py: no project(tsi VERSION ...) in CMakeLists.txt")
    return match.group(1)


def build_jobs():
    if os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL"):
        return os.environ["CMAKE_BUILD_PARALLEL_LEVEL"]
    return str(len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else os.cpu_count() or 1)


class CMakeBuild(build_ext):
    """Configures, builds and installs the CMake project into the wheel's tree (build_lib)."""

    def run(self):
        cmake = shutil.which("cmake")
        if not cmake:
            sys.exit("setup.py: cmake is needed (apt-get install cmake)")
        # Everything under tsi/ of the wheel: the package is the install prefix's tsi/, and the
        # layout relative to it is the one `cmake --install` makes, so RPATHs and the plugin
        # and script look-ups work unchanged.
        layout = {"CMAKE_INSTALL_BINDIR": "tsi/bin", "CMAKE_INSTALL_LIBDIR": "tsi/lib",
                  "CMAKE_INSTALL_INCLUDEDIR": "tsi/include", "CMAKE_INSTALL_DATAROOTDIR": "tsi/share",
                  "CMAKE_INSTALL_DATADIR": "tsi/share", "CMAKE_INSTALL_DOCDIR": "tsi/share/doc/tsi",
                  "TSI_PYTHON_INSTALL_DIR": "."}
        args = [cmake, "-S", SOURCE_DIR, "-B", CMAKE_BUILD_DIR, "-DCMAKE_BUILD_TYPE=Release",
                "-DTSI_BUILD_TESTS=OFF", "-DTSI_BUILD_BENCH=OFF", "-DTSI_BUILD_PYTHON=ON",
                "-DPython3_EXECUTABLE=" + sys.executable]
        args += [f"-D{name}={value}" for name, value in layout.items()]
        if shutil.which("ninja") and not os.path.exists(os.path.join(CMAKE_BUILD_DIR, "Makefile")):
            args += ["-G", "Ninja"]
        env = dict(os.environ)
        if shutil.which("ccache"):  # helps when present, never required
            args.append("-DCMAKE_CXX_COMPILER_LAUNCHER=ccache")
            env.setdefault("CCACHE_BASEDIR", SOURCE_DIR)
        args += shlex.split(os.environ.get("CMAKE_ARGS", ""))
        self.spawn_in(args, env)
        self.spawn_in([cmake, "--build", CMAKE_BUILD_DIR, "--parallel", build_jobs()], env)

        staged = os.path.join(os.path.abspath(self.build_lib), "tsi")
        shutil.rmtree(staged, ignore_errors=True)  # nothing left from an earlier build
        self.spawn_in([cmake, "--install", CMAKE_BUILD_DIR, "--prefix", os.path.abspath(self.build_lib)], env)
        if not os.path.isdir(staged) or not any(name.startswith("_tsi.") for name in os.listdir(staged)):
            sys.exit("setup.py: CMake did not build the module tsi._tsi (are python3-dev and pybind11-dev "
                     "installed? see " + os.path.join(CMAKE_BUILD_DIR, "CMakeCache.txt") + ")")

    def spawn_in(self, args, env):
        print(" ".join(shlex.quote(a) for a in args), flush=True)
        subprocess.run(args, env=env, check=True)

    def get_outputs(self):
        return []


class RunnerLauncher(build_scripts):
    """Writes the `tsi` launcher (its '#!python' line becomes the installing interpreter)."""

    def run(self):
        self.mkpath(self.build_dir)
        path = os.path.join(self.build_dir, "tsi")
        with open(path, "w", encoding="utf-8") as f:
            f.write("#!" + (self.executable or "python") + "\n" + RUNNER_LAUNCHER)
        os.chmod(path, 0o755)
        self.distribution.scripts = [path]  # install_scripts copies only when there are scripts

    def get_source_files(self):
        return []


class PlatformDistribution(Distribution):
    """A platform wheel: the package holds compiled code, though setuptools builds none itself."""

    def has_ext_modules(self):
        return True

    def has_scripts(self):
        return True


setup(
    version=project_version(),
    packages=[],
    py_modules=[],
    distclass=PlatformDistribution,
    cmdclass={"build_ext": CMakeBuild, "build_scripts": RunnerLauncher},
    # setuptools' own files beside the CMake build, not in the source tree or its build/.
    options={"build": {"build_base": os.path.join(CMAKE_BUILD_DIR, "setuptools")},
             "egg_info": {"egg_base": CMAKE_BUILD_DIR}},
    zip_safe=False,
)
