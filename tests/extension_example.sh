#!/usr/bin/env bash
# ctest: install hysteron, build the out-of-tree plugin example doc/examples/<example> against
# the installed package, and run its scene <prm> with the installed executable; the scene's
# CHECK lines must hold. The scene loads the plugin as ./build/lib<example>.so.
# Usage: extension_example.sh <source dir> <build dir> <work dir> <example> <prm>
set -euo pipefail
src=$1 build=$2 work=$3 example=$4 prm=$5
rm -rf "$work" && mkdir -p "$work"
cmake --install "$build" --prefix "$work/install" > "$work/install.log"
cp -r "$src/doc/examples/$example" "$work/example"
cd "$work/example"
cmake -S . -B build -G Ninja -DCMAKE_BUILD_TYPE=Release \
  -Dhysteron_DIR="$work/install/lib/cmake/hysteron" > configure.log
cmake --build build > build.log 2>&1 || { cat build.log; exit 1; }
if grep -q 'warning:' build.log; then cat build.log; echo "the example builds with warnings"; exit 1; fi
# The scene names the plugin relative to the example directory; the runner works elsewhere.
sed "s|./build/lib$example.so|$work/example/build/lib$example.so|" "$prm" > "${prm%.prm}_test.prm"
python3 "$src/tests/run_prm_test.py" --hysteron "$work/install/bin/hysteron" \
  --workdir "$work/run" "${prm%.prm}_test.prm"
