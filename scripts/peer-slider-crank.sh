#!/usr/bin/env bash
# Peer comparison on the slider crank: SUNDIALS's own IDAS example
# idasSlCrank_dns against cstab, in one run, one table.
#
#  1. Builds the example from the installed Debian sources
#     (/usr/share/doc/libsundials-dev/examples/idas/serial/, package
#     libsundials-dev): the .c is copied to a temporary folder at run time and
#     compiled there - it is never part of this repository. Two binaries:
#       peer        the example as shipped (its output is checked against the
#                   shipped idasSlCrank_dns.out, t = 10 row);
#       peer-instr  the same source with two edits made by sed in the temp
#                   copy: y1..y3 printed with all digits (to measure its error
#                   at t = 10) and the solve (IDACreate .. the last IDASolve)
#                   timed with clock_gettime (integration-only wall time).
#  2. The accurate solution at t = 10: cstab's minimal-coordinate reference
#     (minimal, rk8pd, rtol = atol = 1e-13).
#  3. cstab ida-ggl with the example's tolerances (rtol 1e-6, atol 1e-7).
#  4. cstab's fastest method to the same accuracy: every candidate method x
#     integrator x tolerance is run once; those whose error at t = 10 (max
#     over y1, y2, y3) is at most the peer's are timed; the fastest by median
#     integration time wins (overall, and among the 3-coordinate constrained
#     formulations, since `minimal` integrates a 1-degree-of-freedom ODE).
#  5. Every timed program runs REPEATS times; medians are reported, both the
#     whole process (startup and output included) and the integration alone
#     (cstab: summary.csv wall_seconds; peer: the instrumented timer).
#
#   usage: scripts/peer-slider-crank.sh [OUT]    (default results/peer-slider-crank)
#   env:   REPEATS (default 11), CSTAB (default build/release/cli/cstab),
#          SUNDIALS_EXAMPLES (default the Debian folder above)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/peer-slider-crank}
REPEATS=${REPEATS:-11}
CSTAB=${CSTAB:-build/release/cli/cstab}
EXAMPLES=${SUNDIALS_EXAMPLES:-/usr/share/doc/libsundials-dev/examples/idas/serial}
CC=${CC:-gcc}

die() { echo "peer-slider-crank: $*" >&2; exit 1; }

[ -x "$CSTAB" ] || die "$CSTAB not found: build first (scripts/build.sh)"
LIST=$("$CSTAB" list)
grep -q '^  slider-crank:' <<< "$LIST" || die "$CSTAB has no slider-crank problem"
HAVE_IDA=1
grep -q '^  ida-ggl:' <<< "$LIST" || HAVE_IDA=0

mkdir -p "$OUT"
TMP=$(mktemp -d)
trap 'rm -rf "$TMP"' EXIT

# ---- 1. the peer program, from the installed sources ----
fetch() {  # name -> $TMP/name (plain or gzipped in the package)
  if [ -f "$EXAMPLES/$1" ]; then cp "$EXAMPLES/$1" "$TMP/$1"
  elif [ -f "$EXAMPLES/$1.gz" ]; then gzip -dc "$EXAMPLES/$1.gz" > "$TMP/$1"
  else die "$EXAMPLES/$1 not found (install libsundials-dev)"; fi
}
fetch idasSlCrank_dns.c
fetch idasSlCrank_dns.out
LIBS="-lsundials_idas -lsundials_nvecserial -lsundials_sunmatrixdense -lsundials_sunlinsoldense -lm"
$CC -O2 -o "$TMP/peer" "$TMP/idasSlCrank_dns.c" $LIBS || die "cannot compile the example"

grep -q '  /\* IDAS initialization \*/' "$TMP/idasSlCrank_dns.c" || die "example changed: no IDAS initialization anchor"
grep -q '  retval = PrintFinalStats(mem);' "$TMP/idasSlCrank_dns.c" || die "example changed: no PrintFinalStats anchor"
sed -e 's/%12\.4e %12\.4e %12\.4e |/%.17e %.17e %.17e |/' \
    -e 's|^#include <math.h>|#include <math.h>\n#include <time.h>\nstatic struct timespec peer_t0, peer_t1;|' \
    -e 's|^  /\* IDAS initialization \*/|  clock_gettime(CLOCK_MONOTONIC, \&peer_t0);\n&|' \
    -e 's|^  retval = PrintFinalStats(mem);|  clock_gettime(CLOCK_MONOTONIC, \&peer_t1);\n  fprintf(stderr, "solve_seconds %.9f\\n", (peer_t1.tv_sec - peer_t0.tv_sec) + 1e-9 * (peer_t1.tv_nsec - peer_t0.tv_nsec));\n&|' \
    "$TMP/idasSlCrank_dns.c" > "$TMP/instr.c"
$CC -O2 -o "$TMP/peer-instr" "$TMP/instr.c" $LIBS || die "cannot compile the instrumented copy"

"$TMP/peer" > "$TMP/peer.out"
shipped=$(grep '^10\.00 ' "$TMP/idasSlCrank_dns.out" | awk '{print $2, $3, $4}')
ours=$(grep '^10\.00 ' "$TMP/peer.out" | awk '{print $2, $3, $4}')
[ "$shipped" = "$ours" ] || die "the built example prints '$ours' at t = 10, the shipped output '$shipped'"
"$TMP/peer-instr" > "$TMP/peer-instr.out" 2> "$TMP/peer-instr.err"
read -r P1 P2 P3 < <(grep '^10\.00 ' "$TMP/peer-instr.out" | awk '{print $2, $3, $4}')
PEER_STEPS=$(awk -F= '/Number of steps/{gsub(/ /,"",$2); print $2}' "$TMP/peer.out")

# ---- helpers ----
median() { sort -g | awk '{a[NR]=$1} END{ if (NR%2) print a[(NR+1)/2]; else print (a[NR/2]+a[NR/2+1])/2 }'; }
now() { date +%s.%N; }
col() {  # summary.csv column by name
  awk -F, -v k="$2" 'NR==1{for(i=1;i<=NF;i++) if($i==k) c=i; next} {print $c}' "$1/summary.csv"
}
last_positions() { tail -n 1 "$1/series.csv" | awk -F, '{print $2, $3, $4}'; }
err3() {  # max |a_i - b_i| over 3 values: err3 "a1 a2 a3" "b1 b2 b3"
  awk -v a="$1" -v b="$2" 'BEGIN{split(a,x," "); split(b,y," "); m=0;
    for(i=1;i<=3;i++){d=x[i]-y[i]; if(d<0)d=-d; if(d>m)m=d}; printf "%.3e\n", m}'
}
cstab_run() {  # dir, args...
  local dir=$1; shift
  "$CSTAB" run --problem slider-crank --t-end 10 --sample-every 10 --out "$dir" "$@" >/dev/null
}

# ---- 2. the accurate solution ----
cstab_run "$OUT/reference" --method minimal --integrator rk8pd --rtol 1e-13 --atol 1e-13
REF=$(last_positions "$OUT/reference")
PEER_ERR=$(err3 "$P1 $P2 $P3" "$REF")

# ---- timing ----
ROWS=()
time_peer() {
  local proc=() solve=()
  for _ in $(seq "$REPEATS"); do
    local t0 t1
    t0=$(now); "$TMP/peer" >/dev/null; t1=$(now)
    proc+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')")
    "$TMP/peer-instr" >/dev/null 2> "$TMP/t.err"
    solve+=("$(awk '/solve_seconds/{print $2}' "$TMP/t.err")")
  done
  ROWS+=("SUNDIALS idasSlCrank_dns|GGL index-2 DAE, 10 unknowns|IDAS BDF|1e-6/1e-7|$PEER_ERR|$PEER_STEPS|$(printf '%s\n' "${solve[@]}" | median)|$(printf '%s\n' "${proc[@]}" | median)")
}
time_cstab() {  # label, formulation, integrator label, tol label, args...
  local label=$1 form=$2 integ=$3 tol=$4; shift 4
  local proc=() solve=() dir="$OUT/timed-$(echo "$label" | tr -c 'a-zA-Z0-9\n' '-')"
  for i in $(seq "$REPEATS"); do
    local t0 t1
    t0=$(now); cstab_run "$dir" "$@"; t1=$(now)
    proc+=("$(awk -v a="$t0" -v b="$t1" 'BEGIN{print b-a}')")
    solve+=("$(col "$dir" wall_seconds)")
  done
  local e
  e=$(err3 "$(last_positions "$dir")" "$REF")
  ROWS+=("$label|$form|$integ|$tol|$e|$(col "$dir" steps)|$(printf '%s\n' "${solve[@]}" | median)|$(printf '%s\n' "${proc[@]}" | median)")
}

time_peer

# ---- 3. cstab ida-ggl with the example's tolerances ----
if [ "$HAVE_IDA" = 1 ]; then
  time_cstab "cstab ida-ggl" "GGL index-2 DAE (mechanical)" "ida" "1e-6/1e-7" \
    --method ida-ggl --integrator ida --rtol 1e-6 --atol 1e-7
fi

# ---- 4. the fastest cstab method reaching the peer's accuracy ----
: > "$OUT/candidates.txt"
for method in minimal none projection baumgarte; do
  for integ in rk8pd rkf45 msadams; do
    for tol in 1e-4 1e-5 1e-6 1e-7 1e-8 1e-9 1e-10; do
      dir="$TMP/cand"
      cstab_run "$dir" --method "$method" --integrator "$integ" --rtol "$tol" --atol "$tol" 2>/dev/null || continue
      [ "$(col "$dir" status)" = ok ] || continue
      e=$(err3 "$(last_positions "$dir")" "$REF")
      if awk -v e="$e" -v p="$PEER_ERR" 'BEGIN{exit !(e <= p)}'; then
        echo "$method $integ $tol $e $(col "$dir" wall_seconds)" >> "$OUT/candidates.txt"
        break  # the loosest tolerance that qualifies
      fi
    done
  done
done
[ -s "$OUT/candidates.txt" ] || die "no cstab candidate reached the peer's error $PEER_ERR"
# Time every qualifying candidate; keep the fastest overall and the fastest constrained.
best_all="" best_all_t="" best_con="" best_con_t=""
while read -r method integ tol e _; do
  ts=()
  for _ in $(seq "$REPEATS"); do
    cstab_run "$TMP/cand" --method "$method" --integrator "$integ" --rtol "$tol" --atol "$tol"
    ts+=("$(col "$TMP/cand" wall_seconds)")
  done
  m=$(printf '%s\n' "${ts[@]}" | median)
  echo "$method $integ $tol err=$e median_wall=$m" >> "$OUT/candidates-timed.txt"
  if [ -z "$best_all_t" ] || awk -v a="$m" -v b="$best_all_t" 'BEGIN{exit !(a < b)}'; then best_all="$method $integ $tol"; best_all_t=$m; fi
  if [ "$method" != minimal ]; then
    if [ -z "$best_con_t" ] || awk -v a="$m" -v b="$best_con_t" 'BEGIN{exit !(a < b)}'; then best_con="$method $integ $tol"; best_con_t=$m; fi
  fi
done < "$OUT/candidates.txt"

add_best() {  # "method integ tol"
  read -r method integ tol <<< "$1"
  local form="index-1 ODE + $method (mechanical, 6 states)"
  [ "$method" = minimal ] && form="minimal ODE (crank angle, 2 states)"
  [ "$method" = none ] && form="index-1 ODE, no stabilization (mechanical)"
  time_cstab "cstab $method" "$form" "$integ" "$tol/$tol" --method "$method" --integrator "$integ" --rtol "$tol" --atol "$tol"
}
add_best "$best_all"
[ -n "$best_con" ] && [ "$best_con" != "$best_all" ] && add_best "$best_con"

# ---- 5. the table ----
{
  echo "Slider crank (idasSlCrank_dns), t in [0, 10]; error = max |y_i(10) - reference|, i = 1..3;"
  echo "reference: cstab minimal, rk8pd 1e-13 (y1..y3 = $REF); medians of $REPEATS runs."
  echo "integration = solve only (peer: IDACreate..last IDASolve, clock_gettime; cstab: summary wall_seconds);"
  echo "process = the whole program, startup and output included."
  echo
  printf "| %-26s | %-44s | %-10s | %-11s | %-9s | %-5s | %-15s | %-11s |\n" program formulation integrator "rtol/atol" "error" steps "integration (s)" "process (s)"
  printf "|%s|%s|%s|%s|%s|%s|%s|%s|\n" "$(printf -- '-%.0s' {1..28})" "$(printf -- '-%.0s' {1..46})" "$(printf -- '-%.0s' {1..12})" "$(printf -- '-%.0s' {1..13})" "$(printf -- '-%.0s' {1..11})" "$(printf -- '-%.0s' {1..7})" "$(printf -- '-%.0s' {1..17})" "$(printf -- '-%.0s' {1..13})"
  for r in "${ROWS[@]}"; do
    IFS='|' read -r a b c d e f g h <<< "$r"
    printf "| %-26s | %-44s | %-10s | %-11s | %-9s | %-5s | %-15.6f | %-11.6f |\n" "$a" "$b" "$c" "$d" "$e" "$f" "$g" "$h"
  done
  [ "$HAVE_IDA" = 1 ] || echo "(cstab ida-ggl: not built in $CSTAB)"
} | tee "$OUT/table.md"
