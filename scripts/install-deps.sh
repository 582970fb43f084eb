#!/usr/bin/env bash
# Installs the Debian 12 packages cstab needs (plus any given as arguments), only those missing.
# clang-14 compiles cstab (the presets choose it: 0.65 of GCC 12's compile time, docs/build.md);
# libclang-rt-14-dev holds its sanitizer runtimes (the sanitize preset), libomp-14-dev the OpenMP
# that SUNDIALS' CMake package asks the compiler for (find_dependency(OpenMP): with clang it is
# LLVM's libomp, with GCC libgomp, which g++ brings); g++ stays for libstdc++
# and the release-gcc preset; time (/usr/bin/time) and python3 run the build and speed measurement
# scripts (scripts/build-cost.sh, build-floor.py, method-cost.py).
set -euo pipefail
packages=(g++ cmake make libeigen3-dev libsundials-dev libgsl-dev libbenchmark-dev libfccp-dev libtomlplusplus-dev
          gnuplot-nox googletest libgtest-dev libcli11-dev zlib1g-dev parallel lld
          libsimbody-dev libmujoco-dev clang-14 libclang-rt-14-dev libomp-14-dev time python3 "$@")
missing=()
for p in "${packages[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]})); then
  echo "install-deps: installing ${missing[*]}"
  sudo_cmd=()
  [[ $(id -u) -ne 0 ]] && sudo_cmd=(sudo)
  "${sudo_cmd[@]}" apt-get update -qq
  DEBIAN_FRONTEND=noninteractive "${sudo_cmd[@]}" apt-get install -y -qq "${missing[@]}" >/dev/null
fi
