#!/usr/bin/env bash
# Installs the Debian packages frictherm needs (Debian 12). Skips apt entirely when all are present.
#   scripts/install_deps.sh [program|all]   (default all)
# program: what README command 1 needs to build the `frictherm` program and draw a run (compiler,
#          CMake, the libraries the program links, numpy/h5py/matplotlib for examples/plot_run.py).
#          Debian 12's libsundials-dev itself depends on petsc-dev and Open MPI, so those arrive too.
# all:     also the test suite (GoogleTest and GoogleMock: Debian 12 ships the GTest::gmock target the
#          tests link in libgmock-dev, not in libgtest-dev; pytest, pandas, xarray, venv, pybind11 for the bindings),
#          python3-wheel: `pip install --no-build-isolation ./python` in a venv needs setuptools' bdist_wheel,
#          Open MPI and PETSc for the distributed parts, ParaView's pvpython for the XDMF checks and
#          clang with its sanitizer/libFuzzer runtimes for scripts/run_checks.sh.
set -euo pipefail
profile=${1:-all}
program=(build-essential cmake pkg-config libeigen3-dev libsundials-dev libhdf5-dev nlohmann-json3-dev
         libboost-dev libmuparser-dev libpng-dev libtiff-dev python3 python3-numpy python3-matplotlib python3-h5py)
rest=(libgtest-dev libgmock-dev libopenmpi-dev openmpi-bin petsc-dev
      python3-paraview xvfb xauth python3-pandas python3-pytest python3-xarray python3-venv python3-wheel
      python3-dev pybind11-dev
      clang libclang-rt-dev libomp-dev)  # clang, its sanitizer/libFuzzer runtimes and OpenMP: scripts/run_checks.sh
case "$profile" in
  program) packages=("${program[@]}") ;;
  all) packages=("${program[@]}" "${rest[@]}") ;;
  *) echo "install_deps.sh: the profile is 'program' or 'all', not '$profile'" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all Debian packages present ($profile)"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
