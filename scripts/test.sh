#!/usr/bin/env bash
# The README's test command: install what is missing, build, run every test.
# Extra arguments go to ctest (e.g. -L unit, -LE slow).
set -euo pipefail
cd "$(dirname "$0")/.."
bash scripts/install-deps.sh chromium  # chromium: the report is checked in a real browser
bash scripts/build.sh
cd build/release
ctest --output-on-failure -j"$(nproc)" "$@"
