#!/usr/bin/env bash
# Step and gain maps of the methods of issues 17 and 18 (`cstab stability`),
# one folder per problem x method under OUT, and one table:
#   - penalty on RK4, its rate omega: the boundary in h * omega against RK4's
#     real stability interval (2.785), as the older methods' maps;
#   - the self-stepping schemes (--integrator own) over their own parameter
#     (generalized-alpha and its index-2 form: rho_inf; hht: alpha; ali3p:
#     its penalty factor alpha; rattle and symmetric-projection, which have
#     none to sweep, at their solve tolerance): the largest step at which a
#     run over [0, T_END] neither blows up nor fails its Newton iteration.
# Prints OUT/maps.md (markdown) and writes OUT/<problem>-<method>/.
#   usage: bash scripts/stability-maps.sh [OUT]     (about 10 minutes on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."
OUT=${1:-results/stability-maps}
CSTAB=${CSTAB:-build/release/cli/cstab}
[ -x "$CSTAB" ] || bash scripts/build.sh
T_END=${T_END:-ref}
STEPS=1e-3,3e-3,1e-2,3e-2,0.1,0.3,1
mkdir -p "$OUT"

# method parameter values
own=(
  "generalized-alpha rho_inf 0,0.5,0.9,1"
  "hht alpha -0.3333333333,-0.2,-0.05,0"
  "generalized-alpha-i2 rho_inf 0,0.5,0.9,1"
  "ali3p alpha 1e2,1e4,1e6"
  "rattle tol 1e-12"
  "symmetric-projection tol 1e-12"
)
problems=(pendulum slider-crank wheel ball)

{
  echo "Largest stable step (s) over t in [0, $T_END], steps $STEPS bisected 6 times; '>= 1': the whole grid ran."
  echo "T_END ref: each problem's reference time. A run that fails (Newton, or the method refuses the problem) counts as unstable."
  echo
  echo "| problem | method | parameter | value: largest stable step |"
  echo "|---|---|---|---|"
  for p in "${problems[@]}"; do
    for entry in "${own[@]}"; do
      read -r m param values <<<"$entry"
      dir=$OUT/$p-$m
      if ! "$CSTAB" stability --problem "$p" --method "$m" --integrator own --gain-param "$param" \
          --steps "$STEPS" --gains "$values" --t-end "$T_END" --bisect 6 --out "$dir" >"$dir.log" 2>&1; then
        echo "| $p | $m | $param | does not apply: $(tail -1 "$dir.log" | sed 's/|/\//g') |"
        continue
      fi
      cells=$(awk -F, 'NR > 1 {s = ($6 == "" ? "none" : ($7 == "" ? ">= " : "") sprintf("%.3g", $6)); printf "%s%s: %s", (NR > 2 ? "; " : ""), $5 + 0, s}' "$dir/boundary.csv")
      echo "| $p | $m | $param | $cells |"
    done
  done
  echo
  echo "penalty on RK4, the rate omega over t in [0, 1] (pendulum at rest, started 1e-9 off the manifold; wheel as it moves):"
  echo
  echo "| problem | h | measured h omega | RK4 interval | ratio |"
  echo "|---|---|---|---|---|"
  for p in pendulum wheel; do
    extra=()
    [ "$p" = pendulum ] && extra=(--problem-param angle=0 --perturb 1e-9)
    dir=$OUT/$p-penalty-rk4
    "$CSTAB" stability --problem "$p" "${extra[@]}" --method penalty --integrator rk4 --gain-param omega \
      --steps 1e-4,1e-3,1e-2 --gains 10,100,1000,1e4,1e5 --t-end 1 --bisect 12 --out "$dir" >"$dir.log" 2>&1
    awk -F, -v p="$p" 'NR > 1 {printf "| %s | %g | %.4g | %.4g | %.3f |\n", p, $5, $8, $9, $10}' "$dir/boundary.csv"
  done
} >"$OUT/maps.md"
cat "$OUT/maps.md"
