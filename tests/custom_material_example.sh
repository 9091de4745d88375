#!/usr/bin/env bash
# ctest: the user material doc/examples/custom_material built against the installed package
# and its scene run (see extension_example.sh).
# Usage: custom_material_example.sh <source dir> <build dir> <work dir>
exec "$(dirname "$0")/extension_example.sh" "$1" "$2" "$3" custom_material damage.prm
