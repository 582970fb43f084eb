#!/usr/bin/env bash
# The stress tests of README "Stress" (issue 7): runs matrices/stress.toml
# (inconsistent starts over delta = 1e-8 ... 1e-1, the near-singular wheel,
# long horizons, stiffness sweeps) into OUT and renders the report, whose
# "Stress" section holds the tables and pictures; OUT/stress_*.csv are the
# tidy tables. Cases are cached: a rerun redoes only what changed.
#   usage: scripts/stress.sh [OUT] [cstab matrix options, e.g. --filter perturb --jobs 4]
#   (about 20 minutes on 2 loaded cores; the long and stiff sweeps dominate)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/stress}
CSTAB=${CSTAB:-build/release/cli/cstab}
[ -x "$CSTAB" ] || bash scripts/build.sh
"$CSTAB" matrix matrices/stress.toml --out "$OUT" "${@:2}"
echo
echo "Report: $(realpath "$OUT")/report.html (section Stress)"
echo "Tables: $OUT/stress_perturb.csv, $OUT/stress_long.csv, $OUT/stress_stiff.csv; pictures: $OUT/plots/stress_*"
