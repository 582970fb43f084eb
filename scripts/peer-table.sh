#!/usr/bin/env bash
# The peer table of issue 20 from a results folder of matrices/peers.toml:
# per problem and reference error level (1e-3, 1e-6, 1e-9), the fastest
# cstab stabilization method that reaches it (median wall time; the
# constraint-free baselines none and minimal excluded) and each other
# engine's fastest setting that reaches it, as a ratio to cstab's. Then each
# engine's default setting (Simbody: accuracy 1e-3; MuJoCo: Euler at 0.002;
# SUNDIALS' example: its tol 1e-6) with its residual and drift. An engine is
# listed for the problems it has a finished case of. Markdown on stdout.
#   usage: bash scripts/peer-table.sh RESULTS_DIR
set -euo pipefail
dir=${1:?usage: scripts/peer-table.sh RESULTS_DIR}
wp=$dir/work_precision.csv
[ -f "$wp" ] || { echo "peer-table: no $wp" >&2; exit 2; }
awk -F, '
NR == 1 { for (i = 1; i <= NF; i++) col[$i] = i; next }
$col["status"] != "ok" || $col["ref_error"] == "" { next }
{
  p = $col["problem"]; m = $col["method"]; w = $col["wall_median_s"] + 0; e = $col["ref_error"] + 0
  engine = ($col["integrator"] == "external") ? m : "cstab"
  sub(/-.*$/, "", engine)                   # simbody-rkmerson -> simbody
  if (engine == "cstab" && (m == "none" || m == "minimal")) next
  if (!(p in problems)) { problems[p] = 1; plist[++np] = p }
  if (!(engine in engines)) { engines[engine] = 1; glist[++ng] = engine }
  models[p SUBSEP engine] = 1               # the engine has a case of the problem
  split("1e-3 1e-6 1e-9", levels, " ")
  for (k = 1; k <= 3; k++) {
    if (e > levels[k] + 0) continue
    key = p SUBSEP engine SUBSEP k
    if (!(key in best) || w < best[key]) { best[key] = w; who[key] = m " " $col["integrator"] " " $col["setting"] }
  }
  if ((engine == "simbody" && $col["setting"] == "tol=0.001") || (m == "mujoco-euler" && $col["setting"] == "step=0.002") ||
      (m == "sundials-idas" && $col["setting"] == "tol=1e-06"))
    defaults[++nd] = sprintf("%s | %s | %.3g | %.3g | %s | %.3g | %s", p, m, $col["max_residual"], e,
                             $col["max_drift"] == "" ? "n/a" : sprintf("%.3g", $col["max_drift"]), w, $col["steps"])
}
END {
  print "| problem | error <= | cstab fastest (method integrator setting) | wall s | engine | engine fastest | wall s | engine / cstab |"
  print "|---|---|---|---|---|---|---|---|"
  split("1e-3 1e-6 1e-9", levels, " ")
  for (i = 1; i <= np; i++) for (k = 1; k <= 3; k++) for (j = 1; j <= ng; j++) {
    p = plist[i]; g = glist[j]
    if (g == "cstab" || !((p SUBSEP g) in models)) continue
    c = p SUBSEP "cstab" SUBSEP k; o = p SUBSEP g SUBSEP k
    cs = (c in best) ? sprintf("%s | %.3g", who[c], best[c]) : "not reached | "
    os = (o in best) ? sprintf("%s | %.3g", who[o], best[o]) : "not reached | "
    ratio = (c in best && o in best) ? sprintf("%.1f", best[o] / best[c]) : "-"
    print "| " p " | " levels[k] " | " cs " | " g " | " os " | " ratio " |"
  }
  print ""
  print "| problem | engine at its defaults | max residual | ref error | max drift | wall s | steps (external: rows - 1) |"
  print "|---|---|---|---|---|---|---|"
  for (d = 1; d <= nd; d++) print "| " defaults[d] " |"
}' "$wp"
