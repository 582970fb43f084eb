#!/usr/bin/env bash
# Per-step cost of the paper's wheel setting (pesterev, lambda = 1500,
# fixed-step Adams PECE, h = 1e-5) against the minimal-coordinate ODE with
# the same integrator and step (issue 8), on a shorter horizon with identical
# settings (default t_end = 20: 2e6 steps; the paper's t_end = 200 is 2e7).
# Alternates the two runs REPEATS times; prints the median wall time per step
# of each (the harness's wall_seconds, observation excluded) and the ratio.
#   usage: scripts/paper-step-cost.sh [OUT]   (default results/paper-step-cost)
#   env: T_END (20), REPEATS (5), OBSERVE_EVERY (1, the harness default)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/paper-step-cost}
CSTAB=${CSTAB:-build/release/cli/cstab}
T_END=${T_END:-20}
REPEATS=${REPEATS:-5}
OBSERVE_EVERY=${OBSERVE_EVERY:-1}
mkdir -p "$OUT"
: >"$OUT/runs.csv"
for ((r = 1; r <= REPEATS; r++)); do
  for method in pesterev minimal; do
    extra=(); [[ $method == pesterev ]] && extra=(--param lambda=1500)
    "$CSTAB" run --problem wheel --method "$method" "${extra[@]}" --integrator adams --step 1e-5 \
      --t-end "$T_END" --no-series --observe-every "$OBSERVE_EVERY" --out "$OUT/$method" >/dev/null
    awk -F, -v m="$method" 'NR==1{for(i=1;i<=NF;i++)c[$i]=i;next}
      {print m "," $c["steps"] "," $c["rhs_evals"] "," $c["wall_seconds"] "," $c["wall_seconds"] / $c["steps"]}' \
      "$OUT/$method/summary.csv" >>"$OUT/runs.csv"
  done
done
sort -t, -k1,1 -k5,5g "$OUT/runs.csv" | awk -F, '
  { n[$1]++; v[$1, n[$1]] = $5; steps[$1] = $2 }
  END {
    for (m in n) { k = n[m]; med[m] = k % 2 ? v[m, (k + 1) / 2] : (v[m, k / 2] + v[m, k / 2 + 1]) / 2
      printf "%-9s steps %d  median wall per step %.1f ns  (%d runs)\n", m, steps[m], 1e9 * med[m], k }
    printf "ratio pesterev / minimal per step: %.2f\n", med["pesterev"] / med["minimal"]
  }' | tee "$OUT/ratio.txt"
