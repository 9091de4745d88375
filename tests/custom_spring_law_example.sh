#!/usr/bin/env bash
# ctest: the user RBSN spring law doc/examples/custom_spring_law built against the installed
# package and its scene run (see extension_example.sh).
# Usage: custom_spring_law_example.sh <source dir> <build dir> <work dir>
exec "$(dirname "$0")/extension_example.sh" "$1" "$2" "$3" custom_spring_law no_tension.prm
