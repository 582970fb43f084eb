#!/usr/bin/env bash
# MuJoCo's accuracy knobs against cstab's metrics (issue 20, item 3;
# docs/peers-mujoco.md): cstab-peer-mujoco runs cstab's pendulum and
# slider crank to t = 10 at timesteps 1e-2 .. 1e-5 with each integrator
# (euler, rk4, implicit) and two solrefs (MuJoCo's default 0.02,1 and a
# stiffer 0.002,1), writing a row every 0.01 s; `cstab score` scores each
# (label mujoco-<integrator>-<timestep>). Prints one markdown table:
# problem, integrator, timestep, solref, wall seconds (the mj_step loop),
# max residual, max energy drift (the slider crank has no energy law in
# cstab: "-"), ref_error (against cstab's reference at t = 10). A run
# MuJoCo gives up on (bad qacc) is a row with status failed.
#
# Usage: bash scripts/peer-mujoco.sh OUT   (OUT keeps the trajectories and
# scored folders). Uses build/release/cli/cstab and
# build/release/peers/mujoco/cstab-peer-mujoco, or $CSTAB and $PEER.
set -u
cd "$(dirname "$0")/.."
if [ $# -ne 1 ]; then
  echo "usage: bash scripts/peer-mujoco.sh OUT" >&2
  exit 2
fi
OUT=$1
C="${CSTAB:-$(pwd)/build/release/cli/cstab}"
P="${PEER:-$(pwd)/build/release/peers/mujoco/cstab-peer-mujoco}"
for b in "$C" "$P"; do
  if [ ! -x "$b" ]; then
    echo "peer-mujoco.sh: $b is not built (cmake --build build/release --target cstab cstab-peer-mujoco)" >&2
    exit 2
  fi
done
mkdir -p "$OUT"

# The summary.csv column named $2 of file $1.
col() {
  awk -F, -v name="$2" 'NR == 1 { for (i = 1; i <= NF; i++) if ($i == name) c = i; next }
                        NR == 2 { print (c ? $c : "") }' "$1"
}

echo "| problem | integrator | timestep | solref | status | wall s | max residual | max energy drift | ref_error (t = 10) |"
echo "|---|---|---|---|---|---:|---:|---:|---:|"
for problem in pendulum slider-crank; do
  for integrator in euler rk4 implicit; do
    for h in 1e-2 1e-3 1e-4 1e-5; do
      every=0.01
      for solref in 0.02,1 0.002,1; do
        name=$problem-$integrator-$h-${solref/,/-}
        csv=$OUT/$name.csv
        "$P" --problem $problem --integrator $integrator --timestep $h --solref $solref \
          --t-end 10 --every $every --out "$csv" 2> "$OUT/$name.log"
        rc=$?
        if [ $rc -ne 0 ]; then
          msg=$(tail -1 "$OUT/$name.log" | sed 's/.*MuJoCo failed at //; s/|/\//g' | cut -c1-80)
          echo "| $problem | $integrator | $h | $solref | failed (exit $rc): $msg | | | | |"
          continue
        fi
        "$C" score --problem $problem --label mujoco-$integrator-$h "$csv" --out "$OUT/$name" > /dev/null 2>> "$OUT/$name.log"
        s=$OUT/$name/summary.csv
        drift=$(col "$s" max_energy_drift)
        [ -z "$drift" ] && drift=-
        printf '| %s | %s | %s | %s | %s | %.3g | %.3g | %s | %.3g |\n' $problem $integrator $h $solref \
          "$(col "$s" status)" "$(col "$s" wall_seconds)" "$(col "$s" max_residual)" \
          "$([ "$drift" = - ] && echo - || printf '%.3g' "$drift")" "$(col "$s" ref_error)"
      done
    done
  done
done
