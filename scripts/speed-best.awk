# Reads summary.csv files (a matrix folder's DIR/summary.csv: one row per
# repeat of every case; the header of each file names its columns) and
# prints, per problem x method (x formulation), the case with the smallest
# median wall time whose reference error is <= TARGET:
#   problem,method,formulation,integrator,setting,params,median_wall,repeats,ref_error,steps,rhs_evals,case_id,newton_per_step
# Fields are split on commas: no value of the columns used contains one.
BEGIN { FS = ","; if (TARGET == "") TARGET = 1e-8 }
FNR == 1 { delete col; for (i = 1; i <= NF; i++) col[$i] = i; next }
{
  id = $col["case_id"]
  if ($col["status"] != "ok" || $col["ref_error"] == "" || $col["ref_error"] + 0 > TARGET + 0) { bad[id] = 1; next }
  n[id]++
  wall[id, n[id]] = $col["wall_seconds"] + 0
  setting = $col["step"] != "" ? "step=" $col["step"] : "tol=" $col["rtol"]
  info[id] = $col["problem"] "," $col["method"] "," $col["formulation"] "," $col["integrator"] "," setting "," $col["params"]
  group[id] = $col["problem"] SUBSEP $col["method"] SUBSEP $col["formulation"]
  err[id] = $col["ref_error"]; steps[id] = $col["steps"]; evals[id] = $col["rhs_evals"]
  # Newton (or augmented Lagrangian) iterations per step, for the
  # self-stepping schemes; empty for the others.
  nps[id] = ("newton_iters" in col && $col["newton_iters"] != "" && $col["steps"] + 0 > 0) ? \
            sprintf("%.3g", $col["newton_iters"] / $col["steps"]) : ""
}
function median(id,    k, m, i, j, t, a) {
  m = n[id]
  for (i = 1; i <= m; i++) a[i] = wall[id, i]
  for (i = 2; i <= m; i++) { t = a[i]; for (j = i - 1; j >= 1 && a[j] > t; j--) a[j + 1] = a[j]; a[j + 1] = t }
  return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
}
END {
  for (id in n) {
    if (id in bad) continue
    g = group[id]; med = median(id)
    if (!(g in best) || med < bestwall[g]) { best[g] = id; bestwall[g] = med }
  }
  for (g in best) {
    id = best[g]
    # params hold ';' not ','; quote nothing
    printf "%s,%.6g,%d,%s,%s,%s,%s,%s\n", info[id], bestwall[g], n[id], err[id], steps[id], evals[id], id, nps[id]
  }
}
