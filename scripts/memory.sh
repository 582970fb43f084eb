#!/usr/bin/env bash
# Peak memory of a run against its horizon (issue 8): the same run with
# t_end = 200 and 2000 (series written, one row every 0.1 s, so the longer
# run writes 10x the rows), peak resident set size from /usr/bin/time -v.
# Prints one row per run and the ratio; results in OUT.
#   usage: scripts/memory.sh [OUT]   (default results/memory)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/memory}
CSTAB=${CSTAB:-build/release/cli/cstab}
mkdir -p "$OUT"
printf "%-8s %-10s %-8s %10s %12s %12s\n" problem method t_end rows peak_kB wall_s
while read -r problem method args; do
  for t_end in 200 2000; do
    dir="$OUT/$problem-$method-$t_end"
    /usr/bin/time -v -o "$dir.time" "$CSTAB" run --problem "$problem" --method "$method" $args \
      --t-end "$t_end" --sample-every 0.1 --out "$dir" >/dev/null
    kb=$(awk -F': ' '/Maximum resident set size/ {print $2}' "$dir.time")
    rows=$(($(wc -l <"$dir/series.csv") - 1))
    wall=$(awk -F, 'NR==1{for(i=1;i<=NF;i++)c[$i]=i;next}{print $c["wall_seconds"]}' "$dir/summary.csv")
    printf "%-8s %-10s %-8s %10s %12s %12.3g\n" "$problem" "$method" "$t_end" "$rows" "$kb" "$wall"
    echo "$problem,$method,$t_end,$rows,$kb,$wall" >>"$OUT/memory.csv.tmp"
  done
done <<'RUNS'
wheel pesterev --param lambda=20 --integrator rk8pd --rtol 1e-10 --atol 1e-10
ball projection --integrator rk8pd --rtol 1e-9 --atol 1e-9
wheel ida-ggl --integrator ida --rtol 1e-8 --atol 1e-8
RUNS
{ echo "problem,method,t_end,series_rows,peak_rss_kb,wall_seconds"; cat "$OUT/memory.csv.tmp"; } >"$OUT/memory.csv"
rm -f "$OUT/memory.csv.tmp"
awk -F, 'NR > 1 { k = $1 " " $2; if ($3 == 200) a[k] = $5; else b[k] = $5 }
  END { for (k in a) printf "%s: peak RSS t_end=2000 / t_end=200 = %.3f (%.1f MB at 2000)\n", k, b[k] / a[k], b[k] / 1024 }' "$OUT/memory.csv"
