#!/usr/bin/env bash
# Installs immerse's build and run dependencies from Debian 12 packages (idempotent).
set -euo pipefail
pkgs=(cmake g++ make pkg-config lld  # lld: the presets link with it (several times faster than ld)
      libfftw3-dev libfftw3-mpi-dev libhdf5-dev libtomlplusplus-dev libcli11-dev
      petsc-dev openmpi-bin libopenmpi-dev  # MPI: the distributed solver and its tests (mpiexec)
      liblapack-dev  # the dense LU of the walls' capacitance matrix (fluid/GhostCellWalls)
      libgtest-dev libgmock-dev libbenchmark-dev
      python3 python3-matplotlib python3-numpy python3-h5py python3-meshio python3-dev pybind11-dev
      mkdocs mkdocs-material  # scripts/build-docs.sh (the documentation site, test docs.site)
      clang libclang-rt-14-dev libomp-14-dev)  # the last three: scripts/fuzz.sh (libFuzzer, cmake --preset fuzz)
missing=()
for p in "${pkgs[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if [ ${#missing[@]} -gt 0 ]; then
  echo "install-deps: installing ${missing[*]}"
  SUDO=""; [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  export DEBIAN_FRONTEND=noninteractive
  $SUDO apt-get update -qq
  $SUDO apt-get install -y -qq --no-install-recommends "${missing[@]}" >/dev/null
fi
