#!/usr/bin/env bash
# Two selections of a matrix's cases set side by side, from one run: per
# problem and level of error against the reference, the fastest case of
# each selection that reaches the level (median wall time), its largest
# constraint residual, and the ratio of the wall times (B / A: above 1, A is
# faster). A selection is METHOD/INTEGRATOR, either side `*` for any
# (`post-stabilization/*`, `*/ark-erk-fehlberg8`); `*` methods leave out the
# constraint-free baselines none and minimal. Markdown on stdout.
#   usage: bash scripts/ratio-table.sh RESULTS_DIR A B [LEVELS]
#   e.g.   bash scripts/ratio-table.sh results/default 'post-stabilization/*' 'projection/*' '1e-6 1e-10'
set -euo pipefail
dir=${1:?usage: scripts/ratio-table.sh RESULTS_DIR A B [LEVELS]}
a=${2:?usage: scripts/ratio-table.sh RESULTS_DIR A B [LEVELS]}
b=${3:?usage: scripts/ratio-table.sh RESULTS_DIR A B [LEVELS]}
levels=${4:-1e-6 1e-10}
wp=$dir/work_precision.csv
[ -f "$wp" ] || { echo "ratio-table: no $wp (not a matrix results folder with a report)" >&2; exit 2; }
for s in "$a" "$b"; do
  [[ $s == */* && $s != */*/* ]] || { echo "ratio-table: selection '$s': expected METHOD/INTEGRATOR ('*' for any)" >&2; exit 2; }
done
for l in $levels; do
  [[ $l =~ ^[0-9.]+([eE][-+]?[0-9]+)?$ ]] && awk -v l="$l" 'BEGIN { exit !(l + 0 > 0) }' ||
    { echo "ratio-table: level '$l': expected a number > 0" >&2; exit 2; }
done
awk -F, -v A="$a" -v B="$b" -v LEVELS="$levels" '
function selected(sel, m, integ,   parts) {
  split(sel, parts, "/")
  if (parts[1] == "*") { if (m == "none" || m == "minimal") return 0 } else if (parts[1] != m) return 0
  return parts[2] == "*" || parts[2] == integ
}
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; nl = split(LEVELS, lv, " "); next }
$col["status"] != "ok" || $col["ref_error"] == "" || $col["integrator"] == "external" { next }
{
  p = $col["problem"]; m = $col["method"]; g = $col["integrator"]; w = $col["wall_median_s"] + 0
  e = $col["ref_error"] + 0
  if (!(p in seen)) { seen[p] = 1; plist[++np] = p }
  for (s = 1; s <= 2; s++) {
    if (!selected(s == 1 ? A : B, m, g)) continue
    for (k = 1; k <= nl; k++) {
      if (e > lv[k] + 0) continue
      key = p SUBSEP s SUBSEP k
      if (!(key in best) || w < best[key]) {
        best[key] = w
        who[key] = $col["curve"] " " $col["setting"]
        res[key] = $col["max_residual"]
      }
    }
  }
}
END {
  printf "| problem | error <= | A: %s | wall s | max residual | B: %s | wall s | max residual | B / A |\n", A, B
  print "|---|---|---|---|---|---|---|---|---|"
  for (i = 1; i <= np; i++) for (k = 1; k <= nl; k++) {
    p = plist[i]; x = p SUBSEP 1 SUBSEP k; y = p SUBSEP 2 SUBSEP k
    if (!(x in best) && !(y in best)) continue
    xs = (x in best) ? sprintf("%s | %.3g | %.2g", who[x], best[x], res[x]) : "not reached | | "
    ys = (y in best) ? sprintf("%s | %.3g | %.2g", who[y], best[y], res[y]) : "not reached | | "
    ratio = (x in best && y in best) ? sprintf("%.2f", best[y] / best[x]) : "-"
    print "| " p " | " lv[k] " | " xs " | " ys " | " ratio " |"
  }
}' "$wp"
