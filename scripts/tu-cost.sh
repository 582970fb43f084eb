#!/usr/bin/env bash
# Compiler launcher (CMAKE_CXX_COMPILER_LAUNCHER) that appends
# "seconds peak_kB source" for every compile to $CSTAB_TU_LOG.
log=${CSTAB_TU_LOG:-/dev/null}
src=unknown
for a in "$@"; do [[ $a == *.cpp ]] && src=$a; done
exec /usr/bin/time -f "%e %M $src" -a -o "$log" "$@"
