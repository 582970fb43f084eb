#!/usr/bin/env bash
# The README's main command: installs what is missing, builds, runs the
# default benchmark matrix (docs/matrix.md) and writes the report.
#   bash scripts/main.sh [OUT_DIR] [cstab matrix options...]
# Rerunning it reruns only what changed.
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh
bash scripts/build.sh
out=${1:-results/default}
build/release/cli/cstab matrix --out "$out" "${@:2}"
echo
echo "Report: $(realpath "$out")/report.html"
echo "Tables: $out/summary.csv, $out/work_precision.csv, $out/fastest.csv; pictures: $out/plots/"
