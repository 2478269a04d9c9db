#!/usr/bin/env bash
# Installs the Debian packages frictherm needs (Debian 12). Skips apt entirely when all are present.
#   scripts/install_deps.sh [program|all|build|plot]   (default all)
#   scripts/install_deps.sh --check PROFILE             exit status 0 when all of PROFILE is present
# program: what README command 1 needs to build the `frictherm` program and draw a run: `build` and `plot`.
# build:   what compiling and running the program needs (compiler, CMake, the libraries the program
#          links). Debian 12's libsundials-dev itself depends on petsc-dev and Open MPI, so those arrive too.
# plot:    numpy, h5py and matplotlib for examples/plot_run.py. scripts/run_example.sh installs `build`,
#          then `plot` in the background while the program compiles (nothing it compiles needs them).
# all:     also the test suite (GoogleTest and GoogleMock: Debian 12 ships the GTest::gmock target the
#          tests link in libgmock-dev, not in libgtest-dev; pytest, pandas, xarray, venv, pybind11 for the bindings),
#          python3-wheel: `pip install --no-build-isolation ./python` in a venv needs setuptools' bdist_wheel,
#          Open MPI and PETSc for the distributed parts, ParaView's pvpython for the XDMF checks and
#          clang with its sanitizer/libFuzzer runtimes for scripts/run_checks.sh.
set -euo pipefail
check=no
if [ "${1:-}" = --check ]; then check=yes; shift; fi
profile=${1:-all}
build=(build-essential cmake pkg-config libeigen3-dev libsundials-dev libhdf5-dev nlohmann-json3-dev
       libboost-dev libmuparser-dev libpng-dev libtiff-dev)
plot=(python3 python3-numpy python3-matplotlib python3-h5py)
rest=(libgtest-dev libgmock-dev libopenmpi-dev openmpi-bin petsc-dev
      python3-paraview xvfb xauth python3-pandas python3-pytest python3-xarray python3-venv python3-wheel
      python3-dev pybind11-dev
      clang libclang-rt-dev libomp-dev)  # clang, its sanitizer/libFuzzer runtimes and OpenMP: scripts/run_checks.sh
case "$profile" in
  build) packages=("${build[@]}") ;;
  plot) packages=("${plot[@]}") ;;
  program) packages=("${build[@]}" "${plot[@]}") ;;
  all) packages=("${build[@]}" "${plot[@]}" "${rest[@]}") ;;
  *) echo "install_deps.sh: the profile is 'program', 'all', 'build' or 'plot', not '$profile'" >&2; exit 2 ;;
esac
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ $check = yes ]; then
  [ ${#missing[@]} -eq 0 ]; exit
fi
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all Debian packages present ($profile)"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
# INSTALL_DEPS_UPDATED=1: the package lists were just updated (scripts/run_example.sh's second install)
if [ "${INSTALL_DEPS_UPDATED:-0}" != 1 ]; then $SUDO apt-get update -qq; fi
# --force-unsafe-io: dpkg skips its fsync before renaming each unpacked file (as Debian's Docker images
# do). libboost1.74-dev alone is 15 500 header files: unpacking it took 77 s instead of 32 s with it on
# the loaded 2-core test machine (issue 33). A crash during the install can leave files empty; rerun
# this script then (or `apt-get install --reinstall` the package named).
$SUDO apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${missing[@]}"
