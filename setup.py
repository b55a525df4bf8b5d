"""Builds evcorner's _evcorner module with the project's CMake (pyproject.toml has the rest).

The extension is built by `cmake --build --target _evcorner` in the setuptools build
folder, with the library's own CMakeLists.txt (apps, tests and benchmarks off), and put
where setuptools expects it. CMAKE_ARGS (environment) adds configure arguments; the
number of compile jobs follows CMAKE_BUILD_PARALLEL_LEVEL (default: every core).
"""

import os
import shlex
import subprocess
import sys
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent


class CMakeExtension(Extension):
    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    def build_extension(self, ext):
        out_dir = Path(self.get_ext_fullpath(ext.name)).resolve().parent
        build_dir = Path(self.build_temp).resolve() / "cmake"
        build_dir.mkdir(parents=True, exist_ok=True)
        configure = [
            "cmake", "-S", str(ROOT), "-B", str(build_dir),
            "-DCMAKE_BUILD_TYPE=Release",
            "-DEVCORNER_BUILD_APPS=OFF", "-DEVCORNER_BUILD_TESTS=OFF", "-DEVCORNER_BUILD_BENCH=OFF",
            "-DEVCORNER_PYTHON=ON",
            f"-DPython_EXECUTABLE={sys.executable}",
            f"-DEVCORNER_PYTHON_OUTPUT_DIR={out_dir}",
            *shlex.split(os.environ.get("CMAKE_ARGS", "")),
        ]
        subprocess.run(configure, check=True)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL", str(os.cpu_count() or 1))
        subprocess.run(["cmake", "--build", str(build_dir), "--target", "_evcorner", "-j", jobs], check=True)


setup(
    ext_modules=[CMakeExtension("evcorner._evcorner")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": "build/pip"}},  # its own folder (build/ is the CMake build)
)
