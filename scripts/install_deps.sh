#!/usr/bin/env bash
# Installs the Debian packages frictherm needs (Debian 12). Skips apt entirely when all are present.
set -euo pipefail
packages=(build-essential cmake pkg-config libeigen3-dev libsundials-dev libhdf5-dev libgtest-dev
          nlohmann-json3-dev libboost-dev libmuparser-dev libpng-dev libtiff-dev libopenmpi-dev openmpi-bin petsc-dev python3 python3-numpy python3-matplotlib python3-h5py
          python3-paraview python3-pandas python3-pytest python3-xarray python3-venv
          python3-dev pybind11-dev
          clang libclang-rt-dev libomp-dev)  # clang, its sanitizer/libFuzzer runtimes and OpenMP: scripts/run_checks.sh
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -eq 0 ]; then
  echo "install_deps: all Debian packages present"
  exit 0
fi
echo "install_deps: installing ${missing[*]}"
SUDO=""
if [ "$(id -u)" -ne 0 ]; then SUDO="sudo"; fi
export DEBIAN_FRONTEND=noninteractive
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}"
