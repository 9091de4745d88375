#!/usr/bin/env bash
# ctest: install hysteron into <work dir> and compile every installed header on its own
# (tests/installed_headers/CMakeLists.txt), warnings-free.
# Usage: installed_headers.sh <source dir> <build dir> <work dir>
set -euo pipefail
src=$1 build=$2 work=$3
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/install" > "$work/install.log"
cmake -S "$src/tests/installed_headers" -B "$work/build" -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -Dhysteron_DIR="$work/install/lib/cmake/hysteron" > "$work/configure.log"
grep 'installed headers' "$work/configure.log"
cmake --build "$work/build" -j 2 > "$work/build.log" 2>&1 || { cat "$work/build.log"; exit 1; }
if grep -q 'warning:' "$work/build.log"; then cat "$work/build.log"; echo "a header compiles with warnings"; exit 1; fi
echo "every installed header compiles on its own"
