#!/usr/bin/env bash
# Measures what the build costs on this machine, from a fresh clone of HEAD:
#   1. a clean Release build of everything, tests included (wall time, and
#      per translation unit: seconds and peak compiler memory);
#   2. the rebuild after touching one method header (methods/baumgarte.hpp);
#   3. the rebuild after touching one problem's model (problems/wheel/wheel.hpp);
#   4. the rebuild after adding a method (a renamed copy of baumgarte) and
#      the CPU seconds of the units it adds (its marginal clean-build cost);
#   5. the same for a problem (a renamed copy of slider-crank).
#   bash scripts/build-cost.sh [JOBS] [UNITS_LOG]   (JOBS default: nproc)
# UNITS_LOG, if given, receives every compile of the run, one line each:
# "wall_seconds peak_kB source", in build order (the clean build first).
# Prints one line per figure. ccache is bypassed. Takes 5-10 minutes on 2 cores.
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
jobs=${1:-$(nproc)}
keep=${2:-}
[[ -z $keep ]] || keep=$(realpath -m "$keep")
work=$(mktemp -d)
trap '[[ -z $keep || ! -f $work/tu.log ]] || cp "$work/tu.log" "$keep"; rm -rf "$work"' EXIT
git clone -q "$root" "$work/src"
cd "$work/src"
export CCACHE_DISABLE=1
log=$work/tu.log
export CSTAB_TU_LOG=$log
cmake --preset release -DCMAKE_CXX_COMPILER_LAUNCHER="$PWD/scripts/tu-cost.sh" >/dev/null

build() {  # prints wall seconds of a build of everything
  local t0 t1
  t0=$(date +%s.%N)
  cmake --build build/release -j"$jobs" >"$work/build.out" 2>&1 || { tail -30 "$work/build.out" >&2; exit 1; }
  t1=$(date +%s.%N)
  echo "$t0 $t1" | awk '{printf "%.0f", $2 - $1}'
}
cpu_since() {  # CPU seconds and count of the units compiled since line $1 of the log
  awk -v from="$1" 'NR > from {s += $1; n++} END {printf "%.0f s CPU in %d units", s, n}' "$log"
}
units_since() {  # the units compiled since line $1 of the log, slowest first
  awk -v from="$1" 'NR > from' "$log" | sort -rn | awk '{sub(".*/(build/release|src)/", "", $3); printf "    %5.1f s %6.0f MB  %s\n", $1, $2 / 1024, $3}'
}

: >"$log"
clean=$(build)
echo "clean build (everything, tests included, -j$jobs): ${clean} s"
echo "  compiler warnings: $(grep -c 'warning:' "$work/build.out" || true)"
grep -A3 'warning:' "$work/build.out" | head -20 | sed 's/^/    /' || true
awk '{s += $1; if ($2 > m) {m = $2; f = $3}} END {printf "  %d units, %.0f s CPU; peak compiler memory %.0f MB (%s)\n", NR, s, m / 1024, f}' "$log"
echo "  slowest units:"
sort -rn "$log" | head -5 | awk '{printf "    %5.1f s %6.0f MB  %s\n", $1, $2 / 1024, $3}'

mark=$(wc -l <"$log")
touch methods/baumgarte.hpp
echo "touch methods/baumgarte.hpp: $(build) s ($(cpu_since "$mark"))"

mark=$(wc -l <"$log")
touch problems/wheel/wheel.hpp
echo "touch problems/wheel/wheel.hpp: $(build) s ($(cpu_since "$mark"))"

mark=$(wc -l <"$log")
sed -e 's/BaumgarteFormulation/ScratchFormulation/g' -e 's/BaumgarteMethod/ScratchMethod/g' \
    -e 's/"baumgarte"/"scratch"/' methods/baumgarte.hpp >methods/scratch.hpp
echo 'cstab_method(scratch ScratchMethod methods/scratch.hpp)' >>methods/CMakeLists.txt
cmake build/release >/dev/null
echo "add a method (copy of baumgarte): $(build) s ($(cpu_since "$mark"))"
units_since "$mark"

mark=$(wc -l <"$log")
mkdir problems/scratch_crank
for f in problems/slider_crank/*; do
  sed -e 's/SliderCrank/ScratchCrank/g' -e 's/slider_crank/scratch_crank/g' -e 's/slider-crank/scratch-crank/g' \
      "$f" >"problems/scratch_crank/$(basename "$f" | sed 's/slider_crank/scratch_crank/')"
done
sed -i 's/foreach(problem wheel/foreach(problem scratch_crank wheel/' problems/CMakeLists.txt
cmake build/release >/dev/null
echo "add a problem (copy of slider-crank): $(build) s ($(cpu_since "$mark"))"
units_since "$mark"
build/release/cli/cstab list | grep -c 'scratch' | awk '{print "  (cstab list names scratch entries: " $1 ")"}'
