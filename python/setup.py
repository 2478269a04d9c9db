"""Declares the package's dependencies (numpy, h5py, pandas) and, when there is one, puts the compiled
bindings frictherm/_native into the package; everything else is in pyproject.toml.

Dependencies. Debian 12 registers its python3-h5py as the distribution "h5py._debian_h5py_serial", so
pip does not count it as "h5py" and, offline, fails to satisfy the requirement although `import h5py`
works. A requirement whose module is already importable without being registered under its own
name (a distribution's package) is therefore left out; on every other system the list is the full
one. The check runs where the package is built, which is the target environment with
`pip install --no-build-isolation` (the way docs/python.md installs it).

Bindings. frictherm._native (python/src/native.cpp) is compiled by the CMake build (it needs the C++
library and pybind11, Debian pybind11-dev) into <build>/python/frictherm. This file takes it from
$FRICTHERM_NATIVE (the module file itself), else from $FRICTHERM_BUILD_DIR/python/frictherm, else from
../build/python/frictherm beside these sources (the repository's own build), and installs it with the
package when it was built for this interpreter (its file name ends in one of this Python's extension
suffixes, e.g. .cpython-311-x86_64-linux-gnu.so). The wheel is then platform-specific. Without such a
module the package installs as pure Python (the reader; frictherm.run says what is missing) and a
note says where it looked. FRICTHERM_NATIVE=none forces the pure install.
"""
import glob
import importlib.machinery
import importlib.metadata
import importlib.util
import os
import shutil

from setuptools import setup
from setuptools.command.build_py import build_py
from setuptools.dist import Distribution

REQUIRES = {"numpy": "numpy", "h5py": "h5py", "pandas": "pandas"}  # distribution: module
HERE = os.path.dirname(os.path.abspath(__file__))


def _needed(distribution, module):
    try:
        importlib.metadata.version(distribution)
        return True  # registered: pip sees it, keep the requirement
    except importlib.metadata.PackageNotFoundError:
        return importlib.util.find_spec(module) is None


def _native_module():
    """(path of a compiled frictherm/_native for this interpreter or None, where it was looked for)."""
    given = os.environ.get("FRICTHERM_NATIVE", "")
    if given == "none":
        return None, "FRICTHERM_NATIVE=none"
    if given:
        candidates, places = [given], [given]
    else:
        build = os.environ.get("FRICTHERM_BUILD_DIR", os.path.join(HERE, "..", "build"))
        folder = os.path.join(build, "python", "frictherm")
        candidates, places = sorted(glob.glob(os.path.join(folder, "_native*"))), [folder]
    for path in candidates:
        name = os.path.basename(path)
        if os.path.isfile(path) and any(name == "_native" + s for s in importlib.machinery.EXTENSION_SUFFIXES):
            return os.path.abspath(path), places
    return None, places


NATIVE, LOOKED_IN = _native_module()


class BuildWithNative(build_py):
    """build_py that also copies the compiled bindings into the package."""

    def run(self):
        super().run()
        if NATIVE:
            target = os.path.join(self.build_lib, "frictherm", os.path.basename(NATIVE))
            shutil.copy2(NATIVE, target)
            print(f"frictherm: bindings {NATIVE} -> {target}")
        else:
            print(f"frictherm: no compiled bindings for this Python in {LOOKED_IN}: installing the reader only "
                  "(build frictherm with pybind11, Debian pybind11-dev, and set FRICTHERM_BUILD_DIR; docs/python.md)")


class NativeDistribution(Distribution):
    def has_ext_modules(self):  # a platform wheel when it carries the compiled module
        return NATIVE is not None


setup(install_requires=[d for d, m in REQUIRES.items() if _needed(d, m)],
      cmdclass={"build_py": BuildWithNative}, distclass=NativeDistribution)
