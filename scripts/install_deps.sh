#!/usr/bin/env bash
# Installs the Debian packages frictherm needs (Debian 12). Skips apt entirely when all are present.
#   scripts/install_deps.sh [program|all|build|plot]   (default all)
#   scripts/install_deps.sh --check PROFILE             exit status 0 when all of PROFILE is present
# program: what README command 1 needs to build the `frictherm` program and draw a run: `build` and `plot`.
# build:   what compiling and running the program needs (compiler, CMake, Ninja, the libraries the
#          program links). Debian 12's libsundials-dev depends on petsc-dev, hypre and Open MPI (for its parallel
#          vectors, which the program does not link): 361 packages and 315 MB to download for `program`
#          instead of 224 and 209 MB. So, unless libsundials-dev is installed already, `build` and
#          `program` install libsuitesparse-dev (KLU, which SUNDIALS' KLU solver links) and unpack
#          Debian's own SUNDIALS packages (headers, CMake package files, the libraries: each needs only
#          libc, libm and KLU) into .deps/sundials with dpkg-deb, where scripts/build.sh finds them.
#          `all` installs libsundials-dev itself (and with it PETSc and Open MPI for the MPI parts).
# plot:    numpy, h5py and matplotlib for examples/plot_run.py.
# all:     also the test suite (GoogleTest and GoogleMock: Debian 12 ships the GTest::gmock target the
#          tests link in libgmock-dev, not in libgtest-dev; pytest, pandas, xarray, venv, pybind11 for the bindings),
#          python3-wheel: `pip install --no-build-isolation ./python` in a venv needs setuptools' bdist_wheel,
#          Open MPI and PETSc for the distributed parts, ParaView's pvpython for the XDMF checks and
#          clang with its sanitizer/libFuzzer runtimes for scripts/run_checks.sh.
set -euo pipefail
check=no
if [ "${1:-}" = --check ]; then check=yes; shift; fi
profile=${1:-all}
build=(build-essential cmake ninja-build pkg-config libeigen3-dev libsundials-dev libhdf5-dev nlohmann-json3-dev
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
installed() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }
# SUNDIALS unpacked (see `build` above): the folder scripts/build.sh looks in, and whether this run
# unpacks into it instead of installing libsundials-dev.
deps_dir=$(cd "$(dirname "$0")/.." && pwd)/.deps
unpack_sundials=no
if [ "$profile" = build ] || [ "$profile" = program ]; then
  installed libsundials-dev || unpack_sundials=yes
fi
missing=()
for p in "${packages[@]}"; do
  if [ $unpack_sundials = yes ] && [ "$p" = libsundials-dev ]; then
    installed libsuitesparse-dev || missing+=(libsuitesparse-dev)
    continue
  fi
  installed "$p" || missing+=("$p")
done
sundials_unpacked() { compgen -G "$deps_dir/sundials/usr/lib/*/cmake/sundials/SUNDIALSConfig.cmake" >/dev/null; }
if [ $check = yes ]; then
  [ ${#missing[@]} -eq 0 ] && { [ $unpack_sundials = no ] || sundials_unpacked; }; exit
fi
# Debian's SUNDIALS packages, downloaded (apt-get download: no dependencies, no dpkg database change)
# and unpacked into .deps/sundials: libsundials-dev and the libsundials-* libraries it depends on.
unpack_sundials_packages() {
  local debs=$deps_dir/debs names
  mkdir -p "$debs"
  apt-cache show libsundials-dev >/dev/null 2>&1 || $SUDO apt-get update -qq
  names=(libsundials-dev $(apt-cache depends libsundials-dev | awk '$1 == "Depends:" && $2 ~ /^libsundials-/ {print $2}'))
  (cd "$debs" && rm -f ./*.deb && apt-get download -qq "${names[@]}" 2>&1 | grep -v "unsandboxed as root" || true)
  rm -rf "$deps_dir/sundials.tmp" && mkdir -p "$deps_dir/sundials.tmp"
  for d in "$debs"/*.deb; do dpkg-deb -x "$d" "$deps_dir/sundials.tmp"; done
  rm -rf "$deps_dir/sundials" && mv "$deps_dir/sundials.tmp" "$deps_dir/sundials"
  sundials_unpacked || { echo "install_deps: unpacking SUNDIALS into $deps_dir/sundials failed" >&2; exit 1; }
  echo "install_deps: SUNDIALS ($(ls "$debs" | wc -l) Debian packages) unpacked into $deps_dir/sundials"
}
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
if [ ${#missing[@]} -eq 0 ]; then
  if [ $unpack_sundials = yes ] && ! sundials_unpacked; then unpack_sundials_packages; fi
  echo "install_deps: all Debian packages present ($profile)"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
export DEBIAN_FRONTEND=noninteractive
# INSTALL_DEPS_UPDATED=1: the package lists were just updated (scripts/run_example.sh's second install)
if [ "${INSTALL_DEPS_UPDATED:-0}" != 1 ]; then $SUDO apt-get update -qq; fi
# --force-unsafe-io: dpkg skips its fsync before renaming each unpacked file (as Debian's Docker images
# do). libboost1.74-dev alone is 15 500 header files: unpacking it took 77 s instead of 32 s with it on
# the loaded 2-core test machine (issue 33). A crash during the install can leave files empty; rerun
# this script then (or `apt-get install --reinstall` the package named).
$SUDO apt-get install -y -qq --no-install-recommends -o Dpkg::Options::=--force-unsafe-io "${missing[@]}"
if [ $unpack_sundials = yes ]; then unpack_sundials_packages; fi
