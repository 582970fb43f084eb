#!/usr/bin/env bash
# Reproduces the wheel-with-pendulum experiment of Pesterev, Matrosov and
# Morozov (pesterev, lambda = 1500, fixed-step Adams, h = 1e-5, t in [0, 200])
# and searches for the cheapest setting that keeps max residual <= 1e-12 and
# max |dE| <= 1e-10 over [0, 200]. Prints one table; results in $OUT.
#   usage: scripts/wheel-paper.sh [OUT]   (default results/wheel-paper)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/wheel-paper}
CSTAB=${CSTAB:-build/release/cli/cstab}
mkdir -p "$OUT"
run() {  # name, args...
  local name=$1; shift
  "$CSTAB" run --problem wheel --t-end 200 --sample-every 0.01 --out "$OUT/$name" "$@" >/dev/null
}
run paper --method pesterev --param lambda=1500 --integrator adams --step 1e-5
for h in 1e-4 5e-5 2e-5; do
  for lam in 100 1500; do run "adams-h$h-l$lam" --method pesterev --param lambda=$lam --integrator adams --step $h; done
done
for h in 1e-3 5e-4 2e-4; do
  for lam in 100 1500; do run "rk4-h$h-l$lam" --method pesterev --param lambda=$lam --integrator rk4 --step $h; done
done
for tol in 1e-10 1e-12 1e-13; do
  for lam in 20 100 1500; do run "rk8pd-t$tol-l$lam" --method pesterev --param lambda=$lam --integrator rk8pd --rtol $tol --atol $tol; done
done
printf "%-24s %-8s %-10s %-10s %-10s %-10s %s\n" case integr. steps max_resid max_dE wall_s meets
for d in "$OUT"/*/; do
  name=$(basename "$d")
  awk -F, -v name="$name" 'NR==1{for(i=1;i<=NF;i++) c[$i]=i; next}
    { meets = ($c["status"]=="ok" && $c["max_residual"] <= 1e-12 && $c["max_energy_drift"] <= 1e-10) ? "yes" : "no";
      printf "%-24s %-8s %-10s %-10.3g %-10.3g %-10.3g %s\n", name, $c["integrator"], $c["steps"], $c["max_residual"], $c["max_energy_drift"], $c["wall_seconds"], meets }' "$d/summary.csv"
done
