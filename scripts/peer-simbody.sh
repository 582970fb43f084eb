#!/usr/bin/env bash
# Simbody beside cstab (issue 20, item 3): runs cstab-peer-simbody on the
# pendulum, the slider crank, Bricard's mechanism (its redundant closure,
# the default) and Andrews' squeezer with each of Simbody's integrators at
# accuracy 1e-2 .. 1e-8 (constraint tolerance Simbody's 0.1 x accuracy),
# scores every trajectory with `cstab score`, and prints one table.
#
#   scripts/peer-simbody.sh OUT        (BUILD=build/release by default)
#
# OUT/<problem>/<integrator>-<accuracy>.csv are the trajectories and
# OUT/<problem>/<integrator>-<accuracy>/ their scores (label
# simbody-<integrator>-<accuracy>); OUT/table.txt is the table printed.
# Rows are written every 0.1 s to t = 10 (--every), Andrews' squeezer every
# 1 ms to the Test Set's t = 0.03: Simbody's explicit integrators end a step
# at every report time, so a finer spacing changes the run
# (docs/peers-simbody.md). euler stops at 1e-7: its steps grow about 3x per
# decade and 1e-8 takes over 30 s on the pendulum. Each run is limited to
# PEER_TIMEOUT seconds (default 30). PEER_PROBLEMS="bricard" (a space-separated
# list) runs only those problems.
set -euo pipefail

if [[ $# -ne 1 ]]; then
  echo "usage: scripts/peer-simbody.sh OUT" >&2
  exit 2
fi
out=$1
root=$(cd "$(dirname "$0")/.." && pwd)
build=${BUILD:-$root/build/release}
cstab=$build/cli/cstab
peer=$build/peers/simbody/cstab-peer-simbody
timeout_s=${PEER_TIMEOUT:-30}
for b in "$cstab" "$peer"; do
  if [[ ! -x $b ]]; then
    echo "peer-simbody: $b not built (cmake --build $build --target cstab cstab-peer-simbody)" >&2
    exit 2
  fi
done
mkdir -p "$out"

read -r -a problems <<< "${PEER_PROBLEMS:-pendulum slider-crank bricard andrews}"
integrators=(rk3 rkmerson rkfeldberg verlet euler cpodes)
accuracies=(1e-2 1e-3 1e-4 1e-5 1e-6 1e-7 1e-8)

# The value of column $2 in the one-row CSV $1.
column() {
  awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i }
                        NR == 2 { if (c) print $c }' "$1"
}
# The value of "# key = value" in trajectory $1.
meta() { sed -n "s/^# $2 = //p" "$1" | head -1; }

table=$out/table.txt
{
  printf '%-12s %-10s %-8s %-8s %-9s %-7s %-11s %-11s %-11s %s\n' problem integrator accuracy status wall_s steps \
    max_resid max_dE ref_error note
  start=$SECONDS
  for problem in "${problems[@]}"; do
    mkdir -p "$out/$problem"
    t_end=10 every=0.1
    [[ $problem == andrews ]] && t_end=0.03 every=0.001
    for integrator in "${integrators[@]}"; do
      for accuracy in "${accuracies[@]}"; do
        if [[ $integrator == euler && $accuracy == 1e-8 ]]; then
          printf '%-12s %-10s %-8s %-8s %s\n' "$problem" "$integrator" "$accuracy" skipped "(over 30 s; see the header)"
          continue
        fi
        name=$integrator-$accuracy
        csv=$out/$problem/$name.csv
        scored=$out/$problem/$name
        status=ok
        note=""
        set +e
        timeout "$timeout_s" "$peer" --problem "$problem" --integrator "$integrator" --accuracy "$accuracy" \
          --t-end "$t_end" --every "$every" --out "$csv" > "$out/$problem/$name.log" 2>&1
        rc=$?
        set -e
        if [[ $rc -eq 124 ]]; then
          printf '%-12s %-10s %-8s %-8s %s\n' "$problem" "$integrator" "$accuracy" timeout "(> ${timeout_s} s)"
          continue
        elif [[ $rc -ne 0 ]]; then
          status=failed
          note=$(tail -c 120 "$out/$problem/$name.log" | tr '\n' ' ')
        fi
        if ! "$cstab" score --problem "$problem" --label "simbody-$name" "$csv" --out "$scored" \
          >> "$out/$problem/$name.log" 2>&1; then
          printf '%-12s %-10s %-8s %-8s %s\n' "$problem" "$integrator" "$accuracy" "$status" "not scoreable: $note"
          continue
        fi
        s=$scored/summary.csv
        de=$(column "$s" max_energy_drift)
        [[ -z $de ]] && de="n/a"
        # No reference error where the run stopped before t = 10 (a failure).
        re=$(column "$s" ref_error)
        [[ -z $re ]] && re="n/a"
        printf '%-12s %-10s %-8s %-8s %-9.4g %-7s %-11.3g %-11s %-11s %s\n' "$problem" "$integrator" "$accuracy" \
          "$status" "$(column "$s" wall_seconds)" "$(meta "$csv" simbody_steps)" "$(column "$s" max_residual)" \
          "$([[ $de == n/a ]] && echo n/a || printf '%.3g' "$de")" \
          "$([[ $re == n/a ]] && echo n/a || printf '%.3g' "$re")" "$note"
      done
    done
  done
  echo "max_dE: the largest |E(t) - E(0)| (cstab's energy law); n/a for the slider crank, which is damped and"
  echo "forced (no energy law in cstab). ref_error: distance to cstab's reference at t = 10 (the canonical state;"
  echo "andrews: the Test Set's 7 angles at t = 0.03)."
  echo "Defaults: Simbody's accuracy 1e-3, constraint tolerance 1e-4 (the 1e-3 rows). Sweep took $((SECONDS - start)) s."
} | tee "$table"
