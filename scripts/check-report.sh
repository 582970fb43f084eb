#!/usr/bin/env bash
# Opens DIR/report.html in headless Chromium (Debian's `chromium`), checks
# that every image on the page decoded, and takes a full-page screenshot.
#   bash scripts/check-report.sh DIR [SCREENSHOT.png]
# Exit codes: 0 all images loaded, 1 an image did not load or the page did
# not render, 77 Chromium not installed (apt-get install -y chromium).
set -euo pipefail
dir=${1:?usage: check-report.sh DIR [SCREENSHOT.png]}
shot=${2:-$dir/report-screenshot.png}
report=$(realpath "$dir/report.html")
browser=$(command -v chromium || command -v chromium-browser || command -v google-chrome || true)
if [[ -z "$browser" ]]; then
  echo "check-report: chromium not found (apt-get install -y chromium); skipped"
  exit 77
fi
profile=$(mktemp -d)
trap 'rm -rf "$profile"' EXIT
flags=(--headless --no-sandbox --disable-gpu --disable-background-networking --disable-component-update
       --disable-sync --no-first-run --user-data-dir="$profile")
# The page sets data-images-total / data-images-loaded on <html> once loaded
# (naturalWidth > 0 for every <img>); the virtual time budget lets it run.
dom=$("$browser" "${flags[@]}" --virtual-time-budget=15000 --dump-dom "file://$report" 2>/dev/null || true)
total=$(grep -o 'data-images-total="[0-9]*"' <<<"$dom" | grep -o '[0-9]\+' || true)
loaded=$(grep -o 'data-images-loaded="[0-9]*"' <<<"$dom" | grep -o '[0-9]\+' || true)
"$browser" "${flags[@]}" --hide-scrollbars --window-size=1400,3000 --virtual-time-budget=15000 \
  --screenshot="$(realpath -m "$shot")" "file://$report" >/dev/null 2>&1 || true
if [[ -z "$total" || -z "$loaded" ]]; then
  echo "check-report: the page did not report its images (did it render?)"
  exit 1
fi
if [[ ! -s "$shot" ]]; then
  echo "check-report: no screenshot written to $shot"
  exit 1
fi
if [[ "$total" -eq 0 || "$loaded" -ne "$total" ]]; then
  echo "check-report: $loaded of $total images loaded in $report"
  exit 1
fi
echo "check-report: $loaded of $total images loaded in $report; screenshot $shot"
