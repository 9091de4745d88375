#!/usr/bin/env bash
# Regenerates the reference histories *.csv beside this script with OpenSees itself:
# compiles OpenSees' BoucWenMaterial, BoucWenOriginal and BWBN with the few support classes
# they need (OpenSees' own files, taken from OPENSEES and compiled in BUILD, outside the
# repository) and this folder's driver.cpp and stubs.cpp, then runs each case below.
#
# Usage: make_reference.sh OPENSEES [BUILD]
#   OPENSEES  an OpenSees source tree (holding SRC/) or git directory (its HEAD is used)
#   BUILD     scratch directory, default /tmp/opensees-build
set -euo pipefail

here=$(cd "$(dirname "$0")" && pwd)
opensees=$(cd "$1" && pwd)
build=${2:-/tmp/opensees-build}
cxx=${CXX:-g++}

include_dirs="actor/actor actor/channel api domain/component element handler material
              material/uniaxial matrix recorder/response tagged tagged/storage"
sources="material/uniaxial/BoucWenMaterial material/uniaxial/BoucWenOriginal material/uniaxial/BWBN
         material/uniaxial/UniaxialMaterial material/Material tagged/TaggedObject
         tagged/storage/MapOfTaggedObjects tagged/storage/MapOfTaggedObjectsIter
         actor/actor/MovableObject matrix/Vector matrix/Matrix matrix/ID element/Information
         handler/OPS_Stream handler/StandardStream recorder/response/MaterialResponse
         recorder/response/Response"

mkdir -p "$build/obj"
if [ -d "$opensees/SRC" ]; then
  root=$opensees/SRC
  commit=$(git -C "$opensees" rev-parse HEAD 2>/dev/null || echo "unknown (not a git work tree)")
else
  # A git directory without work tree: export the files needed, and only those.
  commit=$(git -C "$opensees" rev-parse HEAD)
  rm -rf "$build/src" && mkdir -p "$build/src"
  paths="SRC/OPS_Globals.h SRC/classTags.h"
  for d in $include_dirs; do paths="$paths SRC/$d"; done
  git -C "$opensees" archive HEAD $paths | tar -x -C "$build/src"
  root=$build/src/SRC
fi

flags="-std=c++17 -O2 -ffp-contract=off -D_LINUX -isystem $root"
for d in $include_dirs; do flags="$flags -isystem $root/$d"; done
objects=""
for s in $sources; do
  o=$build/obj/$(basename "$s").o
  $cxx $flags -w -c "$root/$s.cpp" -o "$o" # OpenSees' files, compiled as they are
  objects="$objects $o"
done
for s in driver stubs; do
  $cxx $flags -Wall -Wextra -c "$here/$s.cpp" -o "$build/obj/$s.o"
  objects="$objects $build/obj/$s.o"
done
# Matrix.cpp calls LAPACK (never on the paths the driver takes).
$cxx $objects -o "$build/driver" -llapack

# case MATERIAL AMPLITUDE DRIFT END STEPS EVERY numbers...: the strain path
# AMPLITUDE t/END sin(2 pi t) + DRIFT t/END in STEPS steps, every EVERY-th step written.
run_case() {
  local name=$1
  shift
  {
    echo "# OpenSees $commit: driver $*"
    "$build/driver" "$@"
  } >"$here/$name.csv"
  echo "wrote $here/$name.csv"
}

#                         material         amplitude drift end steps every
# BoucWen: alpha ko n gamma beta Ao deltaA deltaNu deltaEta tolerance maxNumIter
run_case boucwen_degrading BoucWen         3e-3 1e-3 4 4000 10 0.05 200e9 2 3e5 7e5 1 1e-7 2e-6 1e-6 1e-8 20
run_case boucwen           BoucWen         5e-3 1e-3 4 4000 10 0.1 30e9 1 400 600 1 0 0 0 1e-8 20
# BoucWenOriginal: E fy alphaL alphaNL mu eta beta gamma tol maxIter
run_case boucwen_original  BoucWenOriginal 3e-3 1e-3 4 4000 10 200e9 200e6 0.05 20 2 3 0.6 0.4 1e-8 25
# BWBN: alpha ko n gamma beta Ao q zetas p Shi deltaShi lamda tolerance maxNumIter
run_case bwbn              BWBN            3e-3 1e-3 4 4000 10 0.05 200e9 2 3e5 7e5 1 0.2 0.85 1e-6 3e-4 1e-11 0.5 1e-8 20
run_case bwbn_ao           BWBN            4e-3 -1e-3 4 4000 10 0.1 100e9 1.5 2e4 5e4 1.5 0.1 0.6 2e-6 4e-4 2e-11 0.3 1e-8 20
