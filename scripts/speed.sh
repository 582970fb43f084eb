#!/usr/bin/env bash
# Speed at equal accuracy (issue 8). Per problem, the reference error
# target is 1e-8 (max abs error over the canonical coordinates at the
# problem's reference time, column ref_error). Stage 1 runs
# matrices/speed.toml (every method x integrator x tolerance/step x a few
# gains, 5 repeats of short runs); for each problem x method the cheapest
# case (median wall time) reaching the target is re-timed in stage 2
# (REPEATS repeats, one case at a time), and the table of ratios is written:
#   OUT/speed.csv  problem, method, formulation, integrator, setting, params,
#                  median_wall_s, repeats, ref_error, steps, rhs_evals, case_id,
#                  speedup_vs_ida_ggl (IDA-GGL's median / this one's),
#                  cost_vs_minimal (this one's / the minimal-coordinate ODE's)
#   usage: scripts/speed.sh [OUT]        (default results/speed)
#   env:   CSTAB (binary), JOBS (stage-1 parallel cases, default 2), REPEATS (default 9), TARGET (1e-8),
#          SWEEP (stage 1's results folder, default OUT/sweep: two targets can share one sweep)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/speed}
CSTAB=${CSTAB:-build/release/cli/cstab}
JOBS=${JOBS:-2}
REPEATS=${REPEATS:-9}
TARGET=${TARGET:-1e-8}
SWEEP=${SWEEP:-$OUT/sweep}
mkdir -p "$OUT"

echo "speed: stage 1 (sweep) into $SWEEP" >&2
"$CSTAB" matrix matrices/speed.toml --out "$SWEEP" --jobs "$JOBS" --no-report >"$OUT/sweep.log"
# The folder's summary.csv: every repeat of the cases of this matrix only
# (the folder may hold cases of earlier versions of it).
awk -v TARGET="$TARGET" -f scripts/speed-best.awk "$SWEEP/summary.csv" | sort >"$OUT/stage1-best.csv"

# Stage 2: one sweep per chosen case, all its parameters spelled out.
awk -F, -v R="$REPEATS" '
  { split($5, s, "=");
    printf "[[sweep]]\nname = \"best-%d\"\nproblems = [\"%s\"]\nmethods = [\"%s\"]\nformulations = [\"%s\"]\n", NR, $1, $2, $3
    printf "integrators = [\"%s\"]\n%s = [%s]\n", $4, s[1], s[2]
    np = split($6, p, ";")
    for (i = 1; i <= np; i++) if (p[i] != "") { split(p[i], kv, "="); printf "param.%s = [%s]\n", kv[1], kv[2] }
    printf "t_end = \"ref\"\nseries = false\nobserve_every = 100000000\nrepeats = %d\ntimeout = 120\n\n", R }
' "$OUT/stage1-best.csv" >"$OUT/retime.toml"
echo "speed: stage 2 (re-timing $(wc -l <"$OUT/stage1-best.csv") cases, $REPEATS repeats, one at a time)" >&2
rm -rf "$OUT/retime"
"$CSTAB" matrix "$OUT/retime.toml" --out "$OUT/retime" --jobs 1 --no-report >"$OUT/retime.log"
awk -v TARGET="$TARGET" -f scripts/speed-best.awk "$OUT/retime/summary.csv" | sort >"$OUT/stage2-best.csv"

# Ratios within the stage-2 run: to IDA-GGL, to the minimal-coordinate ODE
# and to the fastest method of the problem (the minimal ODE left out).
awk -F, -v OFS=, '
  { row[NR] = $0; prob[NR] = $1; meth[NR] = $2; wall[NR] = $7
    if ($2 == "ida-ggl") ida[$1] = $7
    if ($2 == "minimal") minimal[$1] = $7
    else if (!($1 in fastest) || $7 < fastest[$1]) fastest[$1] = $7 }
  END {
    print "problem,method,formulation,integrator,setting,params,median_wall_s,repeats,ref_error,steps,rhs_evals,case_id,newton_per_step,speedup_vs_ida_ggl,cost_vs_minimal,cost_vs_fastest"
    for (i = 1; i <= NR; i++) {
      p = prob[i]
      s = (p in ida) ? sprintf("%.3g", ida[p] / wall[i]) : ""
      c = (p in minimal) ? sprintf("%.3g", wall[i] / minimal[p]) : ""
      f = meth[i] == "minimal" ? "" : sprintf("%.3g", wall[i] / fastest[p])
      print row[i], s, c, f
    }
  }' "$OUT/stage2-best.csv" >"$OUT/speed.csv"

# Markdown table: per problem, every method's cheapest setting, fastest first.
{
  echo "| problem | method | integrator, setting | median wall (ms) | ref error | Newton its / step | this / fastest | IDA-GGL / this | this / minimal |"
  echo "|---|---|---|---|---|---|---|---|---|"
  tail -n +2 "$OUT/speed.csv" | sort -t, -k1,1 -k7,7g | awk -F, '{
    m = $2; if ($2 == "pesterev" && $3 != "mechanical") m = $2 " (" $3 ")"
    lam = ""; if (match($6, /(^|;)(lambda|alpha|dt|rho_inf)=[^;]*/)) lam = ", " substr($6, RSTART + (substr($6, RSTART, 1) == ";"), RLENGTH - (substr($6, RSTART, 1) == ";"))
    if ($2 == "baumgarte" && match($6, /beta=[^;]*/)) lam = lam ", " substr($6, RSTART, RLENGTH)
    printf "| %s | %s | %s %s%s | %.3g | %.1e | %s | %s | %s | %s |\n", $1, m, $4, $5, lam, 1000 * $7, $9, $13 == "" ? "-" : $13,
      $16 == "" ? "-" : $16 "x", $14 == "" ? "-" : $14 "x", $15 == "" ? "-" : $15 "x" }'
} >"$OUT/speed.md"
cat "$OUT/speed.md"
echo "speed: wrote $OUT/speed.csv and $OUT/speed.md" >&2
