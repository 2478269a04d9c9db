"""Declares the package's dependencies (numpy, h5py, pandas); everything else is in pyproject.toml.

Debian 12 registers its python3-h5py as the distribution "h5py._debian_h5py_serial", so pip does
not count it as "h5py" and, offline, fails to satisfy the requirement although `import h5py`
works. A requirement whose module is already importable without being registered under its own
name (a distribution's package) is therefore left out; on every other system the list is the full
one. The check runs where the package is built, which is the target environment with
`pip install --no-build-isolation` (the way docs/python.md installs it)."""
import importlib.metadata
import importlib.util

from setuptools import setup

REQUIRES = {"numpy": "numpy", "h5py": "h5py", "pandas": "pandas"}  # distribution: module


def _needed(distribution, module):
    try:
        importlib.metadata.version(distribution)
        return True  # registered: pip sees it, keep the requirement
    except importlib.metadata.PackageNotFoundError:
        return importlib.util.find_spec(module) is None


setup(install_requires=[d for d, m in REQUIRES.items() if _needed(d, m)])
