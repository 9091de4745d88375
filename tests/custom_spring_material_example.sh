#!/usr/bin/env bash
# ctest: the user material doc/examples/custom_spring_material (bilinear springs with kinematic
# hardening) built against the installed package, driving the springs of an RBSN scene (see
# extension_example.sh).
# Usage: custom_spring_material_example.sh <source dir> <build dir> <work dir>
exec "$(dirname "$0")/extension_example.sh" "$1" "$2" "$3" custom_spring_material bilinear.prm
