"""`pip install .`: builds the C++ with CMake and installs, into the interpreter's environment,
the Python package (`import dicestack`), the `dicestack` command, the shared libraries, the
headers and the CMake package, laid out as `cmake --install` lays them out under a prefix (the
module and the command find the libraries relative to themselves). Offline, with Debian's
setuptools (docs/python.md):

    python3 -m venv --system-site-packages v
    v/bin/pip install --no-build-isolation .

DICESTACK_BUILD_DIR=DIR installs from a build tree already built for this interpreter instead of
configuring and building one in build-pip/ (the tests do, to check the install in seconds).
DICESTACK_BUILD_JOBS sets the build's parallel jobs (default: the machine's cores).
"""
import os
import re
import shutil
import subprocess
import sys

from setuptools import setup
from setuptools.command.build import build

ROOT = os.path.dirname(os.path.abspath(__file__))


def cmake_version():
    with open(os.path.join(ROOT, "CMakeLists.txt"), encoding="utf-8") as f:
        return re.search(r"project\(dicestack VERSION ([0-9.]+)", f.read()).group(1)


def run(*command):
    print("dicestack setup:", " ".join(command), flush=True)
    subprocess.run(command, check=True)


class BuildWithCMake(build):
    """Builds (or reuses) the CMake tree, installs it into a staging prefix, then takes the
    Python package from there and hands everything else to install_data, under the prefix."""

    def run(self):
        build = os.environ.get("DICESTACK_BUILD_DIR")
        if not build:
            build = os.path.join(ROOT, "build-pip")
            run("cmake", "-S", ROOT, "-B", build, "-DCMAKE_BUILD_TYPE=Release", "-DDICESTACK_BUILD_TESTS=OFF", "-DCMAKE_UNITY_BUILD=ON",
                "-DPython3_EXECUTABLE=" + sys.executable)
            run("cmake", "--build", build, "-j", os.environ.get("DICESTACK_BUILD_JOBS", str(os.cpu_count() or 2)))
        staging = os.path.abspath(os.path.join(self.build_temp, "dicestack-staging"))
        shutil.rmtree(staging, ignore_errors=True)
        run("cmake", "--install", build, "--prefix", staging)
        package = None
        for folder, _, files in os.walk(staging):
            if os.path.basename(folder) == "dicestack" and "__init__.py" in files:
                package = folder
        if package is None:
            sys.exit("dicestack setup: the build has no Python package (were Python 3 headers, pybind11 and numpy found?)")
        target = os.path.join(self.build_lib, "dicestack")
        shutil.rmtree(target, ignore_errors=True)
        shutil.copytree(package, target)
        site = os.path.dirname(package)
        data = {}
        for folder, _, files in os.walk(staging):
            if folder == site or folder.startswith(site + os.sep):
                continue
            for name in files:
                relative = os.path.relpath(folder, staging)
                data.setdefault(relative, []).append(os.path.join(folder, name))
        self.distribution.data_files = sorted(data.items())
        super().run()


setup(
    version=cmake_version(),
    packages=[],  # the package comes from the CMake install (BuildWithCMake)
    cmdclass={"build": BuildWithCMake},
    has_ext_modules=lambda: True,  # a platform wheel: the package holds a compiled module
    options={"build": {"build_base": os.path.join("build-pip", "setuptools")}},  # not the developers' build/
)
