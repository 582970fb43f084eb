#!/usr/bin/env bash
# The bad-input table of issues 9 and 16: every kind of bad input on every
# command (run, stability, score, tune, matrix and matrix files, merge, report, gate,
# list), with what it got: exit code, first line of stderr, number of stderr
# lines, files left in the output folder (for the rows that damage a folder,
# the files of that folder that changed). Markdown on stdout. Usage: bash
# scripts/bad-input-table.sh (uses build/release/cli/cstab, or $CSTAB). Each
# case: label|arguments, OUT = a fresh output folder, SHARD = a finished
# one-case results folder, and for issue 16: BADID (a shard whose cases.csv
# names a case ../../escaped), BADCSV (a shard whose cases.csv has index x1),
# NOCASES (cases.csv and summary.csv but no cases/), THR (thresholds written
# by --init from DIV, a two-case folder whose step 3e-3 case diverges),
# DIVTHR (a row bounding that diverged case's residual), EMPTYTHR (a header-only thresholds file), PARTTHR
# (THR without its last row), LOCKED (a copy of SHARD whose lock a
# background `flock` holds), NOLOCK (a copy of DIV without its lock file:
# a refused `gate --update` must not leave one), READONLY (a copy of SHARD without write
# permission; its row runs as uid 65534 through setpriv). Every row runs
# under `timeout 900`; SKIP_SLOW=1 skips the row that takes minutes (an
# adaptive run up to the default step limit of 1e8).
set -u
cd "$(dirname "$0")/.."
B="${CSTAB:-$(pwd)/build/release/cli/cstab}"
W=$(mktemp -d /tmp/cstab-bad-input-XXXXXX)
lock_holder=
trap 'rm -rf "$W"' EXIT
G="--problem wheel --method pesterev --integrator rk4 --step 1e-3 --t-end 0.05"
A="--problem wheel --method pesterev --integrator rk8pd --rtol 1e-6 --atol 1e-6 --t-end 0.05"
S="--problem wheel --method pesterev --integrator rk4 --gain-param lambda --steps 1e-3 --gains 10 --t-end 0.05 --no-plot"
T="--problem pendulum --method pesterev --integrator rk4 --target 1e-6 --t-end 0.5"
M=$W/m
mkdir -p $M
# Trajectories for `cstab score` (the pendulum's columns are t,x,y,xdot,ydot).
t() { printf '%b' "$2" > $M/traj_$1.csv; }
t good 't,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n'
t unknown_column 't,x,y,xdot,ydot,zz\n0,1,0,0,0,0\n0.1,1,0,0,0,0\n'
t missing_column 't,x,xdot,ydot\n0,1,0,0\n0.1,1,0,0\n'
t duplicate_column 't,x,y,x,ydot\n0,1,0,0,0\n'
t nan 't,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,nan,0,0\n'
t word 't,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,abc,0,0\n'
t short_row 't,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0\n'
t not_increasing 't,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n0.1,1,0,0,0\n'
t one_row 't,x,y,xdot,ydot\n0,1,0,0,0\n'
t empty ''
t slider_crank 't,q,x,p,qdot,xdot,pdot\n0,0,0,0,0,0,0\n0.1,0,0,0,0,0,0\n'
t wall_nan '# wall_seconds = nan\nt,x,y,xdot,ydot\n0,1,0,0,0\n0.1,1,0,0,0\n'
printf 'not gzip' > $M/traj_corrupt.csv.gz
w() { printf '%b' "$2" > $M/$1.toml; }
w plugins_in_sweep '[defaults]\nproblems = ["pendulum"]\nmethods = ["none"]\nintegrators = ["rk4"]\nstep = 1e-2\nt_end = 0.1\n[[sweep]]\nname = "a"\nplugins = ["x.so"]\n'
w plugins_not_string '[defaults]\nplugins = [1]\nproblems = ["pendulum"]\nmethods = ["none"]\nintegrators = ["rk4"]\nstep = 1e-2\nt_end = 0.1\n[[sweep]]\nname = "a"\n'
w plugins_missing '[defaults]\nplugins = ["no-such.so"]\nproblems = ["pendulum"]\nmethods = ["none"]\nintegrators = ["rk4"]\nstep = 1e-2\nt_end = 0.1\n[[sweep]]\nname = "a"\n'

w good '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w unknown_key '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nstpe = 1\n'
w wrong_type '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = "fast"\nt_end = 0.05\n'
w nan '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = nan\nt_end = 0.05\n'
w inf '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = inf\nt_end = 0.05\n'
w overflow '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e999\nt_end = 0.05\n'
w step_zero '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 0\nt_end = 0.05\n'
w step_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = [1e-3, -1e-3]\nt_end = 0.05\n'
w t_end_zero '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0\n'
w t_end_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = -1\n'
w tol_zero '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk8pd"\ntol = 0\nt_end = 0.05\n'
w tol_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk8pd"\nrtol = -1e-6\natol = 1e-6\nt_end = 0.05\n'
w tol_and_rtol '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk8pd"\ntol = 1e-6\nrtol = 1e-6\nt_end = 0.05\n'
w rtol_alone '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk8pd"\nrtol = 1e-6\nt_end = 0.05\n'
w step_for_adaptive '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk8pd"\nstep = 1e-3\nt_end = 0.05\n'
w no_step '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nt_end = 0.05\n'
w param_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nparam.lambda = -5\n'
w param_string '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nparam.lambda = "big"\n'
w param_unknown_method '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nparam.pesterv.lambda = 5\n'
w problem_param_range '[[sweep]]\nproblems = ["pendulum"]\nmethods = ["projection"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nproblem_param.length = [1, -2]\n'
w problem_param_unknown '[[sweep]]\nproblems = ["pendulum"]\nmethods = ["projection"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nproblem_param.pendulum.N = 4\n'
w param_unknown_name '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nparam.pesterev.lamda = 5\n'
w unknown_problem '[[sweep]]\nproblems = ["whel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w unknown_method '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterv"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w unknown_integrator '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk5"\nstep = 1e-3\nt_end = 0.05\n'
w unknown_formulation '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nformulations = ["lagrange"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w dae_method_ode_integrator '[[sweep]]\nproblems = ["wheel"]\nmethods = ["ida-ggl"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w ode_method_ida '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "ida"\ntol = 1e-6\nt_end = 0.05\n'
w method_not_applicable '[[sweep]]\nproblems = ["biped"]\nmethods = ["minimal"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w tune_one '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\ntune = 1\n'
w tune_and_param '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\ntune = 5\nparam.lambda = [10, 100]\n'
w times_beyond '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\ntimes = [0.01, 7]\n'
w times_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\ntimes = -1\n'
w repeats_zero '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nrepeats = 0\n'
w repeats_fraction '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nrepeats = 1.5\n'
w observe_huge '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nobserve_every = 1e300\n'
w blowup_zero '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nblowup = 0\n'
w timeout_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\ntimeout = -1\n'
w series_number '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nseries = 1\n'
w sample_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nsample_every = -1\n'
w ref_time_negative '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\nref_time = -1\n'
w empty_array '[[sweep]]\nproblems = []\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w mixed_array '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = [1e-3, "x"]\nt_end = 0.05\n'
w nested_array '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = [[1e-3]]\nt_end = 0.05\n'
w unterminated_string '[[sweep]]\nproblems = ["wheel]\n'
w bad_section '[sweeps]\n'
w key_outside '\nstep = 1\n'
w duplicate_key '[[sweep]]\nstep = 1\nstep = 2\n'
w duplicate_name '[[sweep]]\nname = "a"\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n[[sweep]]\nname = "a"\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = 1e-3\nt_end = 0.05\n'
w huge_product '[[sweep]]\nproblems = "all"\nmethods = "all"\nintegrators = "rk4"\nstep = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,42,43,44,45,46,47,48,49,50]\nt_end = 100\nparam.lambda = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,42,43,44,45,46,47,48,49,50]\nparam.alpha = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,42,43,44,45,46,47,48,49,50]\nparam.beta = [1,2,3,4,5,6,7,8,9,10,11,12,13,14,15,16,17,18,19,20,21,22,23,24,25,26,27,28,29,30,31,32,33,34,35,36,37,38,39,40,41,42,43,44,45,46,47,48,49,50]\n'
w binary_garbage '\x00\xff\xfe[[sweep]]\n'
w empty_file ''
w no_sweep '[defaults]\nrepeats = 2\n'

cases=(
"run_unknown_problem|run ${G/wheel/nope} --out OUT"
"run_unknown_method|run ${G/pesterev/nope} --out OUT"
"run_unknown_formulation|run $G --formulation lagrange --out OUT"
"run_wrong_formulation_for_method|run ${G/pesterev/baumgarte} --formulation state-space --out OUT"
"run_unknown_integrator|run ${G/rk4/rk5} --out OUT"
"run_unknown_flag|run $G --stpe 1 --out OUT"
"run_flag_twice|run $G --step 1e-3 --out OUT"
"run_missing_value|run $G --out"
"run_positional|run $G extra --out OUT"
"run_step_zero|run ${G/--step 1e-3/--step 0} --out OUT"
"run_step_negative|run ${G/--step 1e-3/--step -1e-3} --out OUT"
"run_step_nan|run ${G/--step 1e-3/--step nan} --out OUT"
"run_step_inf|run ${G/--step 1e-3/--step inf} --out OUT"
"run_step_hex|run ${G/--step 1e-3/--step 0x1p-10} --out OUT"
"run_step_empty|run ${G/--step 1e-3/--step=} --out OUT"
"run_step_gt_t_end|run ${G/--step 1e-3/--step 1} --out OUT"
"run_t_end_zero|run ${G/--t-end 0.05/--t-end 0} --out OUT"
"run_t_end_inf|run ${G/--t-end 0.05/--t-end inf} --out OUT"
"run_t_end_1e999|run ${G/--t-end 0.05/--t-end 1e999} --out OUT"
"run_rtol_zero|run ${A/--rtol 1e-6/--rtol 0} --out OUT"
"run_atol_negative|run ${A/--atol 1e-6/--atol -1} --out OUT"
"run_atol_nan|run ${A/--atol 1e-6/--atol nan} --out OUT"
"run_tol_for_rk4|run $G --rtol 1e-6 --atol 1e-6 --out OUT"
"run_step_for_rk8pd|run $A --step 1e-3 --out OUT"
"run_dae_method_ode_integrator|run ${G/pesterev/ida-ggl} --out OUT"
"run_ode_method_ida|run ${A/rk8pd/ida} --out OUT"
"run_method_not_applicable|run ${G/wheel --method pesterev/biped --method minimal} --out OUT"
"run_param_unknown|run $G --param foo=1 --out OUT"
"run_param_negative|run $G --param lambda=-1 --out OUT"
"run_param_nan|run $G --param lambda=nan --out OUT"
"run_param_twice|run $G --param lambda=1 --param lambda=2 --out OUT"
"run_param_no_eq|run $G --param lambda --out OUT"
"run_param_for_none|run ${G/pesterev/none} --param lambda=1 --out OUT"
"run_problem_param_unknown|run $G --problem-param N=3 --out OUT"
"run_problem_param_range|run ${G/wheel/pendulum} --problem-param length=0 --out OUT"
"run_problem_param_nan|run ${G/wheel/pendulum} --problem-param angle=nan --out OUT"
"run_problem_param_word|run ${G/wheel/pendulum} --problem-param length=long --out OUT"
"run_problem_param_twice|run ${G/wheel/pendulum} --problem-param length=1 --problem-param length=2 --out OUT"
"run_problem_param_no_eq|run ${G/wheel/pendulum} --problem-param length --out OUT"
"run_times_beyond|run $G --times 1 --out OUT"
"run_times_zero|run $G --times 0 --out OUT"
"run_times_garbage|run $G --times 0.01,,0.02 --out OUT"
"run_sample_negative|run $G --sample-every -1 --out OUT"
"run_ref_time_negative|run $G --ref-time -2 --out OUT"
"run_ref_time_beyond|run $G --ref-time 3 --out OUT"
"run_ref_time_nan|run $G --ref-time nan --out OUT"
"run_blowup_zero|run $G --blowup 0 --out OUT"
"run_observe_zero|run $G --observe-every 0 --out OUT"
"run_observe_huge|run $G --observe-every 99999999999999 --out OUT"
"run_observe_fraction|run $G --observe-every 1.5 --out OUT"
"run_out_missing|run $G"
"run_out_file|run $G --out /etc/passwd"
"run_out_proc|run $G --out /proc/x"
"run_no_series_proc|run $G --no-series --out /proc"
"run_switch_with_value|run $G --no-series=1 --out OUT"
"stab_adaptive|stability ${S/rk4/rk8pd} --out OUT"
"stab_steps_zero|stability ${S/--steps 1e-3/--steps 0} --out OUT"
"stab_steps_empty|stability ${S/--steps 1e-3/--steps=} --out OUT"
"stab_gains_missing|stability ${S/--gains 10/} --out OUT"
"stab_gains_negative|stability ${S/--gains 10/--gains -10} --out OUT"
"stab_gain_param_unknown|stability ${S/--gain-param lambda/--gain-param foo} --out OUT"
"stab_gain_param_also_param|stability $S --param lambda=5 --out OUT"
"stab_t_end_nan|stability ${S/--t-end 0.05/--t-end nan} --out OUT"
"stab_bisect_negative|stability $S --bisect -1 --out OUT"
"stab_bisect_huge|stability $S --bisect 100000000000 --out OUT"
"stab_blowup_zero|stability $S --blowup 0 --out OUT"
"stab_step_gt_t_end|stability ${S/--steps 1e-3/--steps 1} --out OUT"
"stab_out_file|stability $S --out /etc/passwd"
"stab_unknown_problem|stability ${S/wheel/nope} --out OUT"
"score_unknown_problem|score --problem nope $M/traj_good.csv --out OUT"
"score_missing_file|score --problem pendulum /nonexistent.csv --out OUT"
"score_no_trajectory|score --problem pendulum --out OUT"
"score_unknown_column|score --problem pendulum $M/traj_unknown_column.csv --out OUT"
"score_missing_column|score --problem pendulum $M/traj_missing_column.csv --out OUT"
"score_duplicate_column|score --problem pendulum $M/traj_duplicate_column.csv --out OUT"
"score_nan_cell|score --problem pendulum $M/traj_nan.csv --out OUT"
"score_word_cell|score --problem pendulum $M/traj_word.csv --out OUT"
"score_short_row|score --problem pendulum $M/traj_short_row.csv --out OUT"
"score_t_not_increasing|score --problem pendulum $M/traj_not_increasing.csv --out OUT"
"score_one_row|score --problem pendulum $M/traj_one_row.csv --out OUT"
"score_empty_file|score --problem pendulum $M/traj_empty.csv --out OUT"
"score_other_problem|score --problem pendulum $M/traj_slider_crank.csv --out OUT"
"score_corrupt_gz|score --problem pendulum $M/traj_corrupt.csv.gz --out OUT"
"score_formulation|score --problem pendulum --formulation minimal $M/traj_good.csv --out OUT"
"score_blowup_zero|score --problem pendulum --blowup 0 $M/traj_good.csv --out OUT"
"score_wall_negative|score --problem pendulum --wall-seconds -1 $M/traj_good.csv --out OUT"
"score_wall_in_file_nan|score --problem pendulum $M/traj_wall_nan.csv --out OUT"
"score_ref_time_negative|score --problem pendulum --ref-time -1 $M/traj_good.csv --out OUT"
"score_out_file|score --problem pendulum $M/traj_good.csv --out /etc/passwd"
"tune_unknown_method|tune ${T/pesterev/nope} --out OUT"
"tune_no_gain|tune ${T/pesterev/none} --out OUT"
"tune_target_nan|tune ${T/--target 1e-6/--target nan} --out OUT"
"tune_target_negative|tune ${T/--target 1e-6/--target -1} --out OUT"
"tune_steps_garbage|tune $T --steps 1e-3,,x --out OUT"
"tune_tols_for_rk4|tune $T --tols 1e-6 --out OUT"
"tune_measure_unknown|tune $T --measure speed --out OUT"
"tune_out_file|tune $T --out /etc/passwd"
"plugin_missing|run $G --plugin /nonexistent.so --out OUT"
"plugin_not_elf|run $G --plugin /etc/passwd --out OUT"
"plugin_not_plugin|run $G --plugin $(ls /lib/*/libm.so.6 /usr/lib/*/libm.so.6 2>/dev/null | head -1) --out OUT"
"plugin_no_value|list --plugin"
"plugin_empty|run $G --plugin= --out OUT"
"check_nothing|check"
"check_unknown_problem|check --problem nope"
"check_unknown_method|check --method nope"
"mat_missing_file|matrix /nonexistent.toml --out OUT"
"mat_folder_as_file|matrix /tmp --out OUT"
"mat_two_files|matrix $M/good.toml $M/good.toml --out OUT"
"mat_no_out|matrix $M/good.toml"
"mat_jobs_zero|matrix $M/good.toml --jobs 0 --out OUT"
"mat_jobs_garbage|matrix $M/good.toml --jobs x --out OUT"
"mat_jobs_huge|matrix $M/good.toml --jobs 99999999999999999999 --out OUT"
"mat_shard_bad|matrix $M/good.toml --shard 3/2 --out OUT"
"mat_shard_garbage|matrix $M/good.toml --shard a/b --out OUT"
"mat_shard_zero|matrix $M/good.toml --shard 0/0 --out OUT"
"mat_out_file|matrix $M/good.toml --out /etc/passwd"
"mat_out_proc|matrix $M/good.toml --out /proc/x"
"mat_unknown_flag|matrix $M/good.toml --frobnicate --out OUT"
"mat_filter_nothing|matrix $M/good.toml --filter nothing-matches --out OUT"
"mat_svg_no_report|matrix $M/good.toml --svg --no-report --out OUT"
"mat_svg_shard|matrix $M/good.toml --svg --shard 1/2 --out OUT"
)
for f in $M/*.toml; do n=$(basename $f .toml); [ $n = good ] && continue; cases+=("matfile_$n|matrix $f --out OUT"); done
cases+=(
"merge_no_args|merge"
"merge_one_arg|merge OUT"
"merge_not_results|merge OUT /tmp"
"merge_missing_shard|merge OUT /nonexistent"
"merge_into_shard|merge SHARD SHARD"
"merge_jobs_zero|merge OUT SHARD --jobs 0"
"merge_bad_flag|merge OUT SHARD --frob"
"report_no_args|report"
"report_not_results|report /tmp"
"report_missing|report /nonexistent"
"report_jobs_zero|report SHARD --jobs 0"
"report_two|report SHARD SHARD"
"report_svg_no_plots|report SHARD --svg --no-plots"
"merge_svg_no_report|merge OUT SHARD --svg --no-report"
"list_extra|list extra"
"i16_run_step_1e-320|run --problem slider-crank --method pesterev --integrator rk4 --step 1e-320 --t-end 0.1 --out OUT"
"i16_run_t_end_1e9_step_1e-9|run --problem slider-crank --method pesterev --integrator rk4 --step 1e-9 --t-end 1e9 --out OUT"
"i16_slow_run_rk8pd_t_end_1e300|run --problem slider-crank --method pesterev --integrator rk8pd --rtol 1e-6 --atol 1e-6 --t-end 1e300 --no-series --out OUT"
"i16_run_rk8pd_t_end_1e300_max_steps_1e5|run --problem slider-crank --method pesterev --integrator rk8pd --rtol 1e-6 --atol 1e-6 --t-end 1e300 --max-steps 1e5 --no-series --out OUT"
"i16_run_max_steps_zero|run $G --max-steps 0 --out OUT"
"i16_run_param_max_iter_2^31|run ${G/pesterev/projection} --param max_iter=2147483648 --out OUT"
"i16_run_param_max_iter_fraction|run ${G/pesterev/projection} --param max_iter=2.5 --out OUT"
"i16_stab_huge_grid|stability --problem wheel --method pesterev --integrator rk4 --gain-param lambda --steps 1e-7 --gains 10 --t-end 100 --no-plot --out OUT"
"i16_matrix_dev_zero|matrix /dev/zero --out OUT"
"i16_merge_bad_case_id|merge OUT BADID"
"i16_merge_bad_cases_csv|merge OUT BADCSV"
"i16_report_bad_cases_csv|report BADCSV"
"i16_gate_bad_cases_csv|gate --thresholds THR BADCSV"
"i16_report_no_cases|report NOCASES"
"i16_gate_update_factor_1e308|gate --update --factor 1e308 --thresholds DIVTHR DIV"
"i16_gate_header_only|gate --thresholds EMPTYTHR DIV"
"i16_gate_strict_missing_row|gate --strict --thresholds PARTTHR DIV"
"i16_matrix_locked|matrix $M/good.toml --out LOCKED"
"i16_merge_locked|merge LOCKED SHARD"
"i16_report_locked|report LOCKED"
"i16_gate_update_locked|gate --update --thresholds THR LOCKED"
"i16_merge_shard_locked|merge OUT LOCKED"
"i16_gate_update_refused_no_lock_file|gate --update --factor 1e308 --thresholds DIVTHR NOLOCK"
"i16_matrix_read_only_folder_as_uid_65534|NOBODY matrix $M/good.toml --out READONLY"
"list_flag|list --foo"
"unknown_command|frobnicate"
)
# a finished shard for merge/report cases
rm -rf $W/shard; $B matrix $M/good.toml --out $W/shard --no-report >/dev/null 2>&1
# the damaged folders of issue 16 (see the head of this file)
id=$(sed -n 2p $W/shard/cases.csv | cut -d, -f2)
cp -r $W/shard $W/badid; sed -i "2s|$id|../../escaped|" $W/badid/cases.csv
cp -r $W/shard $W/badcsv; sed -i '2s|^0,|x1,|' $W/badcsv/cases.csv
mkdir -p $W/nocases; cp $W/shard/cases.csv $W/shard/summary.csv $W/nocases/
printf '[[sweep]]\nproblems = ["wheel"]\nmethods = ["pesterev"]\nintegrators = "rk4"\nstep = [3e-3, 1e-3]\nt_end = 1\n' > $M/div.toml
$B matrix $M/div.toml --out $W/div --no-report >/dev/null 2>&1   # step 3e-3 diverges (residual ~1e3)
$B gate --init $W/thr.csv $W/div >/dev/null 2>&1
head -n -1 $W/thr.csv > $W/partthr.csv
printf 'problem,method,integrator,setting,status,max_residual\nwheel,pesterev,rk4,step=0.003,diverged,1\n' > $W/divthr.csv
printf 'problem,method,integrator,setting\n' > $W/emptythr.csv
cp -r $W/shard $W/locked
cp -r $W/div $W/nolock; rm -f $W/nolock/.cstab.lock
cp -r $W/shard $W/readonly; chmod -R a-w $W/readonly; chmod a+rx $W $M; chmod a+r $M/good.toml
printf '%s\nflock (bad-input-table.sh)\n' $$ > $W/locked/.cstab.lock
flock $W/locked/.cstab.lock sleep 3600 & lock_holder=$!
trap 'kill $lock_holder 2>/dev/null; chmod -R u+w "$W"; rm -rf "$W"' EXIT
sleep 0.2
shard_before=$(cd $W/shard && find . -type f | sort | xargs md5sum | md5sum)
snap() { (cd "$1" 2>/dev/null && find . -type f | sort | xargs md5sum 2>/dev/null); }
printf '| # | input | exit | message (stderr, first line) | lines | files left |\n|---|---|---|---|---|---|\n'
i=0
for c in "${cases[@]}"; do
  i=$((i+1))
  label=${c%%|*}; args=${c#*|}
  # SKIP_SLOW=1: leave out the rows that take minutes (the default step limit of an adaptive run)
  if [[ ${SKIP_SLOW:-0} == 1 && $label == *_slow_* ]]; then printf '| %d | %s | skipped (SKIP_SLOW=1) | | | |\n' "$i" "$label"; continue; fi
  out=$W/out_$i; rm -rf $out
  args=${args//OUT/$out}; args=${args//SHARD/$W/shard}
  args=${args//BADID/$W/badid}; args=${args//BADCSV/$W/badcsv}; args=${args//NOCASES/$W/nocases}
  args=${args//EMPTYTHR/$W/emptythr.csv}; args=${args//PARTTHR/$W/partthr.csv}; args=${args//DIVTHR/$W/divthr.csv}
  args=${args//THR/$W/thr.csv}; args=${args//DIV/$W/div}
  args=${args//NOLOCK/$W/nolock}; args=${args//LOCKED/$W/locked}; args=${args//READONLY/$W/readonly}
  run_as=""; [[ $args == NOBODY\ * ]] && { args=${args#NOBODY }; run_as="setpriv --reuid=65534 --regid=65534 --clear-groups"; }
  # the folder a row damages, if any: what changed in it is its "files left"
  target=""
  for d in badid badcsv nocases locked nolock readonly; do [[ " $args " == *" $W/$d "* ]] && target=$W/$d; done
  [[ -z $target && " $args " == *" $W/divthr.csv "* ]] && target=$W/div
  [ -n "$target" ] && before=$(snap $target; md5sum $W/thr.csv $W/divthr.csv)
  start=$(date +%s.%N)
  timeout 900 $run_as $B $args >$W/stdout 2>$W/stderr; code=$?
  secs=$(echo "$(date +%s.%N) - $start" | bc)
  # a failed check (exit 1) reports on stdout: its last line then
  [ ! -s $W/stderr ] && [ $code != 0 ] && tail -1 $W/stdout > $W/stderr
  msg=$(head -1 $W/stderr | sed "s|$W/||g; s/|/\\\\|/g" | cut -c1-170)
  lines=$(wc -l < $W/stderr)
  if [ -e $out ]; then left=$(find $out -type f | sed "s|$out/||" | tr '\n' ' '); [ -z "$left" ] && left="(empty folder)"; else left="none"; fi
  if [ -n "$target" ]; then
    after=$(snap $target; md5sum $W/thr.csv $W/divthr.csv)
    changed=$(diff <(echo "$before") <(echo "$after") | grep '^[<>]' | awk '{print $3}' | sort -u | tr '\n' ' ')
    left="$left; $(basename $target): ${changed:-unchanged}"
  fi
  [[ $label == i16_* ]] && label="$label ($(printf '%.1f' $secs) s)"
  printf '| %d | %s | %s | %s | %s | %s |\n' "$i" "$label" "$code" "$msg" "$lines" "$left"
done
shard_after=$(cd $W/shard && find . -type f | sort | xargs md5sum | md5sum)
[ "$shard_before" = "$shard_after" ] && echo "shard folder unchanged by the merge/report cases" || echo "shard folder CHANGED"
