"""Builds the Python package dualgrid with CMake for `pip install --no-build-isolation .`
(pyproject.toml; docs/python.md, "Installation").

The extension is built by the project's CMake for the interpreter running pip
(-DPython3_EXECUTABLE=sys.executable), with the project's targets `_dualgrid` and
`dualgrid_networks`; the package gets the extension, its stub, the build record and the SUMO
networks (dualgrid/networks, found by installed_network_dir()).

Environment: DUALGRID_CMAKE_ARGS (extra configure arguments, e.g.
"-DCMAKE_CXX_COMPILER_LAUNCHER=ccache"), DUALGRID_PIP_BUILD_DIR (CMake's build folder; default
build/pip/cmake under this folder), CMAKE_BUILD_PARALLEL_LEVEL (jobs; default 2).
"""

import glob
import os
import re
import shlex
import shutil
import subprocess
import sys

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

HERE = os.path.dirname(os.path.abspath(__file__))


def project_version():
    with open(os.path.join(HERE, "CMakeLists.txt")) as f:
        m = re.search(r"project\(dualgrid VERSION ([0-9.]+)", f.read())
    if not m:
        raise RuntimeError("setup.py: no 'project(dualgrid VERSION x.y.z' in CMakeLists.txt")
    return m.group(1)


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        build = os.environ.get("DUALGRID_PIP_BUILD_DIR") or os.path.join(HERE, "build", "pip",
                                                                          "cmake")
        configure = ["cmake", "-S", HERE, "-B", build, "-DCMAKE_BUILD_TYPE=Release",
                     f"-DPython3_EXECUTABLE={sys.executable}", "-DDUALGRID_BUILD_TESTS=OFF",
                     "-DDUALGRID_BUILD_BENCHMARKS=OFF", "-DDUALGRID_BUILD_PYTHON=ON",
                     *shlex.split(os.environ.get("DUALGRID_CMAKE_ARGS", ""))]
        if shutil.which("cmake") is None:
            raise RuntimeError("setup.py: cmake not found (Debian: apt-get install cmake; "
                               "scripts/bootstrap.sh installs every build dependency)")
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", "2")
        subprocess.run(["cmake", "--build", build, "--target", "_dualgrid", "dualgrid_networks",
                        "-j", jobs], check=True)
        site = os.path.join(build, "python", "site", "dualgrid")
        built = glob.glob(os.path.join(site, "_dualgrid*.so"))
        if len(built) != 1:
            raise RuntimeError(f"setup.py: expected one _dualgrid*.so in {site}, found {built}")
        target = self.get_ext_fullpath(ext.name)
        package = os.path.dirname(target)
        os.makedirs(package, exist_ok=True)
        shutil.copyfile(built[0], target)
        for f in ("_build_info.py", "_dualgrid.pyi", "py.typed"):
            shutil.copyfile(os.path.join(site, f), os.path.join(package, f))
        networks = os.path.join(package, "networks")
        os.makedirs(networks, exist_ok=True)
        for net in glob.glob(os.path.join(build, "networks", "*.net.xml")):
            shutil.copyfile(net, os.path.join(networks, os.path.basename(net)))


setup(
    version=project_version(),
    packages=["dualgrid"],
    package_dir={"dualgrid": "python/dualgrid"},
    ext_modules=[Extension("dualgrid._dualgrid", sources=[])],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": os.path.join("build", "pip")},
             "egg_info": {"egg_base": os.path.join("build", "pip")}},
    zip_safe=False,
)
