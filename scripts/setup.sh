#!/usr/bin/env bash
# hysteron set-up on Debian 12: install the Debian packages it needs (only the missing
# ones), configure a Release build in build/ (or $HYSTERON_BUILD_DIR) and build it.
# Idempotent: a second run only rebuilds what changed.
set -euo pipefail
cd "$(dirname "${BASH_SOURCE[0]}")/.."

packages=(
  libdeal.ii-dev      # deal.II 9.4 with Trilinos, p4est, SUNDIALS, CGAL, muParser, MPI
  cmake ninja-build g++ make
  openmpi-bin libopenmpi-dev
  libgtest-dev        # unit tests
  numdiff             # numerical comparison of outputs
  python3             # the scene-test runner and plot scripts
  python3-matplotlib  # figures in doc/
  gnuplot-nox
  libcgal-dev         # Voronoi cells (RBSN)
  zlib1g-dev          # CRC-32 of checkpoint files and inputs
  libsuitesparse-dev  # UMFPACK, called directly for the RBSN's kept symbolic analysis
  libsundials-dev     # IDAS and serial vectors (>= 6), called directly by the RBSN's variable-order
                      # analysis (libdeal.ii-dev depends on it too)
  libopenblas0-serial # an optimised BLAS/LAPACK behind libblas.so.3 (the sparse direct
                      # solvers' dense kernels; Debian's default is the reference BLAS)
  calculix-ccx        # benchmarks/calculix_cantilever_3d.py: the 3D FEM against CalculiX
)

missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "setup: installing ${missing[*]}"
  sudo=""
  if [ "$(id -u)" -ne 0 ]; then sudo="sudo"; fi
  $sudo apt-get update -qq
  DEBIAN_FRONTEND=noninteractive $sudo apt-get install -y -qq --no-install-recommends "${missing[@]}"
fi

build_dir=${HYSTERON_BUILD_DIR:-build}
if [ ! -f "$build_dir/build.ninja" ]; then
  cmake -S . -B "$build_dir" -G Ninja -DCMAKE_BUILD_TYPE=Release -DPython3_EXECUTABLE=/usr/bin/python3
fi
cmake --build "$build_dir" -j "$(nproc)"
